/* The core actions (Move, KillOld, ...); forces.cl and surfaces.cl hold the other families.
 * Each function is called in list order by the fused act kernel that the backend generates
 * for each action list (particles live in registers for the whole list) and follows
 * sdk/src/cpu/kernels.hpp operation by operation.
 *
 * Adding an action: a function in its family's .cl file, and a case in that family's
 * generator and packer (sdk/src/opencl/actions_*.cpp). */

FL_INLINE void fl_kill_old(float age, float life, uint code, uint* dead) {
  *dead = fl_dead_old(age, life, code, *dead); /* absorb.h */
}

FL_INLINE void fl_move(float dt, float* px, float* py, float* pz, float vx, float vy, float vz) {
  *px += vx * dt;
  *py += vy * dt;
  *pz += vz * dt;
}

/* (Move's turn of the up vector, fl_turn_up, is in forces.h: the CPU runs it too.) */

/* ---- Spatial culling per work-group (fused_pass.cpp Culler) ------------------------------ */

/* The work-group's swept bounds: the box its straight paths p .. p + v*dt lie in and the
 * longest path |v|*dt. Every work-item of the group puts its own path (fl_cull_put; a
 * newborn's dt is its own) into red[c * FL_ACT_LOCAL + lid], as ordered integer keys (the
 * reductions are then integer min and max, which a compiler may vectorise); those past the
 * live particles (live == 0) add nothing, and a NaN or infinite particle makes the box
 * unbounded (nothing is culled then). After a barrier one work-item reduces them
 * (fl_cull_box) and takes every action's decision for the group (fl_cull_gap; the generated
 * code, codegen.cpp cullingBody): PoCL runs a work-group's work-items one after another, so
 * one work-item doing it costs what many would, and one barrier fewer. red holds
 * FL_CULL_LOCAL ints, then the decisions (generated). */
#define FL_CULL_LOCAL (7 * FL_ACT_LOCAL)
/* An order-preserving integer for a non-NaN float (-0 just below +0). */
FL_INLINE int fl_cull_key(float f) {
  const int b = as_int(f);
  return b >= 0 ? b : b ^ 0x7fffffff;
}
FL_INLINE float fl_cull_unkey(int k) { return as_float(k >= 0 ? k : k ^ 0x7fffffff); }
FL_INLINE uint fl_cull_apart(const float* box, float grow, __global const float* r);
FL_INLINE void fl_cull_put(__local int* red, uint live, float dt, float px, float py, float pz,
                           float vx, float vy, float vz) {
  const uint lid = get_local_id(0);
  const float p[3] = {px, py, pz}, v[3] = {vx, vy, vz};
  int bad = 0;
  for (int c = 0; c < 3; ++c) bad |= !isfinite(p[c]) | !isfinite(v[c]);
  for (int c = 0; c < 3; ++c) {
    const float s = fabs(v[c]) * dt;
    const float lo = bad ? -INFINITY : p[c] - s, hi = bad ? INFINITY : p[c] + s;
    red[c * FL_ACT_LOCAL + lid] = fl_cull_key(live ? lo : INFINITY);
    red[(c + 3) * FL_ACT_LOCAL + lid] = fl_cull_key(live ? hi : -INFINITY);
  }
  const float len = sqrt(vx * vx + vy * vy + vz * vz) * dt;
  red[6 * FL_ACT_LOCAL + lid] = fl_cull_key(live ? (bad ? INFINITY : len) : 0.0f);
}
/* box[0..2]: low corner, [3..5]: high corner, [6]: the longest path. */
FL_INLINE void fl_cull_box(__local const int* red, float* box) {
  for (int c = 0; c < 7; ++c) {
    __local const int* x = red + c * FL_ACT_LOCAL;
    int m = x[0];
    if (c < 3)
      for (uint k = 1u; k < FL_ACT_LOCAL; ++k) m = min(m, x[k]);
    else
      for (uint k = 1u; k < FL_ACT_LOCAL; ++k) m = max(m, x[k]);
    box[c] = fl_cull_unkey(m);
  }
}
/* How far the paths may leave the box with the action of reach r (FL_REACH_FLOATS) still out
 * of their reach; -1: it is not (or the action is not culled this step). */
FL_INLINE float fl_cull_gap(const float* box, __global const float* r) {
  if (!(r[6] >= 0.0f) || !fl_cull_apart(box, 0.0f, r)) return -1.0f;
  /* apart is monotonic in the widening: the largest of a few that still holds. */
  float d = 0.0f;
  for (int c = 0; c < 3; ++c) d = fmax(d, fmax(box[c] - r[3 + c], r[c] - box[3 + c]));
  for (float f = 0.9f; f > 0.05f; f *= 0.5f)
    if (fl_cull_apart(box, f * d, r)) return f * d;
  return 0.0f;
}

/* Whether no particle of the work-group can reach the action's reach box r (FL_REACH_FLOATS):
 * the bounds, widened by grow on every side, are apart from it by more than the rounding of
 * the action's own tests (math.h, as the CPU's Culler::apart). */
FL_INLINE uint fl_cull_apart(const float* box, float grow, __global const float* r) {
  float lo[3], hi[3], scale = 0.0f;
  for (int c = 0; c < 3; ++c) {
    lo[c] = box[c] - grow;
    hi[c] = box[3 + c] + grow;
    scale = fmax(scale, fmax(fabs(lo[c]), fabs(hi[c])));
  }
  if (!(scale < INFINITY)) return 0u; /* unbounded (or empty, or NaN): the bounds say nothing */
  return fl_reach_apart(lo, hi, scale, r, r + 3, r[6], r[7]) ? 1u : 0u;
}
