/* Forces, targets and speed limits, per particle: written once for both backends in the
 * kernels' shared C subset (compat_opencl.h on the device, sdk/src/kernel_compat.hpp on the
 * CPU, whose loops call these on locals and still vectorise). Scalars in, what changes through
 * pointers. Each force's own function (the last part of this file) takes its record
 * (params.h), which one maker fills for both backends (sdk/src/action_params.hpp): the device
 * passes the act kernel's copy, the CPU its own.
 *
 * The *_accel and *_acc functions are a force as an acceleration at a state (integrate.hpp
 * accumulate(), and the device's integrators): they ADD to *ax, *ay, *az. The others change
 * the velocity over a step dt. Where a step is taken (a pull is zero, the particle is out of
 * reach) the result is a select rather than an early return, so the CPU's loops vectorise and
 * both sides add exactly the same terms. Sums of x, y, z go in glm's order. */
#ifndef FLURRY_KERNELS_FORCES_H
#define FLURRY_KERNELS_FORCES_H

/* A force's falloff (its record's FlFalloffParams): (1 - r/radius)^power inside the radius
 * around (cx, cy, cz), 0 outside, 1 everywhere for an infinite radius. Every term is taken
 * before the choices (a loop over particles vectorises; the CPU's loops fold the unit power
 * and the infinite radius away, cpu/kernels.hpp withFalloff). */
FL_INLINE float fl_falloff_weight(FlFalloffParams f, float px, float py, float pz) {
  const float dx = px - f.cx, dy = py - f.cy, dz = pz - f.cz;
  const float t = fl_maxf(0.0f, 1.0f - sqrt(dx * dx + dy * dy + dz * dz) / f.radius);
  const float faded = fl_powf(t, f.power);
  const float w = f.power == 1.0f ? t : faded;
  return f.radius < INFINITY ? w : 1.0f;
}

/* The fraction of the way an exponential approach at `rate` covers in dt: never above 1. */
FL_INLINE float fl_approach(float rate, float dt) {
  return 1.0f - fl_expf(-rate * dt);
}

/* The value carried by k towards the mean of `count` neighbours' (their sum); as it was with
 * none. */
FL_INLINE void fl_match_finish(float sumx, float sumy, float sumz, int count, float k, float* vx,
                               float* vy, float* vz) {
  if (count == 0) return;
  const float c = (float)count;
  *vx = *vx + (sumx / c - *vx) * k;
  *vy = *vy + (sumy / c - *vy) * k;
  *vz = *vz + (sumz / c - *vz) * k;
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
  fl_match_finish(sumx, sumy, sumz, count, k, vx, vy, vz);
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
  /* On the axis there is no radial direction: no swirl, no inflow (finite, not NaN; the
   * offset there is below 1e-22, its square lost). One choice, of the divisor: GCC vectorises
   * the loop only with few choices of r (three on the unit vector were one too many). */
  const float safe = r > 0.0f ? r : 1.0f;
  const float hx = rx / safe, hy = ry / safe, hz = rz / safe;
  /* (Both sides taken before the choice: a loop over particles vectorises.) */
  const float outside = v.around * fl_powf(v.core / r, v.tightness);
  const float around = r < v.core ? v.around * r / v.core : outside;
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
  const float mag = magnitude * fl_expf(-delta * delta * inv2s2) / (r * r + eps);
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
  const float s = magnitude * fl_expf(-delta * delta / twoS2) / (r * r + eps) / r;
  *ax += dx * s;
  *ay += dy * s;
  *az += dz * s;
}

/* ---- Damping, fields ---------------------------------------------------------------------- */

/* Damping with a falloff weight w: each component decays at its rate for dt. */
FL_INLINE void fl_damping_step(float rx, float ry, float rz, float dt, float w, float* vx,
                               float* vy, float* vz) {
  *vx = *vx * fl_expf(-rx * dt * w);
  *vy = *vy * fl_expf(-ry * dt * w);
  *vz = *vz * fl_expf(-rz * dt * w);
}

FL_INLINE void fl_damping_accel(float rx, float ry, float rz, float w, float vx, float vy, float vz,
                                float* ax, float* ay, float* az) {
  *ax += -rx * vx * w;
  *ay += -ry * vy * w;
  *az += -rz * vz * w;
}

/* sin and cos of x in fl_real (double where the device has it) by arithmetic alone: the
 * backends' libm and builtin round their last bits apart, and a libm call per particle keeps
 * the CPU's loop scalar. fdlibm's reduction and kernels: x = k pi/2 + r, |r| <= pi/4, with
 * k = round(x 2/pi) by adding 1.5·2^52 (its spacing is 1; no conversion to an integer, so
 * no undefined behaviour for any x), pi/2 in three parts of 33 bits (k·part exact for
 * |k| < 2^20), then degree-13 and -14 polynomials in r. tests/test_random.cpp checks both
 * against libm's. |x| beyond 2^40 radians (no step's turn: the reduction would lose it)
 * turns by nothing; infinite or NaN x gives NaN. Without doubles the same steps in float
 * (1.5·2^23, |x| up to 2^22), less exact. */
#ifdef FL_FP64
#define FL_REAL_ROUNDER ((fl_real)6755399441055744.0) /* 1.5·2^52 */
#define FL_REAL_TURN_LIMIT ((fl_real)1099511627776.0) /* 2^40 */
#else
#define FL_REAL_ROUNDER ((fl_real)12582912.0) /* 1.5·2^23 */
#define FL_REAL_TURN_LIMIT ((fl_real)4194304.0) /* 2^22 */
#endif
FL_MATH_INLINE void fl_sincos_real(fl_real x, fl_real* sn, fl_real* cs) {
  x = fabs(x) <= FL_REAL_TURN_LIMIT ? x : x - x; /* inf - inf: NaN */
  const fl_real k = (x * (fl_real)6.36619772367581382433e-01 + FL_REAL_ROUNDER) - FL_REAL_ROUNDER;
  const fl_real r = ((x - k * (fl_real)1.57079632673412561417e+00) -
                     k * (fl_real)6.07710050630396597660e-11) -
                    k * (fl_real)2.02226624871116645580e-21;
  const fl_real z = r * r;
  const fl_real s =
      r + r * z *
              ((fl_real)-1.66666666666666324348e-01 +
               z * ((fl_real)8.33333333332248946124e-03 +
                    z * ((fl_real)-1.98412698298579493134e-04 +
                         z * ((fl_real)2.75573137070700676789e-06 +
                              z * ((fl_real)-2.50507602534068634195e-08 +
                                   z * (fl_real)1.58969099521155010221e-10)))));
  const fl_real c =
      ((fl_real)1.0 - (fl_real)0.5 * z) +
      z * z *
          ((fl_real)4.16666666666666019037e-02 +
           z * ((fl_real)-1.38888888888741095749e-03 +
                z * ((fl_real)2.48015872894767294178e-05 +
                     z * ((fl_real)-2.75573143513906633035e-07 +
                          z * ((fl_real)2.08757232129817482790e-09 +
                               z * (fl_real)-1.13596475577881948265e-11)))));
  /* The quadrant, k mod 4, as m = k - 4 round(k/4) in {-2, ..., 2}. */
  const fl_real m = k - (fl_real)4.0 * ((k * (fl_real)0.25 + FL_REAL_ROUNDER) - FL_REAL_ROUNDER);
  const fl_real am = fabs(m);
  const fl_real sr = am == (fl_real)1.0 ? c : s, cr = am == (fl_real)1.0 ? s : c;
  *sn = (am == (fl_real)2.0 || m == (fl_real)-1.0) ? -sr : sr;
  *cs = (am == (fl_real)2.0 || m == (fl_real)1.0) ? -cr : cr;
}

/* v turns about the unit vector k by theta, exactly (Rodrigues), in double where the device
 * has it, so that the length does not drift: a MagneticField's turn of the velocity, Move's
 * of the up vector. */
FL_INLINE void fl_turn_about(float kx, float ky, float kz, fl_real theta, float* vx, float* vy,
                             float* vz) {
  fl_real st, ct;
  fl_sincos_real(theta, &st, &ct);
  const fl_real x = *vx, y = *vy, z = *vz;
  const fl_real dx = kx, dy = ky, dz = kz;
  const fl_real d = (dx * x + dy * y + dz * z) * ((fl_real)1.0 - ct);
  *vx = (float)(x * ct + (dy * z - y * dz) * st + dx * d);
  *vy = (float)(y * ct + (dz * x - z * dx) * st + dy * d);
  *vz = (float)(z * ct + (dx * y - x * dy) * st + dz * d);
}

/* Move turns the up vector with the angular velocity w: about w by |w| dt. */
FL_INLINE void fl_turn_up(float dt, float* ux, float* uy, float* uz, float wx, float wy,
                          float wz) {
  const float speed = sqrt(wx * wx + wy * wy + wz * wz);
  if (!(speed > 0.0f)) return;
  fl_turn_about(wx / speed, wy / speed, wz / speed, (fl_real)(speed * dt), ux, uy, uz);
}

/* The Lorentz acceleration (v x B) q w; q is charge over mass. */
FL_INLINE void fl_magnetic_accel(float Bx, float By, float Bz, float q, float w, float vx, float vy,
                                 float vz, float* ax, float* ay, float* az) {
  *ax += (vy * Bz - By * vz) * q * w;
  *ay += (vz * Bx - Bz * vx) * q * w;
  *az += (vx * By - Bx * vy) * q * w;
}

/* ---- SampledField: a trilinear lookup in a grid of vectors (VectorField::sample),
 * positions outside taking the border's value (fl_grid_sample below). */

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

/* The field's value at p: a grid of nx x ny x nz vectors of three floats each, x fastest, at
 * `g`, from (ox, oy, oz) in steps of vs. Both backends read the same floats: the CPU its
 * VectorField's, the device its copy in the act kernel's `extra`. The corners' offsets are
 * taken in `index_t`: ulong (fl_grid_sample) for any grid (one may pass 2^32 floats); int
 * (fl_grid_sample_int) for a grid of fewer than 2^31 floats, whose lookups the CPU's loop
 * gathers in vectors (GCC vectorises a gather of 32-bit offsets, not of 64-bit ones). The same
 * values either way. */
#define FL_GRID_SAMPLE(name, index_t)                                                          \
  FL_INLINE float3 name(const FL_GLOBAL float* g, int nx, int ny, int nz, float ox, float oy,  \
                        float oz, float vs, float px, float py, float pz) {                    \
    int x0, x1, y0, y1, z0, z1;                                                                \
    const float tx = fl_field_axis((px - ox) / vs, nx, &x0, &x1);                              \
    const float ty = fl_field_axis((py - oy) / vs, ny, &y0, &y1);                              \
    const float tz = fl_field_axis((pz - oz) / vs, nz, &z0, &z1);                              \
    const index_t rx = (index_t)nx, rxy = (index_t)nx * (index_t)ny;                           \
    const index_t c000 = ((index_t)x0 + rx * (index_t)y0 + rxy * (index_t)z0) * 3;            \
    const index_t c100 = ((index_t)x1 + rx * (index_t)y0 + rxy * (index_t)z0) * 3;            \
    const index_t c010 = ((index_t)x0 + rx * (index_t)y1 + rxy * (index_t)z0) * 3;            \
    const index_t c110 = ((index_t)x1 + rx * (index_t)y1 + rxy * (index_t)z0) * 3;            \
    const index_t c001 = ((index_t)x0 + rx * (index_t)y0 + rxy * (index_t)z1) * 3;            \
    const index_t c101 = ((index_t)x1 + rx * (index_t)y0 + rxy * (index_t)z1) * 3;            \
    const index_t c011 = ((index_t)x0 + rx * (index_t)y1 + rxy * (index_t)z1) * 3;            \
    const index_t c111 = ((index_t)x1 + rx * (index_t)y1 + rxy * (index_t)z1) * 3;            \
    return make_float3(FL_GRID_BLEND(0), FL_GRID_BLEND(1), FL_GRID_BLEND(2));                  \
  }
/* Component k of the eight corners, blended. */
#define FL_GRID_BLEND(k)                                                                       \
  fl_field_blend(g[c000 + (k)], g[c100 + (k)], g[c010 + (k)], g[c110 + (k)], g[c001 + (k)],    \
                 g[c101 + (k)], g[c011 + (k)], g[c111 + (k)], tx, ty, tz)
FL_GRID_SAMPLE(fl_grid_sample, ulong)
FL_GRID_SAMPLE(fl_grid_sample_int, int)
#undef FL_GRID_BLEND
#undef FL_GRID_SAMPLE

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

/* ---- Each force from its record (params.h), as both backends call it ---------------------- */

/* exp(-rate dt): the maker's value (fl_expf) for the step length it made the record for, so
 * that both backends use the same bits; computed for any other length (a newborn's rest of its
 * step, a sub-step on the device). Computed before the choice, which then is a select: a loop
 * over newborns vectorises (GCC kept a branch where the exp was conditional). */
FL_INLINE float fl_force_decay(float rate, float dt, float madeDt, float made) {
  const float e = fl_expf(-rate * dt);
  return dt == madeDt ? made : e;
}

/* fl_approach, with the maker's exp for the step length it made the record for. */
FL_INLINE float fl_force_approach(float rate, float dt, float madeDt, float made) {
  const float k = fl_approach(rate, dt); /* (before the choice, as in fl_force_decay) */
  return dt == madeDt ? 1.0f - made : k;
}

/* Gravity: v + a dt; with a falloff v + a (dt w). */
FL_INLINE void fl_gravity(FlGravityParams g, float dt, float* vx, float* vy, float* vz) {
  *vx += g.acceleration.x * dt;
  *vy += g.acceleration.y * dt;
  *vz += g.acceleration.z * dt;
}

FL_INLINE void fl_gravity_falloff(FlGravityParams g, FlFalloffParams f, float dt, float px,
                                  float py, float pz, float* vx, float* vy, float* vz) {
  fl_add_scaled(g.acceleration.x, g.acceleration.y, g.acceleration.z,
                dt * fl_falloff_weight(f, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_gravity_acc(FlGravityParams g, FlFalloffParams f, float px, float py, float pz,
                              float* ax, float* ay, float* az) {
  const float w = fl_falloff_weight(f, px, py, pz);
  *ax += g.acceleration.x * w;
  *ay += g.acceleration.y * w;
  *az += g.acceleration.z * w;
}

/* Damping and RotDamping: each component decays at its rate over dt (exactly); with a falloff
 * at its rate times the weight. */
FL_INLINE void fl_damping_factors(FlDampingParams d, float dt, float* fx, float* fy, float* fz) {
  *fx = fl_force_decay(d.rate.x, dt, d.dt, d.decay.x);
  /* The same rate on every axis (the usual damping) decays the same: one exp, not three (a
   * newborn's own step length has no exp made for it). */
  if (d.rate.y == d.rate.x && d.rate.z == d.rate.x) {
    *fy = *fz = *fx;
    return;
  }
  *fy = fl_force_decay(d.rate.y, dt, d.dt, d.decay.y);
  *fz = fl_force_decay(d.rate.z, dt, d.dt, d.decay.z);
}

FL_INLINE void fl_damping(FlDampingParams d, float dt, float* vx, float* vy, float* vz) {
  float fx, fy, fz;
  fl_damping_factors(d, dt, &fx, &fy, &fz);
  *vx *= fx;
  *vy *= fy;
  *vz *= fz;
}

FL_INLINE void fl_damping_falloff(FlDampingParams d, FlFalloffParams f, float dt, float px,
                                  float py, float pz, float* vx, float* vy, float* vz) {
  fl_damping_step(d.rate.x, d.rate.y, d.rate.z, dt, fl_falloff_weight(f, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_damping_acc(FlDampingParams d, FlFalloffParams f, float px, float py, float pz,
                              float vx, float vy, float vz, float* ax, float* ay, float* az) {
  fl_damping_accel(d.rate.x, d.rate.y, d.rate.z, fl_falloff_weight(f, px, py, pz), vx, vy, vz, ax,
                   ay, az);
}

/* OrbitPoint: the softened pull towards its centre. */
FL_INLINE void fl_orbit_point_acc(FlOrbitPointParams o, float px, float py, float pz, float* ax,
                                  float* ay, float* az) {
  float x, y, z;
  fl_soft_pull(o.center.x - px, o.center.y - py, o.center.z - pz, o.magnitude, o.epsilon,
               o.maxRadius * o.maxRadius, &x, &y, &z);
  fl_add_scaled(x, y, z, 1.0f, ax, ay, az);
}

FL_INLINE void fl_orbit_point(FlOrbitPointParams o, float dt, float px, float py, float pz,
                              float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_soft_pull(o.center.x - px, o.center.y - py, o.center.z - pz, o.magnitude, o.epsilon,
               o.maxRadius * o.maxRadius, &x, &y, &z);
  fl_add_scaled(x, y, z, dt, vx, vy, vz);
}

/* OrbitLine: the softened pull towards the nearest point of its line. */
FL_INLINE void fl_orbit_line_acc(FlOrbitLineParams o, float px, float py, float pz, float* ax,
                                 float* ay, float* az) {
  float x, y, z;
  fl_orbit_line_pull(o.point.x, o.point.y, o.point.z, o.axis.x, o.axis.y, o.axis.z, o.magnitude,
                     o.epsilon, o.maxRadius * o.maxRadius, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, 1.0f, ax, ay, az);
}

FL_INLINE void fl_orbit_line(FlOrbitLineParams o, float dt, float px, float py, float pz,
                             float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_orbit_line_pull(o.point.x, o.point.y, o.point.z, o.axis.x, o.axis.y, o.axis.z, o.magnitude,
                     o.epsilon, o.maxRadius * o.maxRadius, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, dt, vx, vy, vz);
}

/* Vortex: the velocity carried towards its field. */
FL_INLINE FlVortex fl_vortex_of(FlVortexParams p) {
  const FlVortex v = {p.center.x,  p.center.y, p.center.z,    p.axis.x,     p.axis.y,
                      p.axis.z,    p.aroundSpeed, p.coreRadius, p.tightness, p.inSpeed,
                      p.upSpeed,   p.maxRadius};
  return v;
}

FL_INLINE void fl_vortex(FlVortexParams p, float dt, float px, float py, float pz, float* vx,
                         float* vy, float* vz) {
  fl_vortex_step(fl_vortex_of(p), fl_force_approach(p.responsiveness, dt, p.dt, p.decay), px, py,
                 pz, vx, vy, vz);
}

FL_INLINE void fl_vortex_acc(FlVortexParams p, float px, float py, float pz, float vx, float vy,
                             float vz, float* ax, float* ay, float* az) {
  fl_vortex_accel(fl_vortex_of(p), p.responsiveness, px, py, pz, vx, vy, vz, ax, ay, az);
}

/* Jet: whether p is where it acts (its acceleration each side draws from its domain). */
FL_INLINE int fl_jet_reaches(FlJetParams j, float px, float py, float pz) {
  return fl_in_ball(j.center.x, j.center.y, j.center.z, j.radius, px, py, pz);
}

/* Explosion: the pulse whose front is at its radius at mid-step (from the time, in double). */
FL_INLINE void fl_explosion(FlExplosionParams e, float dt, fl_real time, float px, float py,
                            float pz, float* vx, float* vy, float* vz) {
  const fl_real t = time + (fl_real)0.5 * (fl_real)dt;
  if (t < (fl_real)e.time) return;
  const float front = e.speed * (float)(t - (fl_real)e.time);
  fl_explosion_step(e.center.x, e.center.y, e.center.z, e.magnitude, e.invTwoVariance, e.epsilon,
                    front, dt, px, py, pz, vx, vy, vz);
}

FL_INLINE void fl_explosion_acc(FlExplosionParams e, fl_real t, float px, float py, float pz,
                                float* ax, float* ay, float* az) {
  if (!(t >= (fl_real)e.time)) return;
  const float front = e.speed * (float)(t - (fl_real)e.time);
  fl_explosion_accel(e.center.x, e.center.y, e.center.z, e.magnitude, e.twoVariance, e.epsilon,
                     front, px, py, pz, ax, ay, az);
}

/* Turbulence: curl noise (noise.h) at the time, weighed by the falloff. */
FL_INLINE FlTurbulence fl_turbulence_of(FlTurbulenceParams p) {
  const FlTurbulence t = {p.amplitude, p.frequency, p.drift.x, p.drift.y, p.drift.z, p.octaves};
  return t;
}

FL_INLINE void fl_turbulence(FlTurbulenceParams p, FlFalloffParams f, float dt, fl_real time,
                             float px, float py, float pz, float* vx, float* vy, float* vz) {
  const float3 acc = fl_turbulence_field(fl_turbulence_of(p), (float)time, px, py, pz);
  fl_add_scaled(acc.x, acc.y, acc.z, dt * fl_falloff_weight(f, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_turbulence_acc(FlTurbulenceParams p, FlFalloffParams f, fl_real t, float px,
                                 float py, float pz, float* ax, float* ay, float* az) {
  fl_turbulence_accel(fl_turbulence_of(p), (float)t, fl_falloff_weight(f, px, py, pz), px, py, pz,
                      ax, ay, az);
}

/* ElectricField: q E dt w, q the charge over mass. */
FL_INLINE void fl_electric(FlElectricParams e, FlFalloffParams f, float dt, float px, float py,
                           float pz, float* vx, float* vy, float* vz, float charge, float mass) {
  const float w = fl_falloff_weight(f, px, py, pz);
  fl_add_scaled(e.field.x, e.field.y, e.field.z, fl_charge_per_mass(charge, mass) * dt * w, vx,
                vy, vz);
}

FL_INLINE void fl_electric_acc(FlElectricParams e, FlFalloffParams f, float px, float py, float pz,
                               float charge, float mass, float* ax, float* ay, float* az) {
  const float q = fl_charge_per_mass(charge, mass);
  const float w = fl_falloff_weight(f, px, py, pz);
  *ax += e.field.x * q * w;
  *ay += e.field.y * q * w;
  *az += e.field.z * q * w;
}

/* MagneticField: v turns about B by -(q/m)|B| dt w, exactly (fl_turn_about), for a field
 * of strength > 0 (fl_magnetic tests it; the CPU's loop tests it once, before: GCC left the
 * loop scalar with the test inside). */
FL_INLINE void fl_magnetic_field_on(FlMagneticParams m, FlFalloffParams f, float dt, float px,
                                    float py, float pz, float* vx, float* vy, float* vz,
                                    float charge, float mass) {
  const fl_real theta = -(fl_real)fl_charge_per_mass(charge, mass) * (fl_real)m.strength *
                        (fl_real)dt * (fl_real)fl_falloff_weight(f, px, py, pz);
  fl_turn_about(m.direction.x, m.direction.y, m.direction.z, theta, vx, vy, vz);
}

FL_INLINE void fl_magnetic(FlMagneticParams m, FlFalloffParams f, float dt, float px, float py,
                           float pz, float* vx, float* vy, float* vz, float charge, float mass) {
  if (m.strength > 0.0f) fl_magnetic_field_on(m, f, dt, px, py, pz, vx, vy, vz, charge, mass);
}

FL_INLINE void fl_magnetic_acc(FlMagneticParams m, FlFalloffParams f, float px, float py, float pz,
                               float vx, float vy, float vz, float charge, float mass, float* ax,
                               float* ay, float* az) {
  fl_magnetic_accel(m.field.x, m.field.y, m.field.z, fl_charge_per_mass(charge, mass),
                    fl_falloff_weight(f, px, py, pz), vx, vy, vz, ax, ay, az);
}

/* SampledField, from the field's value (ux, uy, uz) at p (each side samples its own copy of
 * the grid with fl_field_axis and fl_field_blend) and the falloff's weight w: an acceleration
 * (v + u s dt w), or carried towards it (Mode::Velocity) by `approach`, the carry's
 * fl_force_approach(s.responsiveness, dt, s.dt, s.decay) (unread without a carry), which a
 * loop over particles of one step length takes once. fl_sampled_field takes it itself. */
FL_INLINE void fl_sampled_field_approach(FlSampledFieldParams s, float approach, float dt, float w,
                                         float ux, float uy, float uz, float* vx, float* vy,
                                         float* vz) {
  ux = ux * s.strength;
  uy = uy * s.strength;
  uz = uz * s.strength;
  if (s.carry) {
    const float kw = approach * w;
    *vx = *vx + (ux - *vx) * kw;
    *vy = *vy + (uy - *vy) * kw;
    *vz = *vz + (uz - *vz) * kw;
  } else {
    const float k = dt * w;
    *vx = *vx + ux * k;
    *vy = *vy + uy * k;
    *vz = *vz + uz * k;
  }
}

FL_INLINE void fl_sampled_field(FlSampledFieldParams s, float dt, float w, float ux, float uy,
                                float uz, float* vx, float* vy, float* vz) {
  const float approach = s.carry ? fl_force_approach(s.responsiveness, dt, s.dt, s.decay) : 0.0f;
  fl_sampled_field_approach(s, approach, dt, w, ux, uy, uz, vx, vy, vz);
}

FL_INLINE void fl_sampled_field_acc(FlSampledFieldParams s, float w, float ux, float uy, float uz,
                                    float vx, float vy, float vz, float* ax, float* ay,
                                    float* az) {
  ux = ux * s.strength;
  uy = uy * s.strength;
  uz = uz * s.strength;
  if (s.carry) {
    ux = (ux - vx) * s.responsiveness;
    uy = (uy - vy) * s.responsiveness;
    uz = (uz - vz) * s.responsiveness;
  }
  *ax += ux * w;
  *ay += uy * w;
  *az += uz * w;
}

/* Targets: each value carried towards the target by fl_approach of the rate. */
FL_INLINE float fl_target_k(FlTargetParams t, float dt) {
  return fl_force_approach(t.rate, dt, t.dt, t.decay);
}

FL_INLINE void fl_target3(FlTargetParams t, float dt, float* x, float* y, float* z) {
  const float k = fl_target_k(t, dt);
  *x = fl_toward(*x, t.target[0], k);
  *y = fl_toward(*y, t.target[1], k);
  *z = fl_toward(*z, t.target[2], k);
}

FL_INLINE void fl_target_color(FlTargetParams t, float dt, float* r, float* g, float* b,
                               float* al) {
  const float k = fl_target_k(t, dt);
  *r = fl_toward(*r, t.target[0], k);
  *g = fl_toward(*g, t.target[1], k);
  *b = fl_toward(*b, t.target[2], k);
  *al = fl_toward(*al, t.target[3], k);
}

FL_INLINE void fl_target_size(FlTargetParams t, float dt, float* size) {
  *size = fl_toward(*size, t.target[0], fl_target_k(t, dt));
}

/* SpeedClamp. */
FL_INLINE void fl_speed_clamp(FlSpeedClampParams c, float* vx, float* vy, float* vz) {
  fl_clamp_speed(c.minSpeed, c.maxSpeed, vx, vy, vz);
}

/* Gravitate and Follow: the softened pull towards a neighbour (dx, dy, dz) away, into o. */
FL_INLINE void fl_pull(FlPullParams q, float dx, float dy, float dz, float* ox, float* oy,
                       float* oz) {
  fl_soft_pull(dx, dy, dz, q.magnitude, q.epsilon, q.maxRadius2, ox, oy, oz);
}

/* MatchVelocity and MatchRotVelocity: how far towards the neighbours' mean over dt (the
 * maker's approach for the step length it made the record for). */
FL_INLINE float fl_match_k(FlMatchParams m, float dt) {
  return dt == m.dt ? m.approach : 1.0f - fl_expf(-m.rate * dt);
}

/* Avoid: the change of speed away from an obstacle at distance dist over dt. */
FL_INLINE float fl_avoid_step(FlAvoidParams a, float dist, float dt) {
  return fl_avoid_push(a.magnitude, a.epsilon, dist) * dt;
}

/* Constrain2D onto its plane (fl_constrain_2d; the normal is unit). */
FL_INLINE void fl_constrain2d(FlConstrain2DParams c, float* px, float* py, float* pz, float* vx,
                              float* vy, float* vz) {
  fl_constrain_2d(c.point.x, c.point.y, c.point.z, c.normal.x, c.normal.y, c.normal.z, px, py, pz,
                  vx, vy, vz);
}

/* Restore towards home (hx, hy, hz) from its start (fl_restore_step); dt is the particle's
 * (sub-)step, `time` when it begins. */
FL_INLINE void fl_restore(FlRestoreParams r, float dt, fl_real time, float* px, float* py,
                          float* pz, float* vx, float* vy, float* vz, float hx, float hy,
                          float hz) {
  if (!fl_restore_started(fl_real_from_bits(r.start), time)) return;
  const float left = fl_restore_left(fl_real_from_bits(r.end), time);
  fl_restore_step(left, dt, hx, hy, hz, px, py, pz, vx, vy, vz);
}

#endif /* FLURRY_KERNELS_FORCES_H */
