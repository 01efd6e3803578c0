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
    const float e = exp(-k * h), term = g / k;
    *p += term * h + (v0 - term) * (1.0f - e) / k;
    *v = term + (v0 - term) * e;
  } else {
    *p += v0 * h + 0.5f * g * h * h;
    *v = v0 + g * h;
  }
}

#endif /* FLURRY_KERNELS_INTEGRATE_H */
