/* Absorbers' kill tests (KillOld, Sink, SinkVelocity), written once for both backends in the
 * kernels' shared C subset (compat_opencl.h, sdk/src/kernel_compat.hpp). A particle's `dead`
 * is 0 while it lives, else the code (1 + index in the list) of the first action that killed
 * it: a later kill does not overwrite it. Branch-free, so the CPU's loops vectorise. Whether a
 * point is inside a domain is each side's domain code. */
#ifndef FLURRY_KERNELS_ABSORB_H
#define FLURRY_KERNELS_ABSORB_H

/* The new dead after an action with `code` that kills where `kill` is nonzero. The code is
 * masked, not selected by `kill ? code : 0`: from a C++ bool, GCC vectorised that select two
 * floats wide (8-byte vectors) and every sink loop with it. */
FL_INLINE uint fl_dead_if(int kill, uint code, uint dead) {
  const uint k = code & (0u - (uint)(kill != 0));
  return dead != 0u ? dead : k;
}

/* KillOld: past its lifetime. */
FL_INLINE uint fl_dead_old(float age, float life, uint code, uint dead) {
  return fl_dead_if(age > life, code, dead);
}

/* Sink (Inside, Outside) and SinkVelocity: `inside` the region, killing those inside when
 * killInside, else those outside. */
FL_INLINE uint fl_dead_sink(int inside, int killInside, uint code, uint dead) {
  return fl_dead_if((inside != 0) == (killInside != 0), code, dead);
}

/* Sink (Enter, Leave): inside now and at the end of the coming Move's straight step. */
FL_INLINE uint fl_dead_sink_motion(int now, int next, int enter, uint code, uint dead) {
  const int k = enter ? ((!now) & next) : (now & (!next));
  return fl_dead_if(k, code, dead);
}

/* Sink (Hit): the coming Move's path crosses the piece's plane at h (fl_path_crosses), at
 * `distance` from the piece: on it, within the rounding of the crossing, it is absorbed. */
FL_INLINE uint fl_dead_sink_hit(float distance, float3 h, uint code, uint dead) {
  return fl_dead_if(distance <= 1e-5f * (1.0f + fl_lengthv(h)), code, dead);
}

/* Block: a particle inside the region is hidden (the list's first blocker starts from 1). */
FL_INLINE uint fl_visible_after_block(int inside, uint visible) {
  return visible & (1u - (uint)(inside != 0));
}

/* The particles an absorber with a pass-through fraction kills survive if this holds: u is
 * the first word of their pass-through Philox block, as a uniform in [0, 1). */
FL_INLINE int fl_passes(uint u, float fraction) {
  return fl_uniform_bits(u) < fraction;
}

/* After an absorber with action code `code` and a pass-through fraction: the particles it
 * took pass if one Philox word of (id, key, FL_STREAM_PASS_THROUGH, 0) says so. The same word
 * every step, so the decision is made once per particle and absorber (key: the group's stream
 * base + the absorber's index in the list). */
FL_INLINE uint fl_dead_after_pass(uint dead, uint code, uint id, uint key, uint seedLo,
                                  uint seedHi, float fraction) {
  uint w0 = id, w1 = key, w2 = FL_STREAM_PASS_THROUGH, w3 = 0u;
  if (dead != code) return dead;
  fl_philox_rounds(&w0, &w1, &w2, &w3, seedLo, seedHi);
  return fl_passes(w0, fraction) ? 0u : dead;
}

#endif /* FLURRY_KERNELS_ABSORB_H */
