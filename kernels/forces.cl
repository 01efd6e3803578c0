/* Forces, random and target actions, curves over life (sdk/src/opencl/actions_forces.cpp
 * generates their calls and packs their constants, whose records are in params.h).
 * Each follows sdk/src/cpu/kernels.hpp, actions_more.hpp and integrate.hpp operation by
 * operation, in the same order (glm's vector operations componentwise), so that with
 * FP_CONTRACT off and correctly rounded division and sqrt the results agree to the bit
 * except where a libm call (exp, pow, cos, sin) differs from the device's builtin.
 *
 * The fl_*_acc functions are the forces as accelerations at a state (integrate.hpp
 * accumulate()): they add to *ax, *ay, *az, as the CPU adds each force's acc to the stage's. */

/* The falloff's weight (forces.h). */
FL_INLINE float fl_force_falloff(__global const FlActionParams* a, float px, float py, float pz) {
  const FlFalloff w = {a->falloff.cx, a->falloff.cy, a->falloff.cz, a->falloff.radius,
                       a->falloff.power};
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

/* ---- Gravity ---------------------------------------------------------------------------- */

FL_INLINE void fl_gravity(__global const FlActionParams* a, float dt, float* vx, float* vy,
                          float* vz) {
  __global const FlXyz* g = &a->own.gravity.acceleration;
  *vx += g->x * dt;
  *vy += g->y * dt;
  *vz += g->z * dt;
}

FL_INLINE void fl_gravity_falloff(__global const FlActionParams* a, float dt, float px, float py,
                                  float pz, float* vx, float* vy, float* vz) {
  __global const FlXyz* g = &a->own.gravity.acceleration;
  fl_add_scaled(g->x, g->y, g->z, dt * fl_force_falloff(a, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_gravity_acc(__global const FlActionParams* a, float px, float py, float pz,
                              float* ax, float* ay, float* az) {
  __global const FlXyz* g = &a->own.gravity.acceleration;
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += g->x * w;
  *ay += g->y * w;
  *az += g->z * w;
}

/* ---- Damping, RotDamping ---------------------------------------------------------------- */

FL_INLINE void fl_damping(__global const FlActionParams* a, float dt, float* vx, float* vy,
                          float* vz) {
  __global const FlDampingParams* d = &a->own.damping;
  *vx *= fl_force_decay(d->rate.x, dt, d->dt, d->decay.x);
  *vy *= fl_force_decay(d->rate.y, dt, d->dt, d->decay.y);
  *vz *= fl_force_decay(d->rate.z, dt, d->dt, d->decay.z);
}

FL_INLINE void fl_damping_falloff(__global const FlActionParams* a, float dt, float px, float py,
                                  float pz, float* vx, float* vy, float* vz) {
  __global const FlXyz* k = &a->own.damping.rate;
  fl_damping_step(k->x, k->y, k->z, dt, fl_force_falloff(a, px, py, pz), vx, vy, vz);
}

FL_INLINE void fl_damping_acc(__global const FlActionParams* a, float px, float py, float pz,
                              float vx, float vy, float vz, float* ax, float* ay, float* az) {
  __global const FlXyz* k = &a->own.damping.rate;
  fl_damping_accel(k->x, k->y, k->z, fl_force_falloff(a, px, py, pz), vx, vy, vz, ax, ay, az);
}

/* ---- OrbitPoint ------------------------------------------------------------------------- */

FL_INLINE void fl_orbit_point_pull(__global const FlActionParams* a, float px, float py,
                                   float pz, float* x, float* y, float* z) {
  __global const FlOrbitPointParams* o = &a->own.orbitPoint;
  fl_soft_pull(o->center.x - px, o->center.y - py, o->center.z - pz, o->magnitude, o->epsilon,
               o->maxRadius * o->maxRadius, x, y, z);
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

/* ---- OrbitLine -------------------------------------------------------------------------- */

FL_INLINE void fl_orbit_line_of(__global const FlActionParams* a, float px, float py, float pz,
                                float* x, float* y, float* z) {
  __global const FlOrbitLineParams* o = &a->own.orbitLine;
  fl_orbit_line_pull(o->point.x, o->point.y, o->point.z, o->axis.x, o->axis.y, o->axis.z,
                     o->magnitude, o->epsilon, o->maxRadius * o->maxRadius, px, py, pz, x, y, z);
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

/* ---- Vortex ----------------------------------------------------------------------------- */

FL_INLINE FlVortex fl_vortex_of(__global const FlActionParams* a) {
  __global const FlVortexParams* p = &a->own.vortex;
  const FlVortex v = {p->center.x,  p->center.y,  p->center.z,     p->axis.x,
                      p->axis.y,    p->axis.z,    p->aroundSpeed,  p->coreRadius,
                      p->tightness, p->inSpeed,   p->upSpeed,      p->maxRadius};
  return v;
}

FL_INLINE void fl_vortex(__global const FlActionParams* a, float dt, float px, float py, float pz,
                         float* vx, float* vy, float* vz) {
  __global const FlVortexParams* p = &a->own.vortex;
  fl_vortex_step(fl_vortex_of(a), fl_force_approach(p->responsiveness, dt, p->dt, p->decay), px,
                 py, pz, vx, vy, vz);
}

FL_INLINE void fl_vortex_acc(__global const FlActionParams* a, float px, float py, float pz,
                             float vx, float vy, float vz, float* ax, float* ay, float* az) {
  fl_vortex_accel(fl_vortex_of(a), a->own.vortex.responsiveness, px, py, pz, vx, vy, vz, ax, ay,
                  az);
}

/* ---- Jet: its acceleration is the domain (kind a literal; a mesh's or union's data in
 * `shapes`, the act kernel's extra) ------------------------------------------------------ */

FL_INLINE int fl_jet_accel(__global const FlActionParams* a, uint kind, float px, float py,
                           float pz, uint id, uint seedLo, uint seedHi, uint step, uint stream,
                           float3* acc, __global const float* shapes) {
  __global const FlJetParams* j = &a->own.jet;
  if (!fl_in_ball(j->center.x, j->center.y, j->center.z, j->radius, px, py, pz)) return 0;
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

/* ---- Explosion -------------------------------------------------------------------------- */

FL_INLINE void fl_explosion(__global const FlActionParams* a, float dt, fl_real time, float px,
                            float py, float pz, float* vx, float* vy, float* vz) {
  __global const FlExplosionParams* e = &a->own.explosion;
  const fl_real t = time + (fl_real)0.5 * (fl_real)dt; /* the front's radius at mid-step */
  if (t < (fl_real)e->time) return;
  const float front = e->speed * (float)(t - (fl_real)e->time);
  fl_explosion_step(e->center.x, e->center.y, e->center.z, e->magnitude, e->invTwoVariance,
                    e->epsilon, front, dt, px, py, pz, vx, vy, vz);
}

FL_INLINE void fl_explosion_acc(__global const FlActionParams* a, fl_real t, float px, float py,
                                float pz, float* ax, float* ay, float* az) {
  __global const FlExplosionParams* e = &a->own.explosion;
  if (!(t >= (fl_real)e->time)) return;
  const float front = e->speed * (float)(t - (fl_real)e->time);
  fl_explosion_accel(e->center.x, e->center.y, e->center.z, e->magnitude, e->twoVariance,
                     e->epsilon, front, px, py, pz, ax, ay, az);
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

/* ---- Turbulence: curl noise (noise.h); falloff ------------------------------------------ */

FL_INLINE FlTurbulence fl_turbulence_params(__global const FlActionParams* a) {
  __global const FlTurbulenceParams* p = &a->own.turbulence;
  const FlTurbulence t = {p->amplitude, p->frequency, p->drift.x,
                          p->drift.y,   p->drift.z,   p->octaves};
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

/* ---- ElectricField; falloff ------------------------------------------------------------- */

FL_INLINE void fl_electric(__global const FlActionParams* a, float dt, float px, float py, float pz,
                           float* vx, float* vy, float* vz, float charge, float mass) {
  __global const FlXyz* e = &a->own.electric.field;
  const float w = fl_force_falloff(a, px, py, pz);
  fl_add_scaled(e->x, e->y, e->z, fl_charge_per_mass(charge, mass) * dt * w, vx, vy, vz);
}

FL_INLINE void fl_electric_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float charge, float mass, float* ax, float* ay, float* az) {
  __global const FlXyz* e = &a->own.electric.field;
  const float q = fl_charge_per_mass(charge, mass);
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += e->x * q * w;
  *ay += e->y * q * w;
  *az += e->z * q * w;
}

/* ---- MagneticField; falloff ------------------------------------------------------------- */

/* v turns about B by -(q/m)|B| dt, exactly (Rodrigues), in double where the device has it,
 * as the CPU does so that the speed does not drift. */
FL_INLINE void fl_magnetic(__global const FlActionParams* a, float dt, float px, float py, float pz,
                           float* vx, float* vy, float* vz, float charge, float mass) {
  __global const FlMagneticParams* m = &a->own.magnetic;
  const float B = m->strength;
  if (!(B > 0.0f)) return;
  const fl_real theta = -(fl_real)fl_charge_per_mass(charge, mass) * (fl_real)B *
                        (fl_real)dt * (fl_real)fl_force_falloff(a, px, py, pz);
  fl_magnetic_turn(m->direction.x, m->direction.y, m->direction.z, theta, vx, vy, vz);
}

FL_INLINE void fl_magnetic_acc(__global const FlActionParams* a, float px, float py, float pz,
                               float vx, float vy, float vz, float charge, float mass, float* ax,
                               float* ay, float* az) {
  __global const FlXyz* B = &a->own.magnetic.field;
  fl_magnetic_accel(B->x, B->y, B->z, fl_charge_per_mass(charge, mass),
                    fl_force_falloff(a, px, py, pz), vx, vy, vz, ax, ay, az);
}

/* ---- SampledField; falloff -------------------------------------------------------------- */

/* field.hpp VectorField::sample: the cell and the blend are forces.h's. */
FL_INLINE float3 fl_field_sample(__global const FlActionParams* a, __global const float* extra,
                                 float px, float py, float pz) {
  __global const FlSampledFieldParams* s = &a->own.sampledField;
  const int nx = (int)s->nx, ny = (int)s->ny, nz = (int)s->nz;
  const float vs = s->voxelSize;
  int x0, x1, y0, y1, z0, z1;
  const float tx = fl_field_axis((px - s->origin.x) / vs, nx, &x0, &x1);
  const float ty = fl_field_axis((py - s->origin.y) / vs, ny, &y0, &y1);
  const float tz = fl_field_axis((pz - s->origin.z) / vs, nz, &z0, &z1);
  __global const float* g = extra + s->first;
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
  __global const FlSampledFieldParams* s = &a->own.sampledField;
  const float k = fl_force_approach(s->responsiveness, dt, s->dt, s->decay);
  const float w = fl_force_falloff(a, px, py, pz);
  const float3 u = fl_field_sample(a, extra, px, py, pz) * s->strength;
  if (s->carry) { /* carried towards u */
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
  __global const FlSampledFieldParams* s = &a->own.sampledField;
  float3 u = fl_field_sample(a, extra, px, py, pz) * s->strength;
  if (s->carry) u = (u - (float3)(vx, vy, vz)) * s->responsiveness;
  const float w = fl_force_falloff(a, px, py, pz);
  *ax += u.x * w;
  *ay += u.y * w;
  *az += u.z * w;
}

/* ---- Targets ---------------------------------------------------------------------------- */

FL_INLINE float fl_target_k(__global const FlActionParams* a, float dt) {
  __global const FlTargetParams* t = &a->own.target;
  return fl_force_approach(t->rate, dt, t->dt, t->decay);
}

FL_INLINE void fl_target3(__global const FlActionParams* a, float dt, float* x, float* y,
                          float* z) {
  const float k = fl_target_k(a, dt);
  __global const float* t = a->own.target.target;
  *x = fl_toward(*x, t[0], k);
  *y = fl_toward(*y, t[1], k);
  *z = fl_toward(*z, t[2], k);
}

FL_INLINE void fl_target_color(__global const FlActionParams* a, float dt, float* r, float* g,
                               float* b, float* al) {
  const float k = fl_target_k(a, dt);
  __global const float* t = a->own.target.target;
  *r = fl_toward(*r, t[0], k);
  *g = fl_toward(*g, t[1], k);
  *b = fl_toward(*b, t[2], k);
  *al = fl_toward(*al, t[3], k);
}

FL_INLINE void fl_target_size(__global const FlActionParams* a, float dt, float* size) {
  *size = fl_toward(*size, a->own.target.target[0], fl_target_k(a, dt));
}

/* ---- SpeedClamp ------------------------------------------------------------------------- */

FL_INLINE void fl_speed_clamp(__global const FlActionParams* a, float* vx, float* vy, float* vz) {
  fl_clamp_speed(a->own.speedClamp.minSpeed, a->own.speedClamp.maxSpeed, vx, vy, vz);
}

/* ---- Curves over life ------------------------------------------------------------------- */

FL_INLINE void fl_color_over_life(__global const FlActionParams* a, __global const float* extra,
                                  float age, float life, float* r, float* g, float* b, float* al) {
  float c[4];
  fl_curve_lookup(extra + a->own.curve.first, a->own.curve.keys, 5u, fl_life_fraction(age, life), c);
  *r = c[0];
  *g = c[1];
  *b = c[2];
  *al = c[3];
}

FL_INLINE void fl_size_over_life(__global const FlActionParams* a, __global const float* extra,
                                 float age, float life, float* size) {
  float s[1];
  fl_curve_lookup(extra + a->own.curve.first, a->own.curve.keys, 2u, fl_life_fraction(age, life), s);
  *size = s[0];
}

/* Multiply mode: the curve scales the birth colour / size. */
FL_INLINE void fl_color_over_life_scaled(__global const FlActionParams* a,
                                         __global const float* extra, float age, float life,
                                         float r0, float g0, float b0, float a0, float* r, float* g,
                                         float* b, float* al) {
  float c[4];
  fl_curve_lookup(extra + a->own.curve.first, a->own.curve.keys, 5u, fl_life_fraction(age, life), c);
  *r = r0 * c[0];
  *g = g0 * c[1];
  *b = b0 * c[2];
  *al = a0 * c[3];
}

FL_INLINE void fl_size_over_life_scaled(__global const FlActionParams* a,
                                        __global const float* extra, float age, float life,
                                        float size0, float* size) {
  float s[1];
  fl_curve_lookup(extra + a->own.curve.first, a->own.curve.keys, 2u, fl_life_fraction(age, life), s);
  *size = size0 * s[0];
}
