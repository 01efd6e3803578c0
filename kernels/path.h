/* An emitter's motion, written once for both backends in the kernels' shared C subset: the
 * CPU's pathPositionAt (sdk/src/emitter.cpp) and the device's fl_emitter_at (emit.cl). Each
 * finds the path's key with its own search over its own layout of keys (the CPU walks on from
 * the last key found, the device searches); times increase, so both find the same one. */
#ifndef FLURRY_KERNELS_PATH_H
#define FLURRY_KERNELS_PATH_H

/* Without a path: from `position` at `start` with `velocity`. */
FL_INLINE float3 fl_path_linear(float3 position, float3 velocity, fl_real start, fl_real t) {
  return position + velocity * (float)(t - start);
}

/* A looping path's time past its last key (t1) brought back into [t0, t1]: fmod is exact, so
 * both backends wrap to the same time. */
FL_INLINE fl_real fl_path_wrap(fl_real t, fl_real t0, fl_real t1) {
  return t0 + fmod(t - t0, t1 - t0);
}

/* Between key a (at ta) and the next key b (at tb), ta <= t < tb. */
FL_INLINE float3 fl_path_between(fl_real t, fl_real ta, float3 a, fl_real tb, float3 b) {
  const fl_real w = (t - ta) / (tb - ta);
  return a + (b - a) * (float)w;
}

#endif /* FLURRY_KERNELS_PATH_H */
