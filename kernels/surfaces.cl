/* Deflectors, absorbers, blockers, 2-D constraints and the actions that read neighbours
 * (sdk/src/opencl/actions_surfaces.cpp generates their calls and packs their constants).
 * Each follows sdk/src/cpu/kernels.hpp and actions_more.hpp operation by operation. */

/* Reflects the velocity at the hit point h (normal n, time of impact tau) and places the
 * particle so that Move ends it at the reflected point (kernels.hpp Reflect). */
FL_INLINE void fl_reflect(__global const FlActionParams* a, float* px, float* py, float* pz,
                          float* vx, float* vy, float* vz, float hx, float hy, float hz,
                          float nx, float ny, float nz, float tau) {
  const float restitution = a->f[6], keep = a->f[7], cutoff2 = a->f[8];
  const float vn = *vx * nx + *vy * ny + *vz * nz;
  const float vnx = vn * nx, vny = vn * ny, vnz = vn * nz;
  const float tx = *vx - vnx, ty = *vy - vny, tz = *vz - vnz;
  const float t2 = tx * tx + ty * ty + tz * tz;
  const float f = t2 > cutoff2 ? keep : 1.0f;
  *vx = tx * f - vnx * restitution;
  *vy = ty * f - vny * restitution;
  *vz = tz * f - vnz * restitution;
  *px = hx - *vx * tau;
  *py = hy - *vy * tau;
  *pz = hz - *vz * tau;
}

#define FL_PIECE_PLANE 0
#define FL_PIECE_RECTANGLE 1
#define FL_PIECE_TRIANGLE 2
#define FL_PIECE_DISC 3

/* Whether a point of the plane lies on the piece (piece is a literal: folded away). */
FL_INLINE int fl_on_piece(__global const FlActionParams* a, int piece, float x, float y,
                          float z) {
  const float wx = x - a->f[0], wy = y - a->f[1], wz = z - a->f[2];
  if (piece == FL_PIECE_RECTANGLE) {
    const float s = wx * a->f[10] + wy * a->f[11] + wz * a->f[12];
    const float t = wx * a->f[13] + wy * a->f[14] + wz * a->f[15];
    return (s >= 0.0f) & (s <= 1.0f) & (t >= 0.0f) & (t <= 1.0f);
  }
  if (piece == FL_PIECE_TRIANGLE) {
    const float s = wx * a->f[10] + wy * a->f[11] + wz * a->f[12];
    const float u = wx * a->f[13] + wy * a->f[14] + wz * a->f[15];
    return (s >= 0.0f) & (u >= 0.0f) & (s + u <= 1.0f);
  }
  if (piece == FL_PIECE_DISC) {
    const float r2 = wx * wx + wy * wy + wz * wz;
    return (r2 <= a->f[10]) & (r2 >= a->f[11]);
  }
  return 1;
}

/* A two-sided planar deflector (kernels.hpp bouncePlanarLoop). */
FL_INLINE void fl_bounce_planar(__global const FlActionParams* a, int piece, float dt,
                                float* px, float* py, float* pz, float* vxs, float* vys,
                                float* vzs) {
  const float Px = a->f[0], Py = a->f[1], Pz = a->f[2];
  const float Nx = a->f[3], Ny = a->f[4], Nz = a->f[5];
  const float x = *px, y = *py, z = *pz, vx = *vxs, vy = *vys, vz = *vzs;
  const float d0 = (x - Px) * Nx + (y - Py) * Ny + (z - Pz) * Nz;
  const float vn = vx * Nx + vy * Ny + vz * Nz;
  const float d1 = d0 + vn * dt;
  const float side = d0 >= 0.0f ? 1.0f : -1.0f;
  const float tau = d0 / (d0 - d1) * dt;
  const float hx = x + vx * tau, hy = y + vy * tau, hz = z + vz * tau;
  const int hit = (side * d1 < 0.0f) & fl_on_piece(a, piece, hx, hy, hz);
  if (!hit) return;
  float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
  fl_reflect(a, &nx, &ny, &nz, &nvx, &nvy, &nvz, hx, hy, hz, Nx, Ny, Nz, tau);
  const float qx = nx + nvx * dt, qy = ny + nvy * dt, qz = nz + nvz * dt;
  const float qd = side * ((qx - Px) * Nx + (qy - Py) * Ny + (qz - Pz) * Nz);
  const float margin = 4e-7f * (fabs(qx) + fabs(qy) + fabs(qz) + a->f[9]) + 1e-30f;
  const float push = fl_maxf(2.0f * margin - qd, 0.0f) * side;
  *px = nx + push * Nx;
  *py = ny + push * Ny;
  *pz = nz + push * Nz;
  *vxs = nvx;
  *vys = nvy;
  *vzs = nvz;
}

/* A sphere deflecting from outside (kernels.hpp bounceSphereLoop). */
FL_INLINE void fl_bounce_sphere(__global const FlActionParams* a, float dt, float* px,
                                float* py, float* pz, float* vxs, float* vys, float* vzs) {
  const float Cx = a->f[0], Cy = a->f[1], Cz = a->f[2];
  const float R2 = a->f[11], invR = a->f[12];
  const float x = *px, y = *py, z = *pz, vx = *vxs, vy = *vys, vz = *vzs;
  const float rx = x - Cx, ry = y - Cy, rz = z - Cz;
  const float c2 = rx * rx + ry * ry + rz * rz - R2;
  const float bb = rx * vx + ry * vy + rz * vz;
  const float aa = vx * vx + vy * vy + vz * vz;
  const float disc = bb * bb - aa * c2;
  const float tHit = (-bb - sqrt(fl_maxf(disc, 0.0f))) / aa;
  const int hit = (c2 >= 0.0f) & (disc >= 0.0f) & (bb < 0.0f) & (tHit <= dt);
  if (!hit) return;
  const float tau = fl_maxf(tHit, 0.0f);
  const float hx = x + vx * tau, hy = y + vy * tau, hz = z + vz * tau;
  const float nnx = (hx - Cx) * invR, nny = (hy - Cy) * invR, nnz = (hz - Cz) * invR;
  float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
  fl_reflect(a, &nx, &ny, &nz, &nvx, &nvy, &nvz, hx, hy, hz, nnx, nny, nnz, tau);
  const float qx = nx + nvx * dt - Cx, qy = ny + nvy * dt - Cy, qz = nz + nvz * dt - Cz;
  const float qd = sqrt(qx * qx + qy * qy + qz * qz) - a->f[10];
  const float margin = 4e-7f * (fabs(qx) + fabs(qy) + fabs(qz) + a->f[9]) + 1e-30f;
  const float push = fl_maxf(2.0f * margin - qd, 0.0f);
  *px = nx + push * nnx;
  *py = ny + push * nny;
  *pz = nz + push * nnz;
  *vxs = nvx;
  *vys = nvy;
  *vzs = nvz;
}

/* An absorber (kernels.hpp sinkLoop, then the pass-through draw for those it just took). */
FL_INLINE void fl_sink(__global const FlActionParams* a, uint kind, int killInside,
                       int passThrough, float x, float y, float z, uint id, uint code,
                       uint* dead, uint seedLo, uint seedHi, uint step, uint stream) {
  const uint in = fl_inside(a->domain.v, kind, x, y, z) ? 1u : 0u;
  const uint k = in == (killInside ? 1u : 0u) ? code : 0u;
  *dead = *dead != 0u ? *dead : k;
  if (passThrough && *dead == code) {
    FlRandom rng = fl_random(seedLo, seedHi, id, step, stream);
    if (fl_uniform(&rng) < a->f[0]) *dead = 0u;
  }
}

