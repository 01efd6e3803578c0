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

/* The falloff's weight (forces.h). */
FL_INLINE float fl_force_falloff(__global const FlActionParams* a, float px, float py, float pz) {
  __global const float* f = a->f + FL_FALLOFF;
  const FlFalloff w = {f[0], f[1], f[2], f[3], f[4]};
  return fl_falloff_weight(w, px, py, pz);
}

/* exp(-rate * dt): the host's value (std::exp, as the CPU's) for the step length it packed,
 * so the two agree to the bit; the device's own for a sub-step's other length. */
FL_INLINE float fl_force_decay(float rate, float dt, float packedDt, float packed) {
  return dt == packedDt ? packed : exp(-rate * dt);
}

/* fl_approach (forces.h), with the host's exp for the packed step length. */
FL_INLINE float fl_force_approach(float rate, float dt, float packedDt, float packed) {
  return dt == packedDt ? 1.0f - packed : fl_approach(rate, dt);
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
  fl_add_scaled(a->f[0], a->f[1], a->f[2], dt * fl_force_falloff(a, px, py, pz), vx, vy, vz);
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
  fl_damping_step(a->f[3], a->f[4], a->f[5], dt, fl_force_falloff(a, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_damping_acc(__global const FlActionParams* a, float px, float py, float pz,
                              float vx, float vy, float vz, float* ax, float* ay, float* az) {
  fl_damping_accel(a->f[3], a->f[4], a->f[5], fl_force_falloff(a, px, py, pz), vx, vy, vz, ax,
                   ay, az);
}

/* ---- OrbitPoint: f[0..2] center, [3] magnitude, [4] epsilon, [5] maxRadius ------------- */

FL_INLINE void fl_orbit_point_pull(__global const FlActionParams* a, float px, float py,
                                   float pz, float* x, float* y, float* z) {
  fl_soft_pull(a->f[0] - px, a->f[1] - py, a->f[2] - pz, a->f[3], a->f[4], a->f[5] * a->f[5], x,
               y, z);
}

FL_INLINE void fl_orbit_point_acc(__global const FlActionParams* a, float px, float py, float pz,
                                  float* ax, float* ay, float* az) {
  float x, y, z;
  fl_orbit_point_pull(a, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, 1.0f, ax, ay, az);
}

FL_INLINE void fl_orbit_point(__global const FlActionParams* a, float dt, float px, float py,
                              float pz, float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_orbit_point_pull(a, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, dt, vx, vy, vz);
}

/* ---- OrbitLine: f[0..2] point, [3..5] unit axis, [6] magnitude, [7] eps, [8] maxRadius -- */

FL_INLINE void fl_orbit_line_of(__global const FlActionParams* a, float px, float py, float pz,
                                float* x, float* y, float* z) {
  fl_orbit_line_pull(a->f[0], a->f[1], a->f[2], a->f[3], a->f[4], a->f[5], a->f[6], a->f[7],
                     a->f[8] * a->f[8], px, py, pz, x, y, z);
}

FL_INLINE void fl_orbit_line(__global const FlActionParams* a, float dt, float px, float py,
                             float pz, float* vx, float* vy, float* vz) {
  float x, y, z;
  fl_orbit_line_of(a, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, dt, vx, vy, vz);
}

FL_INLINE void fl_orbit_line_acc(__global const FlActionParams* a, float px, float py, float pz,
                                 float* ax, float* ay, float* az) {
  float x, y, z;
  fl_orbit_line_of(a, px, py, pz, &x, &y, &z);
  fl_add_scaled(x, y, z, 1.0f, ax, ay, az);
}

/* ---- Vortex: f[0..2] center, [3..5] unit axis, [6] aroundSpeed, [7] coreRadius,
 * [8] tightness, [9] inSpeed, [10] upSpeed, [11] responsiveness, [12] maxRadius,
 * [13] packed dt, [14] exp(-responsiveness * dt) ------------------------------------------ */

FL_INLINE FlVortex fl_vortex_of(__global const FlActionParams* a) {
  const FlVortex v = {a->f[0], a->f[1], a->f[2], a->f[3], a->f[4],  a->f[5],
                      a->f[6], a->f[7], a->f[8], a->f[9], a->f[10], a->f[12]};
  return v;
}

FL_INLINE void fl_vortex(__global const FlActionParams* a, float dt, float px, float py, float pz,
                         float* vx, float* vy, float* vz) {
  fl_vortex_step(fl_vortex_of(a), fl_force_approach(a->f[11], dt, a->f[13], a->f[14]), px, py, pz,
                 vx, vy, vz);
}

FL_INLINE void fl_vortex_acc(__global const FlActionParams* a, float px, float py, float pz,
                             float vx, float vy, float vz, float* ax, float* ay, float* az) {
  fl_vortex_accel(fl_vortex_of(a), a->f[11], px, py, pz, vx, vy, vz, ax, ay, az);
}

/* ---- Jet: f[0..2] center, [3] radius; domain: the acceleration (kind a literal; a mesh's
 * or union's data in `shapes`, the act kernel's extra) ---------------------------------- */

FL_INLINE int fl_jet_accel(__global const FlActionParams* a, uint kind, float px, float py,
                           float pz, uint id, uint seedLo, uint seedHi, uint step, uint stream,
                           float3* acc, __global const float* shapes) {
  if (!fl_in_ball(a->f[0], a->f[1], a->f[2], a->f[3], px, py, pz)) return 0;
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
  fl_explosion_step(a->f[0], a->f[1], a->f[2], a->f[4], a->f[5], a->f[6], front, dt, px, py, pz,
                    vx, vy, vz);
}

FL_INLINE void fl_explosion_acc(__global const FlActionParams* a, fl_real t, float px, float py,
                                float pz, float* ax, float* ay, float* az) {
  if (!(t >= (fl_real)a->f[7])) return;
  const float front = a->f[3] * (float)(t - (fl_real)a->f[7]);
  fl_explosion_accel(a->f[0], a->f[1], a->f[2], a->f[4], a->f[8], a->f[6], front, px, py, pz, ax,
                     ay, az);
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

FL_INLINE FlTurbulence fl_turbulence_params(__global const FlActionParams* a) {
  const FlTurbulence t = {a->f[0], a->f[1], a->f[2], a->f[3], a->f[4], a->u[0]};
  return t;
}

FL_INLINE void fl_turbulence(__global const FlActionParams* a, float dt, fl_real time, float px,
                             float py, float pz, float* vx, float* vy, float* vz) {
  const float3 acc = fl_turbulence_field(fl_turbulence_params(a), (float)time, px, py, pz);
  fl_add_scaled(acc.x, acc.y, acc.z, dt * fl_force_falloff(a, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_turbulence_acc(__global const FlActionParams* a, fl_real t, float px, float py,
                                 float pz, float* ax, float* ay, float* az) {
  fl_turbulence_accel(fl_turbulence_params(a), (float)t, fl_force_falloff(a, px, py, pz), px, py,
                      pz, ax, ay, az);
}

/* ---- ElectricField: f[0..2] field; falloff ------------------------------------------- */

FL_INLINE void fl_electric(__global const FlActionParams* a, float dt, float px, float py, float pz,
                           float* vx, float* vy, float* vz, float charge, float mass) {
  const float w = fl_force_falloff(a, px, py, pz);
  fl_add_scaled(a->f[0], a->f[1], a->f[2], fl_charge_per_mass(charge, mass) * dt * w, vx, vy, vz);
}

FL_INLINE void fl_electric_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float charge, float mass, float* ax, float* ay, float* az) {
  const float q = fl_charge_per_mass(charge, mass);
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
  const fl_real theta = -(fl_real)fl_charge_per_mass(charge, mass) * (fl_real)B *
                        (fl_real)dt * (fl_real)fl_force_falloff(a, px, py, pz);
  fl_magnetic_turn(a->f[0], a->f[1], a->f[2], theta, vx, vy, vz);
}

FL_INLINE void fl_magnetic_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float vx, float vy, float vz, float charge, float mass, float* ax,
                               float* ay, float* az) {
  fl_magnetic_accel(a->f[4], a->f[5], a->f[6], fl_charge_per_mass(charge, mass),
                    fl_force_falloff(a, px, py, pz), vx, vy, vz, ax, ay, az);
}

/* ---- SampledField: f[0..2] grid origin, [3] voxel size, [4] strength,
 * [5] responsiveness, [6] packed dt, [7] exp(-responsiveness * dt); u[0] the grid's first
 * float in extra (xyz per sample, x fastest), u[1..3] dims, u[4] 1 for Mode::Velocity;
 * falloff ---------------------------------------------------------------------------------- */

/* field.hpp VectorField::sample: the cell and the blend are forces.h's. */
FL_INLINE float3 fl_field_sample(__global const FlActionParams* a, __global const float* extra,
                                 float px, float py, float pz) {
  const int nx = (int)a->u[1], ny = (int)a->u[2], nz = (int)a->u[3];
  const float vs = a->f[3];
  int x0, x1, y0, y1, z0, z1;
  const float tx = fl_field_axis((px - a->f[0]) / vs, nx, &x0, &x1);
  const float ty = fl_field_axis((py - a->f[1]) / vs, ny, &y0, &y1);
  const float tz = fl_field_axis((pz - a->f[2]) / vs, nz, &z0, &z1);
  __global const float* g = extra + a->u[0];
#define FL_AT(x, y, z) vload3((uint)(x) + (uint)nx * ((uint)(y) + (uint)ny * (uint)(z)), g)
  const float3 c000 = FL_AT(x0, y0, z0), c100 = FL_AT(x1, y0, z0), c010 = FL_AT(x0, y1, z0),
               c110 = FL_AT(x1, y1, z0), c001 = FL_AT(x0, y0, z1), c101 = FL_AT(x1, y0, z1),
               c011 = FL_AT(x0, y1, z1), c111 = FL_AT(x1, y1, z1);
#undef FL_AT
#define FL_BLEND(k) \
  fl_field_blend(c000.k, c100.k, c010.k, c110.k, c001.k, c101.k, c011.k, c111.k, tx, ty, tz)
  return make_float3(FL_BLEND(x), FL_BLEND(y), FL_BLEND(z));
#undef FL_BLEND
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
  *x = fl_toward(*x, a->f[0], k);
  *y = fl_toward(*y, a->f[1], k);
  *z = fl_toward(*z, a->f[2], k);
}

FL_INLINE void fl_target_color(__global const FlActionParams* a, float dt, float* r, float* g,
                               float* b, float* al) {
  const float k = fl_target_k(a, dt);
  *r = fl_toward(*r, a->f[0], k);
  *g = fl_toward(*g, a->f[1], k);
  *b = fl_toward(*b, a->f[2], k);
  *al = fl_toward(*al, a->f[3], k);
}

FL_INLINE void fl_target_size(__global const FlActionParams* a, float dt, float* size) {
  *size = fl_toward(*size, a->f[0], fl_target_k(a, dt));
}

/* ---- SpeedClamp: f[0] minSpeed, [1] maxSpeed ------------------------------------------- */

FL_INLINE void fl_speed_clamp(__global const FlActionParams* a, float* vx, float* vy, float* vz) {
  fl_clamp_speed(a->f[0], a->f[1], vx, vy, vz);
}

/* ---- Curves over life: u[0] the first key's float in extra, u[1] keys; a key is t then
 * its value (ColorOverLife: r g b a, SizeOverLife: size) ---------------------------------- */

FL_INLINE void fl_color_over_life(__global const FlActionParams* a, __global const float* extra,
                                  float age, float life, float* r, float* g, float* b, float* al) {
  float c[4];
  fl_curve_lookup(extra + a->u[0], a->u[1], 5u, fl_life_fraction(age, life), c);
  *r = c[0];
  *g = c[1];
  *b = c[2];
  *al = c[3];
}

FL_INLINE void fl_size_over_life(__global const FlActionParams* a, __global const float* extra,
                                 float age, float life, float* size) {
  float s[1];
  fl_curve_lookup(extra + a->u[0], a->u[1], 2u, fl_life_fraction(age, life), s);
  *size = s[0];
}

/* Multiply mode: the curve scales the birth colour / size. */
FL_INLINE void fl_color_over_life_scaled(__global const FlActionParams* a,
                                         __global const float* extra, float age, float life,
                                         float r0, float g0, float b0, float a0, float* r, float* g,
                                         float* b, float* al) {
  float c[4];
  fl_curve_lookup(extra + a->u[0], a->u[1], 5u, fl_life_fraction(age, life), c);
  *r = r0 * c[0];
  *g = g0 * c[1];
  *b = b0 * c[2];
  *al = a0 * c[3];
}

FL_INLINE void fl_size_over_life_scaled(__global const FlActionParams* a,
                                        __global const float* extra, float age, float life,
                                        float size0, float* size) {
  float s[1];
  fl_curve_lookup(extra + a->u[0], a->u[1], 2u, fl_life_fraction(age, life), s);
  *size = size0 * s[0];
}
