/* Forces, targets and speed limits, per particle: written once for both backends in the
 * kernels' shared C subset (compat_opencl.h on the device, sdk/src/kernel_compat.hpp on the
 * CPU, whose loops call these on locals and still vectorise). Scalars in, what changes through
 * pointers; each side passes an action's constants as arguments from its own storage
 * (forces.cl unpacks FlActionParams, actions_more.hpp the action's struct).
 *
 * The fl_*_accel functions are a force as an acceleration at a state (integrate.hpp
 * accumulate(), and the device's integrators): they ADD to *ax, *ay, *az. The others change
 * the velocity over a step dt. Where a step is taken (a pull is zero, the particle is out of
 * reach) the result is a select rather than an early return, so the CPU's loops vectorise and
 * both sides add exactly the same terms. Sums of x, y, z go in glm's order. */
#ifndef FLURRY_KERNELS_FORCES_H
#define FLURRY_KERNELS_FORCES_H

/* A force's falloff: (1 - r/radius)^power inside the radius around (cx, cy, cz), 0 outside,
 * 1 everywhere for an infinite radius. */
typedef struct FlFalloff {
  float cx, cy, cz, radius, power;
} FlFalloff;

FL_INLINE float fl_falloff_weight(FlFalloff f, float px, float py, float pz) {
  if (!(f.radius < INFINITY)) return 1.0f;
  const float dx = px - f.cx, dy = py - f.cy, dz = pz - f.cz;
  const float t = fl_maxf(0.0f, 1.0f - sqrt(dx * dx + dy * dy + dz * dz) / f.radius);
  return f.power == 1.0f ? t : pow(t, f.power);
}

/* The fraction of the way an exponential approach at `rate` covers in dt: never above 1. */
FL_INLINE float fl_approach(float rate, float dt) {
  return 1.0f - exp(-rate * dt);
}

/* MatchVelocity and MatchRotVelocity: the mean of a field (fx, fy, fz) over the particles of
 * the step's start (n of them, at sx, sy, sz) within r2max (a squared radius) of p, `self`
 * left out, and the value (vx, vy, vz) carried towards it by k; left as it is with no
 * neighbour. */
FL_INLINE void fl_match_mean(const FL_GLOBAL float* sx, const FL_GLOBAL float* sy,
                             const FL_GLOBAL float* sz, const FL_GLOBAL float* fx,
                             const FL_GLOBAL float* fy, const FL_GLOBAL float* fz, uint n,
                             uint self, float r2max, float px, float py, float pz, float k,
                             float* vx, float* vy, float* vz) {
  float sumx = 0.0f, sumy = 0.0f, sumz = 0.0f;
  int count = 0;
  for (uint j = 0; j < n; ++j) {
    if (j == self) continue;
    const float dx = sx[j] - px, dy = sy[j] - py, dz = sz[j] - pz;
    if (dx * dx + dy * dy + dz * dz > r2max) continue;
    sumx += fx[j];
    sumy += fy[j];
    sumz += fz[j];
    ++count;
  }
  if (count == 0) return;
  const float c = (float)count;
  *vx = *vx + (sumx / c - *vx) * k;
  *vy = *vy + (sumy / c - *vy) * k;
  *vz = *vz + (sumz / c - *vz) * k;
}

/* Charge over mass: a particle of zero (or negative) mass feels no field. */
FL_INLINE float fl_charge_per_mass(float charge, float mass) {
  return mass > 0.0f ? charge / mass : 0.0f;
}

/* v += a * s. */
FL_INLINE void fl_add_scaled(float ax, float ay, float az, float s, float* vx, float* vy,
                             float* vz) {
  *vx = *vx + ax * s;
  *vy = *vy + ay * s;
  *vz = *vz + az * s;
}

/* ---- Softened pulls: OrbitPoint, OrbitLine, Gravitate, Follow ------------------------------ */

/* magnitude d / (|d|^2 + eps)^(3/2) into o; zero beyond sqrt(maxR2) and at the centre, where
 * s sqrt(s) underflows to 0 for eps below ~1e-26 and 0 inf would be NaN (the select keeps out
 * what is computed there). Elsewhere a pull that overflows stays infinite, and the NaN guard
 * kills the particle. */
FL_INLINE void fl_soft_pull(float dx, float dy, float dz, float magnitude, float eps, float maxR2,
                            float* ox, float* oy, float* oz) {
  const float r2 = dx * dx + dy * dy + dz * dz;
  const int pulls = (r2 <= maxR2) & (r2 > 0.0f);
  const float s = r2 + eps;
  const float k = magnitude / (s * sqrt(s));
  *ox = pulls ? dx * k : 0.0f;
  *oy = pulls ? dy * k : 0.0f;
  *oz = pulls ? dz * k : 0.0f;
}

/* OrbitLine: the pull towards the nearest point of the line through (lx, ly, lz) along the unit
 * axis (ux, uy, uz). */
FL_INLINE void fl_orbit_line_pull(float lx, float ly, float lz, float ux, float uy, float uz,
                                  float magnitude, float eps, float maxR2, float px, float py,
                                  float pz, float* ox, float* oy, float* oz) {
  const float wx = px - lx, wy = py - ly, wz = pz - lz;
  const float d = wx * ux + wy * uy + wz * uz;
  fl_soft_pull(-(wx - ux * d), -(wy - uy * d), -(wz - uz * d), magnitude, eps, maxR2, ox, oy, oz);
}

/* ---- Vortex ------------------------------------------------------------------------------- */

/* Centre, unit axis, the swirl's speed (aroundSpeed up to the core's radius, then falling off
 * as (core / r)^tightness), the inflow and the rise, and where it ends. */
typedef struct FlVortex {
  float cx, cy, cz, kx, ky, kz;
  float around, core, tightness, in, up, maxR;
} FlVortex;

/* The vortex's velocity field at p into u; 0 beyond maxR (the particle is left alone). */
FL_INLINE int fl_vortex_field(FlVortex v, float px, float py, float pz, float* ux, float* uy,
                              float* uz) {
  const float wx = px - v.cx, wy = py - v.cy, wz = pz - v.cz;
  const float d = wx * v.kx + wy * v.ky + wz * v.kz;
  const float rx = wx - v.kx * d, ry = wy - v.ky * d, rz = wz - v.kz * d;
  const float r = sqrt(rx * rx + ry * ry + rz * rz);
  /* On the axis there is no radial direction: no swirl, no inflow (finite, not NaN). */
  const float hx = r > 0.0f ? rx / r : 0.0f, hy = r > 0.0f ? ry / r : 0.0f,
              hz = r > 0.0f ? rz / r : 0.0f;
  const float around = r < v.core ? v.around * r / v.core : v.around * pow(v.core / r, v.tightness);
  *ux = (v.ky * hz - hy * v.kz) * around - hx * v.in + v.kx * v.up;
  *uy = (v.kz * hx - hz * v.kx) * around - hy * v.in + v.ky * v.up;
  *uz = (v.kx * hy - hx * v.ky) * around - hz * v.in + v.kz * v.up;
  return r <= v.maxR;
}

/* The velocity carried towards the field by k (fl_approach of responsiveness). */
FL_INLINE void fl_vortex_step(FlVortex v, float k, float px, float py, float pz, float* vx,
                              float* vy, float* vz) {
  float ux, uy, uz;
  if (!fl_vortex_field(v, px, py, pz, &ux, &uy, &uz)) return;
  *vx = *vx + (ux - *vx) * k;
  *vy = *vy + (uy - *vy) * k;
  *vz = *vz + (uz - *vz) * k;
}

FL_INLINE void fl_vortex_accel(FlVortex v, float responsiveness, float px, float py, float pz,
                               float vx, float vy, float vz, float* ax, float* ay, float* az) {
  float ux, uy, uz;
  if (!fl_vortex_field(v, px, py, pz, &ux, &uy, &uz)) return;
  *ax += (ux - vx) * responsiveness;
  *ay += (uy - vy) * responsiveness;
  *az += (uz - vz) * responsiveness;
}

/* ---- Jet ---------------------------------------------------------------------------------- */

/* Whether p lies in the ball where the jet acts (its acceleration is drawn by each side's
 * domain sampler). */
FL_INLINE int fl_in_ball(float cx, float cy, float cz, float radius, float px, float py, float pz) {
  const float dx = px - cx, dy = py - cy, dz = pz - cz;
  return dx * dx + dy * dy + dz * dz <= radius * radius;
}

/* ---- Explosion ---------------------------------------------------------------------------- */

/* A spherical pulse from (cx, cy, cz) whose front is at radius `front` (the caller computes it
 * from the time, in double): magnitude exp(-(r - front)^2 inv2s2) / (r^2 + eps) outwards, over
 * a step of dt. Nothing at the centre. inv2s2 = 1 / (2 stddev^2). */
FL_INLINE void fl_explosion_step(float cx, float cy, float cz, float magnitude, float inv2s2,
                                 float eps, float front, float dt, float px, float py, float pz,
                                 float* vx, float* vy, float* vz) {
  const float dx = px - cx, dy = py - cy, dz = pz - cz;
  const float r = sqrt(dx * dx + dy * dy + dz * dz);
  if (!(r > 0.0f)) return;
  const float delta = r - front;
  const float mag = magnitude * exp(-delta * delta * inv2s2) / (r * r + eps);
  fl_add_scaled(dx, dy, dz, mag / r * dt, vx, vy, vz);
}

/* The same as an acceleration; twoS2 = 2 stddev^2. */
FL_INLINE void fl_explosion_accel(float cx, float cy, float cz, float magnitude, float twoS2,
                                  float eps, float front, float px, float py, float pz, float* ax,
                                  float* ay, float* az) {
  const float dx = px - cx, dy = py - cy, dz = pz - cz;
  const float r = sqrt(dx * dx + dy * dy + dz * dz);
  if (!(r > 0.0f)) return;
  const float delta = r - front;
  const float s = magnitude * exp(-delta * delta / twoS2) / (r * r + eps) / r;
  *ax += dx * s;
  *ay += dy * s;
  *az += dz * s;
}

/* ---- Damping, fields ---------------------------------------------------------------------- */

/* Damping with a falloff weight w: each component decays at its rate for dt. */
FL_INLINE void fl_damping_step(float rx, float ry, float rz, float dt, float w, float* vx,
                               float* vy, float* vz) {
  *vx = *vx * exp(-rx * dt * w);
  *vy = *vy * exp(-ry * dt * w);
  *vz = *vz * exp(-rz * dt * w);
}

FL_INLINE void fl_damping_accel(float rx, float ry, float rz, float w, float vx, float vy, float vz,
                                float* ax, float* ay, float* az) {
  *ax += -rx * vx * w;
  *ay += -ry * vy * w;
  *az += -rz * vz * w;
}

/* MagneticField: v turns about the unit field direction k by theta = -(q/m)|B| dt w, exactly
 * (Rodrigues), in double where the device has it, so that the speed does not drift. */
FL_INLINE void fl_magnetic_turn(float kx, float ky, float kz, fl_real theta, float* vx, float* vy,
                                float* vz) {
  const fl_real ct = cos(theta), st = sin(theta);
  const fl_real x = *vx, y = *vy, z = *vz;
  const fl_real dx = kx, dy = ky, dz = kz;
  const fl_real d = (dx * x + dy * y + dz * z) * ((fl_real)1.0 - ct);
  *vx = (float)(x * ct + (dy * z - y * dz) * st + dx * d);
  *vy = (float)(y * ct + (dz * x - z * dx) * st + dy * d);
  *vz = (float)(z * ct + (dx * y - x * dy) * st + dz * d);
}

/* The Lorentz acceleration (v x B) q w; q is charge over mass. */
FL_INLINE void fl_magnetic_accel(float Bx, float By, float Bz, float q, float w, float vx, float vy,
                                 float vz, float* ax, float* ay, float* az) {
  *ax += (vy * Bz - By * vz) * q * w;
  *ay += (vz * Bx - Bz * vx) * q * w;
  *az += (vx * By - Bx * vy) * q * w;
}

/* ---- SampledField: a trilinear lookup in a grid of vectors (field.hpp VectorField::sample),
 * positions outside taking the border's value. Each side reads the eight corners from its
 * own storage (the CPU's vector, the device's buffer) and blends them here. */

/* Along an axis of n samples, at g voxels from the grid's origin: the cell's lower sample
 * *i0 and upper *i1 (the same at the last sample), and the weight of *i1. The clamp is
 * max(0, min()): the same values as fl_clampf, but GCC makes it minss/maxss where
 * fl_clampf's nested select became two branches, mispredicted for positions in and out of
 * the grid (1.7x slower on the CPU); and a NaN position (an earlier action's, before the
 * step's guard kills it) samples the first cell instead of casting NaN to int (undefined
 * behaviour, INT_MIN on x86: a read far outside the grid). */
FL_INLINE float fl_field_axis(float g, int n, int* i0, int* i1) {
  const float f = fl_maxf(0.0f, fl_minf(g, (float)(n - 1))); /* NaN -> 0 */
  const int lo = fl_mini((int)f, n - 1);
  *i0 = lo;
  *i1 = fl_mini(lo + 1, n - 1);
  return f - (float)lo;
}

/* One component blended from the eight corners, cXYZ at the lower (0) or upper (1) sample
 * along each axis, by the upper samples' weights tx, ty, tz: along x, then y, then z. */
FL_INLINE float fl_field_blend(float c000, float c100, float c010, float c110, float c001,
                               float c101, float c011, float c111, float tx, float ty, float tz) {
  const float sx = 1.0f - tx, sy = 1.0f - ty;
  const float c00 = c000 * sx + c100 * tx, c10 = c010 * sx + c110 * tx;
  const float c01 = c001 * sx + c101 * tx, c11 = c011 * sx + c111 * tx;
  return (c00 * sy + c10 * ty) * (1.0f - tz) + (c01 * sy + c11 * ty) * tz;
}

/* ---- Targets, speed limits ---------------------------------------------------------------- */

/* A value carried towards its target by k (fl_approach of the rate). */
FL_INLINE float fl_toward(float x, float target, float k) {
  return x + (target - x) * k;
}

/* SpeedClamp: a speed above maxS comes down to it, one below minS (but moving) up to it. */
FL_INLINE void fl_clamp_speed(float minS, float maxS, float* vx, float* vy, float* vz) {
  const float x = *vx, y = *vy, z = *vz;
  const float s = sqrt(x * x + y * y + z * z);
  const int over = s > maxS, under = (s < minS) & (s > 0.0f);
  const float k = over ? maxS / s : minS / s;
  const int take = over | under;
  *vx = take ? x * k : x;
  *vy = take ? y * k : y;
  *vz = take ? z * k : z;
}

/* ---- Avoid -------------------------------------------------------------------------------- */

/* Avoid's push away from an obstacle at distance dist, per second: v += away push dt. */
FL_INLINE float fl_avoid_push(float magnitude, float eps, float dist) {
  return magnitude / (dist * dist + eps);
}

/* ---- Constrain2D ------------------------------------------------------------------------- */

/* Constrain2D: the position onto the plane through o with unit normal n, p - n ((p - o)·n),
 * and the velocity onto its directions, v - n (v·n). */
FL_INLINE void fl_constrain_2d(float ox, float oy, float oz, float nx, float ny, float nz,
                               float* px, float* py, float* pz, float* vx, float* vy, float* vz) {
  const float x = *px, y = *py, z = *pz, u = *vx, v = *vy, w = *vz;
  const float d = (x - ox) * nx + (y - oy) * ny + (z - oz) * nz;
  const float e = u * nx + v * ny + w * nz;
  *px = x - nx * d;
  *py = y - ny * d;
  *pz = z - nz * d;
  *vx = u - nx * e;
  *vy = v - ny * e;
  *vz = w - nz * e;
}

/* ---- Restore ------------------------------------------------------------------------------ */

/* Restore steers once `time` has reached `start` (a nanosecond early counts: the host's and
 * the step's sums of dt differ in the last bits). */
FL_INLINE int fl_restore_started(fl_real start, fl_real time) {
  return !(time + (fl_real)1e-9 < start);
}

/* The seconds left until the arrival at `end` (start + duration). */
FL_INLINE float fl_restore_left(fl_real end, fl_real time) {
  return (float)(end - time);
}

/* Towards home h: the velocity that arrives in `left` seconds, or in the last step exactly;
 * a particle with dt = 0 (a newborn born at the step's very end) keeps its velocity. Once
 * left <= 0 it is home, at rest. */
FL_INLINE void fl_restore_step(float left, float dt, float hx, float hy, float hz, float* px,
                               float* py, float* pz, float* vx, float* vy, float* vz) {
  const float by = left > dt ? left : dt;
  if (dt > 0.0f) {
    *vx = (hx - *px) / by;
    *vy = (hy - *py) / by;
    *vz = (hz - *pz) / by;
  }
  if (left <= 0.0f) {
    *px = hx;
    *py = hy;
    *pz = hz;
    *vx = 0.0f;
    *vy = 0.0f;
    *vz = 0.0f;
  }
}

/* ---- Curves over life --------------------------------------------------------------------- */

/* Where a particle is in its life, 0 to 1 (1 for one without a lifetime). */
FL_INLINE float fl_life_fraction(float age, float life) {
  return life > 0.0f ? fl_clampf(age / life, 0.0f, 1.0f) : 1.0f;
}

/* Between two keys at t0 and t1: how far t is (1 where they coincide). */
FL_INLINE float fl_key_weight(float t0, float t1, float t) {
  const float span = t1 - t0;
  return span > 0.0f ? (t - t0) / span : 1.0f;
}

/* A curve's value at t (ColorOverLife, SizeOverLife): `count` keys of `stride` floats, its t
 * then stride - 1 values, t ascending. Before the first key the first's values, past the
 * last the last's, linear in between (a key found by walking: curves have a few keys). */
FL_INLINE void fl_curve_lookup(const FL_GLOBAL float* keys, uint count, uint stride, float t,
                               float* out) {
  uint hi = count; /* past the last key: its value */
  float w = 0.0f;
  if (t <= keys[0]) {
    hi = 0;
  } else {
    for (uint k = 1; k < count; ++k) {
      if (t <= keys[k * stride]) {
        w = fl_key_weight(keys[(k - 1) * stride], keys[k * stride], t);
        hi = k;
        break;
      }
    }
  }
  if (hi == 0 || hi == count) {
    const FL_GLOBAL float* v = keys + (hi == 0 ? 0u : (count - 1) * stride) + 1;
    for (uint c = 0; c + 1 < stride; ++c) out[c] = v[c];
    return;
  }
  const FL_GLOBAL float* v0 = keys + (hi - 1) * stride + 1;
  const FL_GLOBAL float* v1 = keys + hi * stride + 1;
  for (uint c = 0; c + 1 < stride; ++c) out[c] = v0[c] + (v1[c] - v0[c]) * w;
}

#endif /* FLURRY_KERNELS_FORCES_H */
