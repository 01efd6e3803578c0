/* Deflectors (Bounce) on spheres and boxes, and the reflection every deflector shares: written
 * once for both backends in the kernels' shared C subset (compat_opencl.h on the device,
 * sdk/src/kernel_compat.hpp on the CPU, whose loops call these per particle and still
 * vectorise). Scalars in, the particle's state through pointers; what a deflector needs comes
 * as arguments, so each side keeps its own way of storing the action's constants.
 *
 * Every function is branch-free where the CPU's loop must vectorise (selects rather than
 * early returns), and adds x, y, z in glm's order, so the two backends agree to the bit. */
#ifndef FLURRY_KERNELS_DEFLECT_H
#define FLURRY_KERNELS_DEFLECT_H

/* How a deflector reflects: the normal part of the velocity is reversed and scaled by
 * restitution; the tangential part keeps `keep` (1 - friction) when its square exceeds
 * cutoff2. */
typedef struct FlReflect {
  float restitution, keep, cutoff2;
} FlReflect;

/* Reflects the velocity (vx, vy, vz) at the hit point h (normal n, time of impact tau) and
 * places the particle so that the following Move ends it at the reflected point. vns is the
 * normal part's length along n, (v·n)/(n·n): v·n for a unit normal. */
FL_INLINE void fl_reflect_vn(FlReflect r, float* px, float* py, float* pz, float* vx, float* vy,
                             float* vz, float hx, float hy, float hz, float nx, float ny, float nz,
                             float vns, float tau) {
  const float vnx = vns * nx, vny = vns * ny, vnz = vns * nz;
  const float tx = *vx - vnx, ty = *vy - vny, tz = *vz - vnz;
  const float t2 = tx * tx + ty * ty + tz * tz;
  const float f = t2 > r.cutoff2 ? r.keep : 1.0f; /* the one select: vectorises */
  *vx = tx * f - vnx * r.restitution;
  *vy = ty * f - vny * r.restitution;
  *vz = tz * f - vnz * r.restitution;
  *px = hx - *vx * tau;
  *py = hy - *vy * tau;
  *pz = hz - *vz * tau;
}

/* fl_reflect_vn at a unit normal n (planes, box faces). */
FL_INLINE void fl_reflect(FlReflect r, float* px, float* py, float* pz, float* vx, float* vy,
                          float* vz, float hx, float hy, float hz, float nx, float ny, float nz,
                          float tau) {
  fl_reflect_vn(r, px, py, pz, vx, vy, vz, hx, hy, hz, nx, ny, nz, *vx * nx + *vy * ny + *vz * nz,
                tau);
}

/* fl_reflect_vn at a normal d of any nonzero length: a sphere's h - C. Its computed hit point
 * is off the sphere by rounding (|h - C|² - R² up to ~20 ulps of R², more where the time of
 * impact cancels), so (h - C)/R is not unit, and mirroring about it changes |v|² by
 * 4·cos²·(|n|² - 1) per bounce: a drift at restitution 1 that grows with the bounces. Dividing
 * by d·d mirrors exactly in exact arithmetic, whatever |d|: a few ulps of |v|² are left. */
FL_INLINE void fl_reflect_any(FlReflect r, float* px, float* py, float* pz, float* vx, float* vy,
                              float* vz, float hx, float hy, float hz, float dx, float dy, float dz,
                              float tau) {
  const float vns = (*vx * dx + *vy * dy + *vz * dz) / (dx * dx + dy * dy + dz * dz);
  fl_reflect_vn(r, px, py, pz, vx, vy, vz, hx, hy, hz, dx, dy, dz, vns, tau);
}

/* A sphere (centre C, radius R, R2 = R², invR = 1/R, scale = |C|₁ + R) deflecting from
 * outside (inside = 0) or keeping particles in (inside = 1): one reflection where the step's
 * straight path first meets it. Inside, a reflected path that reaches the wall again, or ends
 * too close to it, is left as it was for fl_bounce_sphere_again: its end is near another point
 * of the wall, where this hit's normal does not point inwards. */
FL_INLINE void fl_bounce_sphere_once(FlReflect rf, float Cx, float Cy, float Cz, float R, float R2,
                                     float invR, float scale, int inside, float dt, float* px,
                                     float* py, float* pz, float* vxs, float* vys, float* vzs) {
  const float x = *px, y = *py, z = *pz, vx = *vxs, vy = *vys, vz = *vzs;
  const float rx = x - Cx, ry = y - Cy, rz = z - Cz;
  const float c2 = rx * rx + ry * ry + rz * rz - R2;
  const float bb = rx * vx + ry * vy + rz * vz;
  const float aa = vx * vx + vy * vy + vz * vz;
  const float disc = bb * bb - aa * c2;
  const float root = sqrt(fl_maxf(disc, 0.0f));
  /* Outside: the entry root; inside: the exit root. inf/NaN (aa = 0) is a miss. */
  const float tHit = inside ? (-bb + root) / aa : (-bb - root) / aa;
  const int hit = inside ? (c2 <= 0.0f) & (tHit <= dt)
                         : (c2 >= 0.0f) & (disc >= 0.0f) & (bb < 0.0f) & (tHit <= dt);
  const float tau = fl_maxf(tHit, 0.0f);
  const float hx = x + vx * tau, hy = y + vy * tau, hz = z + vz * tau;
  const float nnx = (hx - Cx) * invR, nny = (hy - Cy) * invR, nnz = (hz - Cz) * invR;
  float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
  fl_reflect_any(rf, &nx, &ny, &nz, &nvx, &nvy, &nvz, hx, hy, hz, hx - Cx, hy - Cy, hz - Cz, tau);
  const float qx = nx + nvx * dt - Cx, qy = ny + nvy * dt - Cy, qz = nz + nvz * dt - Cz;
  /* Signed clearance on the allowed side: outside it is |q| - R, inside R - |q|. */
  const float ql = sqrt(qx * qx + qy * qy + qz * qz);
  const float qd = inside ? R - ql : ql - R;
  const float margin = 4e-7f * (fabs(qx) + fabs(qy) + fabs(qz) + scale + fabs(nvx * dt) +
                                fabs(nvy * dt) + fabs(nvz * dt)) +
                       1e-30f;
  const float push = fl_maxf(2.0f * margin - qd, 0.0f) * (inside ? -1.0f : 1.0f);
  const int take = hit & !(inside & (qd < 2.0f * margin));
  *px = take ? nx + push * nnx : x;
  *py = take ? ny + push * nny : y;
  *pz = take ? nz + push * nnz : z;
  *vxs = take ? nvx : vx;
  *vys = take ? nvy : vy;
  *vzs = take ? nvz : vz;
}

/* Inside a sphere, after fl_bounce_sphere_once: a particle that crosses the sphere more than
 * once in a step bounces at every exit for what is left of the step, from where it began;
 * past 16 bounces it ends inside. Particles whose step ends inside are left as they are. */
/* Whether fl_bounce_sphere_again acts on the particle: not if it bounced already (its end is
 * inside) or was outside to begin with (the CPU tests a chunk with it, in vectors, and runs
 * fl_bounce_sphere_again for the few it holds for). */
FL_INLINE int fl_bounce_sphere_again_acts(float Cx, float Cy, float Cz, float R, float dt, float x,
                                          float y, float z, float vx, float vy, float vz) {
  const float speed = sqrt(vx * vx + vy * vy + vz * vz);
  const float slack = 4e-7f * (R + speed * dt);
  const float ex = x + vx * dt - Cx, ey = y + vy * dt - Cy, ez = z + vz * dt - Cz;
  const float bx = x - Cx, by = y - Cy, bz = z - Cz;
  return (sqrt(ex * ex + ey * ey + ez * ez) > R - slack) &
         !(sqrt(bx * bx + by * by + bz * bz) > R + slack);
}

FL_INLINE void fl_bounce_sphere_again(FlReflect rf, float Cx, float Cy, float Cz, float R, float R2,
                                      float dt, float* px, float* py, float* pz, float* vxs,
                                      float* vys, float* vzs) {
  const float x = *px, y = *py, z = *pz;
  float vx = *vxs, vy = *vys, vz = *vzs;
  if (!fl_bounce_sphere_again_acts(Cx, Cy, Cz, R, dt, x, y, z, vx, vy, vz)) return;
  float cx = x, cy = y, cz = z;
  float left = dt;
  for (int bounce = 0; bounce < 16; ++bounce) {
    const float rx = cx - Cx, ry = cy - Cy, rz = cz - Cz;
    const float bb = rx * vx + ry * vy + rz * vz, aa = vx * vx + vy * vy + vz * vz,
                c2 = rx * rx + ry * ry + rz * rz - R2;
    const float root = sqrt(fl_maxf(bb * bb - aa * c2, 0.0f));
    /* The exit root, in the form without cancellation for either sign of bb. */
    const float t = fl_maxf(bb > 0.0f ? -c2 / (bb + root) : (root - bb) / aa, 0.0f);
    if (!(t < left)) break; /* stays inside for the rest of the step */
    cx += vx * t;
    cy += vy * t;
    cz += vz * t;
    left -= t;
    /* On the sphere: never the centre. */
    float qx = cx, qy = cy, qz = cz;
    fl_reflect_any(rf, &qx, &qy, &qz, &vx, &vy, &vz, cx, cy, cz, cx - Cx, cy - Cy, cz - Cz, 0.0f);
  }
  float ox = cx + vx * left, oy = cy + vy * left, oz = cz + vz * left;
  /* Inside by more than Move's rounding of p + v·dt, which grows with |v|·dt. */
  const float margin = 4e-6f * R + 1e-6f * sqrt(vx * vx + vy * vy + vz * vz) * dt;
  const float dx = ox - Cx, dy = oy - Cy, dz = oz - Cz;
  const float dist = sqrt(dx * dx + dy * dy + dz * dz);
  if (dist > R - margin) {
    const float k = fl_maxf(R - margin, 0.5f * R) / dist;
    ox = Cx + dx * k;
    oy = Cy + dy * k;
    oz = Cz + dz * k;
  }
  *px = ox - vx * dt;
  *py = oy - vy * dt;
  *pz = oz - vz * dt;
  *vxs = vx;
  *vys = vy;
  *vzs = vz;
}

/* A box (lo, hi: its corners as arrays of three) keeping particles inside: each axis is its
 * own pair of walls (exact for an axis-aligned box, also in corners); friction acts on the
 * other two axes on a hit. */
/* Whether fl_bounce_box_inside acts on the particle: its step's end leaves the box on some
 * axis (its own test, the same arithmetic; the CPU tests a chunk with it, in vectors). */
FL_INLINE int fl_bounce_box_inside_acts(const float* lo, const float* hi, float dt, float x,
                                        float y, float z, float vx, float vy, float vz) {
  const float qx = x + vx * dt, qy = y + vy * dt, qz = z + vz * dt;
  return (qx < lo[0]) | (qx > hi[0]) | (qy < lo[1]) | (qy > hi[1]) | (qz < lo[2]) | (qz > hi[2]);
}

FL_INLINE void fl_bounce_box_inside(FlReflect rf, const float* lo, const float* hi, float dt,
                                    float* px, float* py, float* pz, float* vxs, float* vys,
                                    float* vzs) {
  float* p[3] = {px, py, pz};
  const float v[3] = {*vxs, *vys, *vzs};
  int hit[3];
  float wall[3], tau[3];
  for (int k = 0; k < 3; ++k) {
    const float x = *p[k], vk = v[k];
    const float q = x + vk * dt;
    hit[k] = q < lo[k] || q > hi[k];
    wall[k] = q > hi[k] ? hi[k] : lo[k];
    tau[k] = hit[k] ? fl_clampf((wall[k] - x) / vk, 0.0f, dt) : 0.0f;
  }
  if (!(hit[0] || hit[1] || hit[2])) return;
  /* The final velocity first: reflected on the axes that hit, slowed by friction on the
   * others; then positions that Move will carry to their reflected places. */
  float nv[3];
  for (int k = 0; k < 3; ++k) {
    nv[k] = hit[k] ? -v[k] * rf.restitution : v[k];
    for (int j = 0; j < 3; ++j) {
      if (j == k || !hit[j]) continue;
      const int a1 = (j + 1) % 3, a2 = (j + 2) % 3;
      const float t2 = v[a1] * v[a1] + v[a2] * v[a2];
      if (t2 > rf.cutoff2) nv[k] *= rf.keep;
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (hit[k]) {
      const float margin = 4e-7f * (fabs(wall[k]) + fabs(nv[k] * dt)) + 1e-30f;
      const float end = fl_clampf(wall[k] + nv[k] * (dt - tau[k]), lo[k] + margin, hi[k] - margin);
      *p[k] = end - nv[k] * dt;
    }
  }
  /* A slower velocity on an axis that did not hit stays between here and the old end. */
  *vxs = nv[0];
  *vys = nv[1];
  *vzs = nv[2];
}

/* A box deflecting from outside: the segment's entry face (slab method). */
FL_INLINE void fl_bounce_box_outside(FlReflect rf, const float* lo, const float* hi, float dt,
                                     float* px, float* py, float* pz, float* vxs, float* vys,
                                     float* vzs) {
  const float p[3] = {*px, *py, *pz}, v[3] = {*vxs, *vys, *vzs};
  /* Already in: not this deflector's business. */
  if ((p[0] >= lo[0]) & (p[0] <= hi[0]) & (p[1] >= lo[1]) & (p[1] <= hi[1]) & (p[2] >= lo[2]) &
      (p[2] <= hi[2]))
    return;
  float tEnter = 0.0f, tExit = dt;
  int axis = -1;
  int miss = 0;
  for (int k = 0; k < 3 && !miss; ++k) {
    if (v[k] == 0.0f) {
      miss = p[k] < lo[k] || p[k] > hi[k];
      continue;
    }
    float t0 = (lo[k] - p[k]) / v[k], t1 = (hi[k] - p[k]) / v[k];
    if (t0 > t1) {
      const float s = t0;
      t0 = t1;
      t1 = s;
    }
    if (t0 > tEnter) {
      tEnter = t0;
      axis = k;
    }
    tExit = fl_minf(tExit, t1);
    miss = tEnter > tExit;
  }
  if (miss || axis < 0) return;
  float nrm[3] = {0.0f, 0.0f, 0.0f};
  nrm[axis] = v[axis] > 0.0f ? -1.0f : 1.0f;
  const float hx = p[0] + v[0] * tEnter, hy = p[1] + v[1] * tEnter, hz = p[2] + v[2] * tEnter;
  float np[3] = {p[0], p[1], p[2]}, nv[3] = {v[0], v[1], v[2]};
  fl_reflect(rf, &np[0], &np[1], &np[2], &nv[0], &nv[1], &nv[2], hx, hy, hz, nrm[0], nrm[1], nrm[2],
             tEnter);
  /* Keep the end of the step outside the entry face. */
  const float face = nrm[axis] > 0.0f ? hi[axis] : lo[axis];
  const float q = np[axis] + nv[axis] * dt;
  const float margin = 4e-7f * (fabs(face) + fabs(q)) + 1e-30f;
  const float clearance = (q - face) * nrm[axis];
  if (clearance < margin) np[axis] += (2.0f * margin - clearance) * nrm[axis];
  *px = np[0];
  *py = np[1];
  *pz = np[2];
  *vxs = nv[0];
  *vys = nv[1];
  *vzs = nv[2];
}

/* ---- Planar pieces: planes, rectangles, triangles, discs, 2-D segments --------------------
 * A piece is a point P of its plane and a unit normal N, and a test of whether a point of the
 * plane lies on it, taken at w = point - P (the fl_on_* below). Deflection is two-sided. */

/* Whether the straight path from (x, y, z) over dt approaches the plane and reaches it.
 * Ending within a few ulps of the plane counts as arriving on it (Move's p + v·dt may round
 * onto the plane where d1 does not): bounced at the end of the step and pushed out, so that no
 * particle comes to rest on a piece by moving. */
FL_INLINE int fl_planar_reaches(float x, float y, float z, float vx, float vy, float vz, float dt,
                                float Px, float Py, float Pz, float Nx, float Ny, float Nz) {
  const float d0 = (x - Px) * Nx + (y - Py) * Ny + (z - Pz) * Nz;
  const float vn = vx * Nx + vy * Ny + vz * Nz;
  const float d1 = d0 + vn * dt;
  const float side = d0 >= 0.0f ? 1.0f : -1.0f;
  const float reach = 1.2e-7f * (fabs(Nx) * (fabs(x) + fabs(Px) + 2.0f * fabs(vx * dt)) +
                                 fabs(Ny) * (fabs(y) + fabs(Py) + 2.0f * fabs(vy * dt)) +
                                 fabs(Nz) * (fabs(z) + fabs(Pz) + 2.0f * fabs(vz * dt))) +
                      1e-30f;
  return (side * d1 <= reach) & (side * vn < 0.0f);
}

/* Where the path meets the plane (the time of impact *tau and the point *h, computed for
 * every particle: they may be inf where it does not), the side it starts on (±1), and
 * whether it hits the plane: reaching it, and not born or placed exactly on it (d0 = 0: such
 * a particle belongs to neither side and leaves freely, whichever way the normal points, so
 * an emitter on a floor emits through it). The caller adds whether h is on the piece. */
FL_INLINE int fl_planar_hit(float x, float y, float z, float vx, float vy, float vz, float dt,
                            float Px, float Py, float Pz, float Nx, float Ny, float Nz, float* side,
                            float* tau, float* hx, float* hy, float* hz) {
  const float d0 = (x - Px) * Nx + (y - Py) * Ny + (z - Pz) * Nz;
  const float vn = vx * Nx + vy * Ny + vz * Nz;
  const float d1 = d0 + vn * dt;
  *side = d0 >= 0.0f ? 1.0f : -1.0f;
  *tau = fl_minf(d0 / (d0 - d1), 1.0f) * dt;
  *hx = x + vx * *tau;
  *hy = y + vy * *tau;
  *hz = z + vz * *tau;
  return fl_planar_reaches(x, y, z, vx, vy, vz, dt, Px, Py, Pz, Nx, Ny, Nz) & (d0 != 0.0f);
}

/* The bounce of a particle that hits (hit != 0; the others are left as they are) at h after
 * tau: reflected, and pushed out if rounding would leave Move's p + v·dt on or behind the
 * plane. The margin is a few ulps of what decides the side: the coordinates along the normal
 * and the step Move adds to them; far from the origin along the plane it stays small, so
 * bounces do not gain height. One if-block (GCC vectorises it; not several selects). */
FL_INLINE void fl_planar_bounce(FlReflect rf, int hit, float side, float tau, float hx, float hy,
                                float hz, float dt, float Px, float Py, float Pz, float Nx,
                                float Ny, float Nz, float* px, float* py, float* pz, float* vxs,
                                float* vys, float* vzs) {
  const float x = *px, y = *py, z = *pz, vx = *vxs, vy = *vys, vz = *vzs;
  float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
  fl_reflect(rf, &nx, &ny, &nz, &nvx, &nvy, &nvz, hx, hy, hz, Nx, Ny, Nz, tau);
  const float qx = nx + nvx * dt, qy = ny + nvy * dt, qz = nz + nvz * dt;
  const float qd = side * ((qx - Px) * Nx + (qy - Py) * Ny + (qz - Pz) * Nz);
  const float margin = 1.2e-7f * (fabs(Nx) * (fabs(qx) + fabs(Px) + fabs(nvx * dt)) +
                                  fabs(Ny) * (fabs(qy) + fabs(Py) + fabs(nvy * dt)) +
                                  fabs(Nz) * (fabs(qz) + fabs(Pz) + fabs(nvz * dt))) +
                       1e-30f;
  const float push = fl_maxf(margin - qd, 0.0f) * side;
  float ox = x, oy = y, oz = z, ovx = vx, ovy = vy, ovz = vz;
  if (hit) {
    ox = nx + push * Nx;
    oy = ny + push * Ny;
    oz = nz + push * Nz;
    ovx = nvx;
    ovy = nvy;
    ovz = nvz;
  }
  *px = ox;
  *py = oy;
  *pz = oz;
  *vxs = ovx;
  *vys = ovy;
  *vzs = ovz;
}

/* The same piece when the following Move integrates with an acceleration (ax, ay, az) taken
 * as constant over the step (Exact with gravity and electric fields; Verlet and RK4 with their
 * first stage's): the particle runs the parabola p + v·t + ½a·t², so the impact is found on
 * it, and the velocity it has there, v + a·tau, is the one reflected (with the straight path
 * that velocity would be off by a·(dt − tau): first order). Where the path meets the plane
 * (*tau, *h), the side it starts on, and whether it hits: crossing within the step or ending
 * within a few ulps of the plane, approaching at the impact, not born on it. The caller adds
 * whether h is on the piece. */
FL_INLINE int fl_planar_accel_hit(float x, float y, float z, float vx, float vy, float vz, float ax,
                                  float ay, float az, float dt, float Px, float Py, float Pz,
                                  float Nx, float Ny, float Nz, float* side, float* tau, float* hx,
                                  float* hy, float* hz) {
  const float hdt2 = 0.5f * dt * dt;
  const float d0 = (x - Px) * Nx + (y - Py) * Ny + (z - Pz) * Nz;
  const float vn = vx * Nx + vy * Ny + vz * Nz;
  const float an = ax * Nx + ay * Ny + az * Nz;
  *side = d0 >= 0.0f ? 1.0f : -1.0f;
  /* Towards the side it is on: s(t) = s0 + u·t + ½w·t², s0 > 0 (0 when on the plane). */
  const float s0 = *side * d0, u = *side * vn, w = *side * an;
  const float s1 = s0 + u * dt + w * hdt2;
  const float reach =
      1.2e-7f * (fabs(Nx) * (fabs(x) + fabs(Px) + 2.0f * (fabs(vx * dt) + fabs(ax * hdt2))) +
                 fabs(Ny) * (fabs(y) + fabs(Py) + 2.0f * (fabs(vy * dt) + fabs(ay * hdt2))) +
                 fabs(Nz) * (fabs(z) + fabs(Pz) + 2.0f * (fabs(vz * dt) + fabs(az * hdt2)))) +
      1e-30f;
  /* The first root of s(t) = 0 in the forms without cancellation: approaching (u < 0)
   * 2·s0 / (√D − u); receding but pulled back (u ≥ 0, w < 0) (u + √D) / −w. D < 0: the path
   * turns before it reaches the plane. */
  const float D = u * u - 2.0f * w * s0;
  const float sq = sqrt(fl_maxf(D, 0.0f));
  const float root = u < 0.0f ? 2.0f * s0 / (sq - u) : (u + sq) / -w;
  const int crossing = (D >= 0.0f) & (root >= 0.0f) & (root <= dt);
  /* Or ending within a few ulps of the plane: an arrival at the end of the step. */
  *tau = crossing ? root : dt;
  *hx = x + (vx + 0.5f * ax * *tau) * *tau;
  *hy = y + (vy + 0.5f * ay * *tau) * *tau;
  *hz = z + (vz + 0.5f * az * *tau) * *tau;
  return (crossing | (s1 <= reach)) & (u + w * *tau < 0.0f) & (d0 != 0.0f);
}

/* The bounce of a particle that fl_planar_accel_hit found hitting the piece at h after tau:
 * the velocity at the impact reflected, then the start of a parabola through h at tau with
 * that velocity (v_start = v' − a·tau, p_start = h − v'·tau + ½a·tau²), so that the
 * integrator's p + v·dt + ½a·dt² runs the reflected parabola after the impact; pushed out if
 * rounding would leave that end on or behind the plane (the reflected parabola may also come
 * back through the plane within the step, a slow bounce: then it ends just in front). */
FL_INLINE void fl_planar_accel_bounce(FlReflect rf, float side, float tau, float hx, float hy,
                                      float hz, float dt, float ax, float ay, float az, float Px,
                                      float Py, float Pz, float Nx, float Ny, float Nz, float* px,
                                      float* py, float* pz, float* vxs, float* vys, float* vzs) {
  const float hdt2 = 0.5f * dt * dt;
  float nx = *px, ny = *py, nz = *pz;
  float nvx = *vxs + ax * tau, nvy = *vys + ay * tau, nvz = *vzs + az * tau;
  fl_reflect(rf, &nx, &ny, &nz, &nvx, &nvy, &nvz, hx, hy, hz, Nx, Ny, Nz, tau);
  const float htau2 = 0.5f * tau * tau;
  nx += ax * htau2;
  ny += ay * htau2;
  nz += az * htau2;
  nvx -= ax * tau;
  nvy -= ay * tau;
  nvz -= az * tau;
  const float sx = nvx * dt + 0.5f * ax * dt * dt, sy = nvy * dt + 0.5f * ay * dt * dt,
              sz = nvz * dt + 0.5f * az * dt * dt;
  const float qx = nx + sx, qy = ny + sy, qz = nz + sz;
  const float qd = side * ((qx - Px) * Nx + (qy - Py) * Ny + (qz - Pz) * Nz);
  const float margin =
      1.2e-7f * (fabs(Nx) * (fabs(qx) + fabs(Px) + fabs(nvx * dt) + fabs(ax * hdt2)) +
                 fabs(Ny) * (fabs(qy) + fabs(Py) + fabs(nvy * dt) + fabs(ay * hdt2)) +
                 fabs(Nz) * (fabs(qz) + fabs(Pz) + fabs(nvz * dt) + fabs(az * hdt2))) +
      1e-30f;
  const float push = fl_maxf(margin - qd, 0.0f) * side;
  *px = nx + push * Nx;
  *py = ny + push * Ny;
  *pz = nz + push * Nz;
  *vxs = nvx;
  *vys = nvy;
  *vzs = nvz;
}

/* A rectangle: (s, t) = (w·du, w·dv) in [0, 1]² (du, dv: the dual vectors of its edges,
 * which also serve a rhombus). */
FL_INLINE int fl_on_rectangle(float wx, float wy, float wz, float dux, float duy, float duz,
                              float dvx, float dvy, float dvz) {
  const float s = wx * dux + wy * duy + wz * duz;
  const float t = wx * dvx + wy * dvy + wz * dvz;
  return (s >= 0.0f) & (s <= 1.0f) & (t >= 0.0f) & (t <= 1.0f);
}

/* A triangle: barycentric (s, u) from the dual vectors d1, d2 of its edges from p0. */
FL_INLINE int fl_on_triangle(float wx, float wy, float wz, float d1x, float d1y, float d1z,
                             float d2x, float d2y, float d2z) {
  const float s = wx * d1x + wy * d1y + wz * d1z;
  const float u = wx * d2x + wy * d2y + wz * d2z;
  return (s >= 0.0f) & (u >= 0.0f) & (s + u <= 1.0f);
}

/* A disc or annulus: outer and inner radii squared. */
FL_INLINE int fl_on_disc(float wx, float wy, float wz, float outer2, float inner2) {
  const float r2 = wx * wx + wy * wy + wz * wz;
  return (r2 <= outer2) & (r2 >= inner2);
}

/* A 2-D segment (a wall standing on the group's plane): from p0 along dir, len2 = |dir|². */
FL_INLINE int fl_on_segment(float wx, float wy, float wz, float dx, float dy, float dz,
                            float len2) {
  const float t = (wx * dx + wy * dy + wz * dz) / len2;
  return (t >= 0.0f) & (t <= 1.0f);
}

/* Whether a point of the plane lies on Bounce's planar piece (FL_PIECE_*, params.h; a literal,
 * so the tests of the other pieces fold away), from the record both backends make. */
FL_INLINE int fl_on_piece(const FlBounceParams* b, int piece, float x, float y, float z) {
  const float wx = x - b->point.x, wy = y - b->point.y, wz = z - b->point.z;
  if (piece == FL_PIECE_RECTANGLE || piece == FL_PIECE_TRIANGLE) {
    const FlXyz u = b->piece.dual.u, v = b->piece.dual.v;
    return piece == FL_PIECE_RECTANGLE ? fl_on_rectangle(wx, wy, wz, u.x, u.y, u.z, v.x, v.y, v.z)
                                       : fl_on_triangle(wx, wy, wz, u.x, u.y, u.z, v.x, v.y, v.z);
  }
  if (piece == FL_PIECE_DISC)
    return fl_on_disc(wx, wy, wz, b->piece.disc.outer2, b->piece.disc.inner2);
  if (piece == FL_PIECE_SEGMENT) {
    const FlXyz d = b->piece.segment.direction;
    return fl_on_segment(wx, wy, wz, d.x, d.y, d.z, b->piece.segment.length2);
  }
  return 1;
}

/* ---- Collision events (Group::recordCollisions): where a deflected particle met a solid ---- */

/* When the straight path p + v·t meets a sphere (centre c, radius R) within [0, dt]: from
 * outside its first meeting, from inside its way out; the outward normal there (up when the
 * point is the centre). */
FL_INLINE float fl_sphere_hit(float px, float py, float pz, float vx, float vy, float vz, float cx,
                              float cy, float cz, float R, int inside, float dt, float* nx,
                              float* ny, float* nz) {
  const float dx = px - cx, dy = py - cy, dz = pz - cz;
  const float a = vx * vx + vy * vy + vz * vz, b = dx * vx + dy * vy + dz * vz,
              c = dx * dx + dy * dy + dz * dz - R * R;
  const float disc = fl_maxf(b * b - a * c, 0.0f);
  float t = a > 0.0f ? (inside ? (-b + sqrt(disc)) / a : (-b - sqrt(disc)) / a) : 0.0f;
  t = fl_clampf(t, 0.0f, dt);
  const float hx = dx + vx * t, hy = dy + vy * t, hz = dz + vz * t;
  const float len = sqrt(hx * hx + hy * hy + hz * hz);
  *nx = len > 0.0f ? hx / len : 0.0f;
  *ny = len > 0.0f ? hy / len : 1.0f;
  *nz = len > 0.0f ? hz / len : 0.0f;
  return t;
}

/* The same for a box (lo, hi): the face the path enters by (outside: the latest entry) or
 * leaves by (inside: the earliest exit), and that face's outward normal. */
FL_INLINE float fl_box_hit(const float* p, const float* v, const float* lo, const float* hi,
                           int inside, float dt, float* n) {
  float best = inside ? INFINITY : -INFINITY;
  int axis = 0;
  float sign = 1.0f;
  for (int k = 0; k < 3; ++k) {
    if (v[k] == 0.0f) continue;
    const float t0 = (lo[k] - p[k]) / v[k], t1 = (hi[k] - p[k]) / v[k];
    const float enter = fl_minf(t0, t1), leave = fl_maxf(t0, t1);
    if (inside ? leave < best : enter > best) {
      best = inside ? leave : enter;
      axis = k;
      /* The face met: max when moving + and leaving, or moving - and entering. */
      sign = (v[k] > 0.0f) == (inside != 0) ? 1.0f : -1.0f;
    }
  }
  for (int k = 0; k < 3; ++k) n[k] = k == axis ? sign : 0.0f;
  return fabs(best) < INFINITY ? fl_clampf(best, 0.0f, dt) : 0.0f;
}

#endif /* FLURRY_KERNELS_DEFLECT_H */
