/* Forces, random and target actions, curves over life (sdk/src/opencl/actions_forces.cpp
 * generates their calls and packs their constants, and documents each one's f[] and u[]).
 * Each follows sdk/src/cpu/kernels.hpp, actions_more.hpp and integrate.hpp operation by
 * operation, in the same order (glm's vector operations componentwise), so that with
 * FP_CONTRACT off and correctly rounded division and sqrt the results agree to the bit
 * except where a libm call (exp, pow, cos, sin) differs from the device's builtin.
 *
 * The fl_*_acc functions are the forces as accelerations at a state (integrate.hpp
 * accumulate()): they add to *ax, *ay, *az, as the CPU adds each force's acc to the stage's. */

/* Where a force has a falloff, its five floats sit at f[FL_FALLOFF]: center xyz, radius,
 * power. */
#define FL_FALLOFF 27

/* actions_more.hpp falloffWeight: (1 - r/radius)^power inside the radius, 0 outside, 1 for
 * an infinite radius. */
FL_INLINE float fl_force_falloff(__global const FlActionParams* a, float px, float py, float pz) {
  __global const float* f = a->f + FL_FALLOFF;
  if (!(f[3] < INFINITY)) return 1.0f;
  const float dx = px - f[0], dy = py - f[1], dz = pz - f[2];
  const float t = fl_maxf(0.0f, 1.0f - sqrt(dx * dx + dy * dy + dz * dz) / f[3]);
  return f[4] == 1.0f ? t : pow(t, f[4]);
}

/* exp(-rate * dt): the host's value (std::exp, as the CPU's) for the step length it packed,
 * so the two agree to the bit; the device's own for a sub-step's other length. */
FL_INLINE float fl_force_decay(float rate, float dt, float packedDt, float packed) {
  return dt == packedDt ? packed : exp(-rate * dt);
}

/* actions_more.hpp approach(): the fraction of the way an exponential approach covers. */
FL_INLINE float fl_force_approach(float rate, float dt, float packedDt, float packed) {
  return 1.0f - fl_force_decay(rate, dt, packedDt, packed);
}

/* actions_more.hpp softPull: magnitude * d / (|d|^2 + eps)^(3/2), zero beyond maxR and at
 * the centre (where s sqrt(s) underflows to 0 for a tiny eps: 0 inf would be NaN). */
FL_INLINE void fl_force_soft_pull(float dx, float dy, float dz, float magnitude, float eps,
                                  float maxR, float* ox, float* oy, float* oz) {
  const float r2 = dx * dx + dy * dy + dz * dz;
  if (!(r2 <= maxR * maxR) || !(r2 > 0.0f)) {
    *ox = 0.0f;
    *oy = 0.0f;
    *oz = 0.0f;
    return;
  }
  const float s = r2 + eps;
  const float k = magnitude / (s * sqrt(s));
  *ox = dx * k;
  *oy = dy * k;
  *oz = dz * k;
}

/* actions_more.hpp chargePerMass: a particle of zero (or negative) mass feels no field. */
FL_INLINE float fl_force_charge_per_mass(float charge, float mass) {
  return mass > 0.0f ? charge / mass : 0.0f;
}

/* ---- Gravity: f[0..2] acceleration --------------------------------------------------- */

FL_INLINE void fl_gravity(__global const FlActionParams* a, float dt, float* vx, float* vy,
                          float* vz) {
  *vx += a->f[0] * dt;
  *vy += a->f[1] * dt;
  *vz += a->f[2] * dt;
}

FL_INLINE void fl_gravity_falloff(__global const FlActionParams* a, float dt, float px, float py,
                                  float pz, float* vx, float* vy, float* vz) {
  const float s = dt * fl_force_falloff(a, px, py, pz);
  *vx = *vx + a->f[0] * s;
  *vy = *vy + a->f[1] * s;
  *vz = *vz + a->f[2] * s;
}

FL_INLINE void fl_gravity_acc(__global const FlActionParams* a, float px, float py, float pz,
                              float* ax, float* ay, float* az) {
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += a->f[0] * w;
  *ay += a->f[1] * w;
  *az += a->f[2] * w;
}

/* ---- Damping, RotDamping: f[0..2] exp(-rate * dt), f[3..5] rate, f[6] that dt -------- */

FL_INLINE void fl_damping(__global const FlActionParams* a, float dt, float* vx, float* vy,
                          float* vz) {
  *vx *= fl_force_decay(a->f[3], dt, a->f[6], a->f[0]);
  *vy *= fl_force_decay(a->f[4], dt, a->f[6], a->f[1]);
  *vz *= fl_force_decay(a->f[5], dt, a->f[6], a->f[2]);
}

FL_INLINE void fl_damping_falloff(__global const FlActionParams* a, float dt, float px, float py,
                                  float pz, float* vx, float* vy, float* vz) {
  const float w = fl_force_falloff(a, px, py, pz);
  *vx = *vx * exp(-a->f[3] * dt * w);
  *vy = *vy * exp(-a->f[4] * dt * w);
  *vz = *vz * exp(-a->f[5] * dt * w);
}

FL_INLINE void fl_damping_acc(__global const FlActionParams* a, float px, float py, float pz,
                              float vx, float vy, float vz, float* ax, float* ay, float* az) {
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += -a->f[3] * vx * w;
  *ay += -a->f[4] * vy * w;
  *az += -a->f[5] * vz * w;
}

/* ---- OrbitPoint: f[0..2] center, [3] magnitude, [4] epsilon, [5] maxRadius ------------- */

FL_INLINE void fl_orbit_point_acc(__global const FlActionParams* a, float px, float py, float pz,
                                  float* ax, float* ay, float* az) {
  float x, y, z;
  fl_force_soft_pull(a->f[0] - px, a->f[1] - py, a->f[2] - pz, a->f[3], a->f[4], a->f[5], &x, &y,
                     &z);
  *ax += x;
  *ay += y;
  *az += z;
}

FL_INLINE void fl_orbit_point(__global const FlActionParams* a, float dt, float px, float py,
                              float pz, float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_force_soft_pull(a->f[0] - px, a->f[1] - py, a->f[2] - pz, a->f[3], a->f[4], a->f[5], &x, &y,
                     &z);
  *vx = *vx + x * dt;
  *vy = *vy + y * dt;
  *vz = *vz + z * dt;
}

/* ---- OrbitLine: f[0..2] point, [3..5] unit axis, [6] magnitude, [7] eps, [8] maxRadius -- */

FL_INLINE void fl_orbit_line_pull(__global const FlActionParams* a, float px, float py, float pz,
                                  float* x, float* y, float* z) {
  const float ux = a->f[3], uy = a->f[4], uz = a->f[5];
  const float wx = px - a->f[0], wy = py - a->f[1], wz = pz - a->f[2];
  const float d = wx * ux + wy * uy + wz * uz;
  /* towards the nearest point of the line */
  fl_force_soft_pull(-(wx - ux * d), -(wy - uy * d), -(wz - uz * d), a->f[6], a->f[7], a->f[8], x,
                     y, z);
}

FL_INLINE void fl_orbit_line(__global const FlActionParams* a, float dt, float px, float py,
                             float pz, float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_orbit_line_pull(a, px, py, pz, &x, &y, &z);
  *vx = *vx + x * dt;
  *vy = *vy + y * dt;
  *vz = *vz + z * dt;
}

FL_INLINE void fl_orbit_line_acc(__global const FlActionParams* a, float px, float py, float pz,
                                 float* ax, float* ay, float* az) {
  float x, y, z;
  fl_orbit_line_pull(a, px, py, pz, &x, &y, &z);
  *ax += x;
  *ay += y;
  *az += z;
}

/* ---- Vortex: f[0..2] center, [3..5] unit axis, [6] aroundSpeed, [7] coreRadius,
 * [8] tightness, [9] inSpeed, [10] upSpeed, [11] responsiveness, [12] maxRadius,
 * [13] packed dt, [14] exp(-responsiveness * dt) ------------------------------------------ */

/* The vortex's velocity field at p into u; 0 beyond maxRadius (the particle is left alone). */
FL_INLINE int fl_vortex_u(__global const FlActionParams* a, float px, float py, float pz, float* ux,
                          float* uy, float* uz) {
  const float kx = a->f[3], ky = a->f[4], kz = a->f[5];
  const float wx = px - a->f[0], wy = py - a->f[1], wz = pz - a->f[2];
  const float d = wx * kx + wy * ky + wz * kz;
  const float rx = wx - kx * d, ry = wy - ky * d, rz = wz - kz * d;
  const float r = sqrt(rx * rx + ry * ry + rz * rz);
  if (!(r <= a->f[12])) return 0;
  /* On the axis there is no radial direction: no swirl, no inflow. */
  const float hx = r > 0.0f ? rx / r : 0.0f, hy = r > 0.0f ? ry / r : 0.0f,
              hz = r > 0.0f ? rz / r : 0.0f;
  const float around = r < a->f[7] ? a->f[6] * r / a->f[7] : a->f[6] * pow(a->f[7] / r, a->f[8]);
  const float in = a->f[9], up = a->f[10];
  *ux = (ky * hz - hy * kz) * around - hx * in + kx * up;
  *uy = (kz * hx - hz * kx) * around - hy * in + ky * up;
  *uz = (kx * hy - hx * ky) * around - hz * in + kz * up;
  return 1;
}

FL_INLINE void fl_vortex(__global const FlActionParams* a, float dt, float px, float py, float pz,
                         float* vx, float* vy, float* vz) {
  const float k = fl_force_approach(a->f[11], dt, a->f[13], a->f[14]);
  float ux, uy, uz;
  if (!fl_vortex_u(a, px, py, pz, &ux, &uy, &uz)) return;
  *vx = *vx + (ux - *vx) * k;
  *vy = *vy + (uy - *vy) * k;
  *vz = *vz + (uz - *vz) * k;
}

FL_INLINE void fl_vortex_acc(__global const FlActionParams* a, float px, float py, float pz,
                             float vx, float vy, float vz, float* ax, float* ay, float* az) {
  float ux, uy, uz;
  if (!fl_vortex_u(a, px, py, pz, &ux, &uy, &uz)) return;
  *ax += (ux - vx) * a->f[11];
  *ay += (uy - vy) * a->f[11];
  *az += (uz - vz) * a->f[11];
}

/* ---- Jet: f[0..2] center, [3] radius; domain: the acceleration (kind a literal; a mesh's
 * or union's data in `shapes`, the act kernel's extra) ---------------------------------- */

FL_INLINE int fl_jet_accel(__global const FlActionParams* a, uint kind, float px, float py,
                           float pz, uint id, uint seedLo, uint seedHi, uint step, uint stream,
                           float3* acc, __global const float* shapes) {
  const float dx = px - a->f[0], dy = py - a->f[1], dz = pz - a->f[2];
  if (!(dx * dx + dy * dy + dz * dz <= a->f[3] * a->f[3])) return 0;
  FlRandom rng = fl_random(seedLo, seedHi, id, step, stream);
  /* a point domain: its point, no draw */
  *acc = fl_sample_any(&a->domain, kind, &rng, shapes);
  return 1;
}

FL_INLINE void fl_jet(__global const FlActionParams* a, uint kind, float dt, float px, float py,
                      float pz, float* vx, float* vy, float* vz, uint id, uint seedLo, uint seedHi,
                      uint step, uint stream, __global const float* shapes) {
  float3 acc;
  if (!fl_jet_accel(a, kind, px, py, pz, id, seedLo, seedHi, step, stream, &acc, shapes)) return;
  *vx = *vx + acc.x * dt;
  *vy = *vy + acc.y * dt;
  *vz = *vz + acc.z * dt;
}

FL_INLINE void fl_jet_acc(__global const FlActionParams* a, uint kind, float px, float py, float pz,
                          uint id, uint seedLo, uint seedHi, uint step, uint stream,
                          __global const float* shapes, float* ax, float* ay, float* az) {
  float3 acc;
  if (!fl_jet_accel(a, kind, px, py, pz, id, seedLo, seedHi, step, stream, &acc, shapes)) return;
  *ax += acc.x;
  *ay += acc.y;
  *az += acc.z;
}

/* ---- Explosion: f[0..2] center, [3] speed, [4] magnitude, [5] 1 / (2 stddev^2),
 * [6] epsilon, [7] time, [8] 2 stddev^2 ------------------------------------------------- */

FL_INLINE void fl_explosion(__global const FlActionParams* a, float dt, fl_real time, float px,
                            float py, float pz, float* vx, float* vy, float* vz) {
  const fl_real t = time + (fl_real)0.5 * (fl_real)dt; /* the front's radius at mid-step */
  if (t < (fl_real)a->f[7]) return;
  const float front = a->f[3] * (float)(t - (fl_real)a->f[7]);
  const float dx = px - a->f[0], dy = py - a->f[1], dz = pz - a->f[2];
  const float r = sqrt(dx * dx + dy * dy + dz * dz);
  if (!(r > 0.0f)) return;
  const float delta = r - front;
  const float mag = a->f[4] * exp(-delta * delta * a->f[5]) / (r * r + a->f[6]);
  const float s = mag / r * dt;
  *vx = *vx + dx * s;
  *vy = *vy + dy * s;
  *vz = *vz + dz * s;
}

FL_INLINE void fl_explosion_acc(__global const FlActionParams* a, fl_real t, float px, float py,
                                float pz, float* ax, float* ay, float* az) {
  if (!(t >= (fl_real)a->f[7])) return;
  const float dx = px - a->f[0], dy = py - a->f[1], dz = pz - a->f[2];
  const float r = sqrt(dx * dx + dy * dy + dz * dz);
  if (!(r > 0.0f)) return;
  const float delta = r - a->f[3] * (float)(t - (fl_real)a->f[7]);
  const float s = a->f[4] * exp(-delta * delta / a->f[8]) / (r * r + a->f[6]) / r;
  *ax += dx * s;
  *ay += dy * s;
  *az += dz * s;
}

/* ---- Random actions: domain, the draw (kind a literal; a mesh's or union's data in
 * `shapes`); falloff ------------------------------------------------------------------- */

FL_INLINE float3 fl_force_draw(__global const FlActionParams* a, uint kind, uint id, uint seedLo,
                               uint seedHi, uint step, uint stream, __global const float* shapes) {
  FlRandom rng = fl_random(seedLo, seedHi, id, step, stream);
  return fl_sample_any(&a->domain, kind, &rng, shapes);
}

FL_INLINE void fl_random_accel(__global const FlActionParams* a, uint kind, float dt, float px,
                               float py, float pz, float* vx, float* vy, float* vz, uint id,
                               uint seedLo, uint seedHi, uint step, uint stream,
                               __global const float* shapes) {
  const float3 s = fl_force_draw(a, kind, id, seedLo, seedHi, step, stream, shapes);
  const float k = dt * fl_force_falloff(a, px, py, pz);
  *vx = *vx + s.x * k;
  *vy = *vy + s.y * k;
  *vz = *vz + s.z * k;
}

FL_INLINE void fl_random_accel_acc(__global const FlActionParams* a, uint kind, float px, float py,
                                   float pz, uint id, uint seedLo, uint seedHi, uint step,
                                   uint stream, __global const float* shapes, float* ax,
                                   float* ay, float* az) {
  const float3 s = fl_force_draw(a, kind, id, seedLo, seedHi, step, stream, shapes);
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += s.x * w;
  *ay += s.y * w;
  *az += s.z * w;
}

FL_INLINE void fl_random_displace(__global const FlActionParams* a, uint kind, float dt, float* px,
                                  float* py, float* pz, uint id, uint seedLo, uint seedHi,
                                  uint step, uint stream, __global const float* shapes) {
  const float3 s = fl_force_draw(a, kind, id, seedLo, seedHi, step, stream, shapes);
  *px = *px + s.x * dt;
  *py = *py + s.y * dt;
  *pz = *pz + s.z * dt;
}

/* RandomVelocity, RandomRotVelocity: the drawn vector replaces the lane. */
FL_INLINE void fl_random_set(__global const FlActionParams* a, uint kind, float* x, float* y,
                             float* z, uint id, uint seedLo, uint seedHi, uint step, uint stream,
                             __global const float* shapes) {
  const float3 s = fl_force_draw(a, kind, id, seedLo, seedHi, step, stream, shapes);
  *x = s.x;
  *y = s.y;
  *z = s.z;
}

/* ---- Turbulence: curl noise (noise.h), f[0] amplitude, [1] frequency,
 * [2..4] drift, u[0] octaves; falloff ----------------------------------------------------- */

/* The turbulence's acceleration without the falloff, at p and time t. */
FL_INLINE float3 fl_turbulence_field(__global const FlActionParams* a, float t, float px, float py,
                                     float pz) {
  const float f = a->f[1], amp = a->f[0];
  const float sx = a->f[2] * t, sy = a->f[3] * t, sz = a->f[4] * t;
  const float3 c = fl_curl_noise((px - sx) * f, (py - sy) * f, (pz - sz) * f, a->u[0]);
  return (float3)(c.x * amp, c.y * amp, c.z * amp);
}

FL_INLINE void fl_turbulence(__global const FlActionParams* a, float dt, fl_real time, float px,
                             float py, float pz, float* vx, float* vy, float* vz) {
  const float3 acc = fl_turbulence_field(a, (float)time, px, py, pz);
  const float k = dt * fl_force_falloff(a, px, py, pz);
  *vx = *vx + acc.x * k;
  *vy = *vy + acc.y * k;
  *vz = *vz + acc.z * k;
}

FL_INLINE void fl_turbulence_acc(__global const FlActionParams* a, fl_real t, float px, float py,
                                 float pz, float* ax, float* ay, float* az) {
  const float3 acc = fl_turbulence_field(a, (float)t, px, py, pz);
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += acc.x * w;
  *ay += acc.y * w;
  *az += acc.z * w;
}

/* ---- ElectricField: f[0..2] field; falloff ------------------------------------------- */

FL_INLINE void fl_electric(__global const FlActionParams* a, float dt, float px, float py, float pz,
                           float* vx, float* vy, float* vz, float charge, float mass) {
  const float w = fl_force_falloff(a, px, py, pz);
  const float s = fl_force_charge_per_mass(charge, mass) * dt * w;
  *vx = *vx + a->f[0] * s;
  *vy = *vy + a->f[1] * s;
  *vz = *vz + a->f[2] * s;
}

FL_INLINE void fl_electric_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float charge, float mass, float* ax, float* ay, float* az) {
  const float q = fl_force_charge_per_mass(charge, mass);
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += a->f[0] * q * w;
  *ay += a->f[1] * q * w;
  *az += a->f[2] * q * w;
}

/* ---- MagneticField: f[0..2] field / |field|, [3] |field|, [4..6] field; falloff ------- */

/* v turns about B by -(q/m)|B| dt, exactly (Rodrigues), in double where the device has it,
 * as the CPU does so that the speed does not drift. */
FL_INLINE void fl_magnetic(__global const FlActionParams* a, float dt, float px, float py, float pz,
                           float* vx, float* vy, float* vz, float charge, float mass) {
  const float B = a->f[3];
  if (!(B > 0.0f)) return;
  const fl_real theta = -(fl_real)fl_force_charge_per_mass(charge, mass) * (fl_real)B *
                        (fl_real)dt * (fl_real)fl_force_falloff(a, px, py, pz);
  const fl_real ct = cos(theta), st = sin(theta);
  const fl_real x = *vx, y = *vy, z = *vz;
  const fl_real kx = a->f[0], ky = a->f[1], kz = a->f[2];
  const fl_real d = (kx * x + ky * y + kz * z) * ((fl_real)1.0 - ct);
  *vx = (float)(x * ct + (ky * z - y * kz) * st + kx * d);
  *vy = (float)(y * ct + (kz * x - z * kx) * st + ky * d);
  *vz = (float)(z * ct + (kx * y - x * ky) * st + kz * d);
}

FL_INLINE void fl_magnetic_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float vx, float vy, float vz, float charge, float mass, float* ax,
                               float* ay, float* az) {
  const float Bx = a->f[4], By = a->f[5], Bz = a->f[6];
  const float q = fl_force_charge_per_mass(charge, mass);
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += (vy * Bz - By * vz) * q * w;
  *ay += (vz * Bx - Bz * vx) * q * w;
  *az += (vx * By - Bx * vy) * q * w;
}

/* ---- SampledField: f[0..2] grid origin, [3] voxel size, [4] strength,
 * [5] responsiveness, [6] packed dt, [7] exp(-responsiveness * dt); u[0] the grid's first
 * float in extra (xyz per sample, x fastest), u[1..3] dims, u[4] 1 for Mode::Velocity;
 * falloff ---------------------------------------------------------------------------------- */

FL_INLINE float fl_force_clamp(float v, float lo, float hi) { /* std::clamp's rule */
  return v < lo ? lo : hi < v ? hi : v;
}

/* field.hpp VectorField::sample: trilinear, positions outside take the border's value. */
FL_INLINE float3 fl_field_sample(__global const FlActionParams* a, __global const float* extra,
                                 float px, float py, float pz) {
  const int nx = (int)a->u[1], ny = (int)a->u[2], nz = (int)a->u[3];
  const float vs = a->f[3];
  const float fx = fl_force_clamp((px - a->f[0]) / vs, 0.0f, (float)(nx - 1));
  const float fy = fl_force_clamp((py - a->f[1]) / vs, 0.0f, (float)(ny - 1));
  const float fz = fl_force_clamp((pz - a->f[2]) / vs, 0.0f, (float)(nz - 1));
  const int x0 = min((int)fx, nx - 1), y0 = min((int)fy, ny - 1), z0 = min((int)fz, nz - 1);
  const int x1 = min(x0 + 1, nx - 1), y1 = min(y0 + 1, ny - 1), z1 = min(z0 + 1, nz - 1);
  const float tx = fx - (float)x0, ty = fy - (float)y0, tz = fz - (float)z0;
  __global const float* g = extra + a->u[0];
#define FL_AT(x, y, z) vload3((uint)(x) + (uint)nx * ((uint)(y) + (uint)ny * (uint)(z)), g)
  const float3 sx = (float3)(1.0f - tx), sy = (float3)(1.0f - ty), sz = (float3)(1.0f - tz);
  const float3 c00 = FL_AT(x0, y0, z0) * sx + FL_AT(x1, y0, z0) * tx;
  const float3 c10 = FL_AT(x0, y1, z0) * sx + FL_AT(x1, y1, z0) * tx;
  const float3 c01 = FL_AT(x0, y0, z1) * sx + FL_AT(x1, y0, z1) * tx;
  const float3 c11 = FL_AT(x0, y1, z1) * sx + FL_AT(x1, y1, z1) * tx;
#undef FL_AT
  return (c00 * sy + c10 * ty) * sz + (c01 * sy + c11 * ty) * tz;
}

FL_INLINE void fl_sampled_field(__global const FlActionParams* a, __global const float* extra,
                                float dt, float px, float py, float pz, float* vx, float* vy,
                                float* vz) {
  const float k = fl_force_approach(a->f[5], dt, a->f[6], a->f[7]);
  const float w = fl_force_falloff(a, px, py, pz);
  const float3 u = fl_field_sample(a, extra, px, py, pz) * a->f[4];
  if (a->u[4]) { /* carried towards u */
    const float kw = k * w;
    *vx = *vx + (u.x - *vx) * kw;
    *vy = *vy + (u.y - *vy) * kw;
    *vz = *vz + (u.z - *vz) * kw;
  } else {
    const float s = dt * w;
    *vx = *vx + u.x * s;
    *vy = *vy + u.y * s;
    *vz = *vz + u.z * s;
  }
}

FL_INLINE void fl_sampled_field_acc(__global const FlActionParams* a, __global const float* extra,
                                    float px, float py, float pz, float vx, float vy, float vz,
                                    float* ax, float* ay, float* az) {
  float3 u = fl_field_sample(a, extra, px, py, pz) * a->f[4];
  if (a->u[4]) u = (u - (float3)(vx, vy, vz)) * a->f[5];
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += u.x * w;
  *ay += u.y * w;
  *az += u.z * w;
}

/* ---- Targets: f[0..3] the target (a vector's three, or color and alpha, or a size),
 * [4] rate, [5] packed dt, [6] exp(-rate * dt) ------------------------------------------ */

FL_INLINE float fl_target_k(__global const FlActionParams* a, float dt) {
  return fl_force_approach(a->f[4], dt, a->f[5], a->f[6]);
}

FL_INLINE void fl_target3(__global const FlActionParams* a, float dt, float* x, float* y,
                          float* z) {
  const float k = fl_target_k(a, dt);
  *x += (a->f[0] - *x) * k;
  *y += (a->f[1] - *y) * k;
  *z += (a->f[2] - *z) * k;
}

FL_INLINE void fl_target_color(__global const FlActionParams* a, float dt, float* r, float* g,
                               float* b, float* al) {
  const float k = fl_target_k(a, dt);
  *r += (a->f[0] - *r) * k;
  *g += (a->f[1] - *g) * k;
  *b += (a->f[2] - *b) * k;
  *al += (a->f[3] - *al) * k;
}

FL_INLINE void fl_target_size(__global const FlActionParams* a, float dt, float* size) {
  *size += (a->f[0] - *size) * fl_target_k(a, dt);
}

/* ---- SpeedClamp: f[0] minSpeed, [1] maxSpeed ------------------------------------------- */

FL_INLINE void fl_speed_clamp(__global const FlActionParams* a, float* vx, float* vy, float* vz) {
  const float x = *vx, y = *vy, z = *vz;
  const float s = sqrt(x * x + y * y + z * z);
  float k;
  if (s > a->f[1])
    k = a->f[1] / s;
  else if (s < a->f[0] && s > 0.0f)
    k = a->f[0] / s;
  else
    return;
  *vx = x * k;
  *vy = y * k;
  *vz = z * k;
}

/* ---- Curves over life: u[0] the first key's float in extra, u[1] keys; a key is t then
 * its value (ColorOverLife: r g b a, SizeOverLife: size) ---------------------------------- */

/* actions_more.hpp lifeFraction. */
FL_INLINE float fl_force_life_fraction(float age, float life) {
  return life > 0.0f ? fl_force_clamp(age / life, 0.0f, 1.0f) : 1.0f;
}

/* actions_more.hpp lookup(): keys of `stride` floats (t, then stride - 1 values) into out. */
FL_INLINE void fl_force_lookup(__global const float* keys, uint count, uint stride, float t,
                               float* out) {
  uint hi = 0;
  float w = 0.0f;
  if (t <= keys[0]) {
    hi = 0;
  } else {
    hi = count; /* past the last key: its value */
    for (uint k = 1; k < count; ++k) {
      if (t <= keys[k * stride]) {
        const float t0 = keys[(k - 1) * stride];
        const float span = keys[k * stride] - t0;
        w = span > 0.0f ? (t - t0) / span : 1.0f;
        hi = k;
        break;
      }
    }
  }
  if (hi == 0 || hi == count) {
    __global const float* v = keys + (hi == 0 ? 0u : (count - 1) * stride) + 1;
    for (uint c = 0; c + 1 < stride; ++c) out[c] = v[c];
    return;
  }
  __global const float* v0 = keys + (hi - 1) * stride + 1;
  __global const float* v1 = keys + hi * stride + 1;
  for (uint c = 0; c + 1 < stride; ++c) out[c] = v0[c] + (v1[c] - v0[c]) * w;
}

FL_INLINE void fl_color_over_life(__global const FlActionParams* a, __global const float* extra,
                                  float age, float life, float* r, float* g, float* b, float* al) {
  float c[4];
  fl_force_lookup(extra + a->u[0], a->u[1], 5u, fl_force_life_fraction(age, life), c);
  *r = c[0];
  *g = c[1];
  *b = c[2];
  *al = c[3];
}

FL_INLINE void fl_size_over_life(__global const FlActionParams* a, __global const float* extra,
                                 float age, float life, float* size) {
  float s[1];
  fl_force_lookup(extra + a->u[0], a->u[1], 2u, fl_force_life_fraction(age, life), s);
  *size = s[0];
}

/* Multiply mode: the curve scales the birth colour / size. */
FL_INLINE void fl_color_over_life_scaled(__global const FlActionParams* a,
                                         __global const float* extra, float age, float life,
                                         float r0, float g0, float b0, float a0, float* r, float* g,
                                         float* b, float* al) {
  float c[4];
  fl_force_lookup(extra + a->u[0], a->u[1], 5u, fl_force_life_fraction(age, life), c);
  *r = r0 * c[0];
  *g = g0 * c[1];
  *b = b0 * c[2];
  *al = a0 * c[3];
}

FL_INLINE void fl_size_over_life_scaled(__global const FlActionParams* a,
                                        __global const float* extra, float age, float life,
                                        float size0, float* size) {
  float s[1];
  fl_force_lookup(extra + a->u[0], a->u[1], 2u, fl_force_life_fraction(age, life), s);
  *size = size0 * s[0];
}
