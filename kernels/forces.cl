/* Forces, random and target actions, curves over life on the device: what needs the device's
 * own storage (a domain's packed data, a grid or a curve in the act kernel's `extra`) or its
 * random streams. The forces that need neither are kernels/forces.h's, which the CPU calls
 * too; sdk/src/opencl/actions_forces.cpp generates the calls, and the records they read are
 * params.h's, made by sdk/src/action_params.hpp's maker for both backends.
 *
 * The fl_*_acc functions are the forces as accelerations at a state (integrate.hpp
 * accumulate()): they add to *ax, *ay, *az, as the CPU adds each force's acc to the stage's. */

/* ---- Jet: its acceleration is the domain (kind a literal; a mesh's or union's data in
 * `shapes`, the act kernel's extra) ------------------------------------------------------ */

FL_INLINE int fl_jet_accel(__global const FlActionParams* a, uint kind, float px, float py,
                           float pz, uint id, uint seedLo, uint seedHi, uint step, uint stream,
                           float3* acc, __global const float* shapes) {
  if (!fl_jet_reaches(a->own.jet, px, py, pz)) return 0;
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
  const float k = dt * fl_falloff_weight(a->falloff, px, py, pz);
  *vx = *vx + s.x * k;
  *vy = *vy + s.y * k;
  *vz = *vz + s.z * k;
}

FL_INLINE void fl_random_accel_acc(__global const FlActionParams* a, uint kind, float px, float py,
                                   float pz, uint id, uint seedLo, uint seedHi, uint step,
                                   uint stream, __global const float* shapes, float* ax,
                                   float* ay, float* az) {
  const float3 s = fl_force_draw(a, kind, id, seedLo, seedHi, step, stream, shapes);
  const float w = fl_falloff_weight(a->falloff, px, py, pz);
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

/* ---- SampledField; falloff -------------------------------------------------------------- */

/* SampledField: the grid in the act kernel's `extra` (forces.h fl_grid_sample). */
FL_INLINE float3 fl_field_sample(__global const FlActionParams* a, __global const float* extra,
                                 float px, float py, float pz) {
  __global const FlSampledFieldParams* s = &a->own.sampledField;
  return fl_grid_sample(extra + s->first, (int)s->nx, (int)s->ny, (int)s->nz, s->origin.x,
                        s->origin.y, s->origin.z, s->voxelSize, px, py, pz);
}

FL_INLINE void fl_grid_field(__global const FlActionParams* a, __global const float* extra,
                              float dt, float px, float py, float pz, float* vx, float* vy,
                              float* vz) {
  const float3 u = fl_field_sample(a, extra, px, py, pz);
  fl_sampled_field(a->own.sampledField, dt, fl_falloff_weight(a->falloff, px, py, pz), u.x, u.y,
                   u.z, vx, vy, vz);
}

FL_INLINE void fl_grid_field_acc(__global const FlActionParams* a, __global const float* extra,
                                  float px, float py, float pz, float vx, float vy, float vz,
                                  float* ax, float* ay, float* az) {
  const float3 u = fl_field_sample(a, extra, px, py, pz);
  fl_sampled_field_acc(a->own.sampledField, fl_falloff_weight(a->falloff, px, py, pz), u.x, u.y,
                       u.z, vx, vy, vz, ax, ay, az);
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
