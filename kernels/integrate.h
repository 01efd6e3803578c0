/* The integrators' per-axis updates for Move, written once for both backends in the kernels'
 * shared C subset: the CPU's block loops (sdk/src/cpu/integrate.hpp) and the device's generated
 * Move (codegen.cpp integrateMove) call these with the forces' gathered acceleration, so the two
 * make the same operations in the same order. */
#ifndef FLURRY_KERNELS_INTEGRATE_H
#define FLURRY_KERNELS_INTEGRATE_H

/* Explicit Euler: the position moves with the velocity at the start of the step. */
FL_INLINE void fl_euler_explicit(float a, float dt, float* p, float* v) {
  *p += *v * dt;
  *v += a * dt;
}

/* Velocity Verlet's predicted state (its velocity for the forces that read one)... */
FL_INLINE void fl_verlet_predict(float p, float v, float a0, float dt, float* p1, float* v1) {
  *p1 = p + v * dt + 0.5f * a0 * dt * dt;
  *v1 = v + a0 * dt;
}
/* ...and its end: the predicted position, the velocity by the mean of the accelerations. */
FL_INLINE void fl_verlet_finish(float p1, float a0, float a1, float dt, float* p, float* v) {
  *p = p1;
  *v += 0.5f * (a0 + a1) * dt;
}

/* Classic RK4 on (p, v): a stage's slopes (kp its velocity, kv its acceleration) weighted by w
 * into the sums (sp, sv), and the next stage's state, `next` (h of the next stage times dt;
 * 0 after the last) along them from the start (p, v). */
FL_INLINE void fl_rk4_stage(float p, float v, float kp, float kv, float w, float next, float* sp,
                            float* sv, float* ps, float* vs) {
  *sp += w * kp;
  *sv += w * kv;
  *ps = p + kp * next;
  *vs = v + kv * next;
}
FL_INLINE void fl_rk4_finish(float sp, float sv, float dt, float* p, float* v) {
  *p += sp * (dt / 6.0f);
  *v += sv * (dt / 6.0f);
}

/* Exact: a constant acceleration g with a linear drag of rate k >= 0, in closed form over h. */
FL_INLINE void fl_exact_step(float g, float k, float h, float* p, float* v) {
  const float v0 = *v;
  if (k > 0.0f) {
    const float e = fl_expf(-k * h), term = g / k;
    *p += term * h + (v0 - term) * (1.0f - e) / k;
    *v = term + (v0 - term) * e;
  } else {
    *p += v0 * h + 0.5f * g * h * h;
    *v = v0 + g * h;
  }
}

/* ---- The guard after a curved step (fused_pass.cpp guard, surfaces.cl fl_bounce_guard) ----
 * A particle that its integrated step (or its bounce) left on the wrong side of a deflector,
 * compared with where it began the step (p0), is put back on its side and reflected. Each
 * backend asks its own domain code for the closest points, normals and containment (their
 * storage differs); what it does with them is here. */

/* A planar piece, with o its closest point to p0 and *n the normal there: *n turned towards
 * p0's side; 1 when p1 ended short of that side by the margin, with where the chord p0 p1
 * crosses the plane (*hit, to check it is on the piece) and where to put the particle back
 * (*back); else 0, nothing to do. */
FL_INLINE int fl_guard_planar(float3 p0, float3 p1, float3 o, float3* n, float3* hit,
                              float3* back) {
  const float d0 = fl_dotv(p0 - o, *n);
  if (d0 < 0.0f) *n = -*n;
  const float d1 = fl_dotv(p1 - o, *n);
  const float margin = 1e-6f * (1.0f + fl_lengthv(p1));
  if (d1 >= margin) return 0;
  const float dd0 = fabs(d0);
  *hit = p0 + (p1 - p0) * (dd0 / (dd0 - d1));
  *back = p1 + *n * (margin - d1);
  return 1;
}

/* Whether the crossing `hit`, at `distance` from the piece, is on it (a plane: always). */
FL_INLINE int fl_guard_on_piece(float distance, float3 hit) {
  return distance <= 1e-4f * (1.0f + fl_lengthv(hit));
}

/* A solid that keeps particles inside (inside 1) or out: whether the step took the particle
 * across it from the side it keeps (in0, in1: inside at p0, at p1). */
FL_INLINE int fl_guard_crossed(int in0, int in1, int inside) {
  return in1 != in0 && in0 == inside;
}

/* ...and then where it goes back: just off the closest point c on the kept side, the outward
 * normal there (*n) turned towards that side. */
FL_INLINE float3 fl_guard_solid_back(float3 c, int inside, float3* n) {
  *n = *n * (inside ? -1.0f : 1.0f);
  return c + *n * (1e-5f * (1.0f + fl_lengthv(c)));
}

/* The velocity reflected off the normal n (towards the kept side) when it points away. */
FL_INLINE float3 fl_guard_reflect(float3 v, float3 n, float restitution) {
  const float vn = fl_dotv(v, n);
  if (vn < 0.0f) v -= n * (vn * (1.0f + restitution));
  return v;
}

#endif /* FLURRY_KERNELS_INTEGRATE_H */
