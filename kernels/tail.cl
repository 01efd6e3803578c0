/* The tail of a step (see emit.cl); after the generated fl_emit(). */
__kernel void fl_tail(FL_LANE_PARAMS, __global const uint* holes, __global const uint* tail,
                      __global const uint* state, __global const FlBirthRun* runs,
                      __global const FlEmitter* emitters, __global const FlParticleType* types,
                      __global const FlKeyframe* keys, uint runCount, ulong t1Bits,
                      uint seedLo, uint seedHi, uint salt) {
  const uint gid = get_global_id(0), gsize = get_global_size(0);
  const uint born = state[FL_STATE_BORN], low = state[FL_STATE_LOW_HOLES];
  const uint n = state[FL_STATE_OLD_SIZE];

  /* Holes below the new size that no newborn takes, filled from the tail in order. */
  const uint moves = low > born ? low - born : 0u;
  for (uint j = gid; j < moves; j += gsize) {
    const uint src = tail[j], dst = holes[born + j];
    FL_COPY_LANES(dst, src);
  }

  if (gid >= born) return;
  const uint r = gid;
  uint k = 0; /* the run of newborn r: runs are few and sorted by start */
  while (k + 1 < runCount && runs[k + 1].start <= r) ++k;
  __global const FlBirthRun* run = runs + k;
  __global const FlEmitter* em = emitters + run->emitter;
  const ulong q = (ulong)r - run->start;
  const fl_real tb = run->burst ? fl_real_from_bits(run->burstTime)
                                : fl_real_from_bits(em->start) +
                                      (fl_real)(run->first + q + 1) / fl_real_from_bits(em->rate);
  const fl_real dtb = fl_real_from_bits(t1Bits) - tb;
  const float age = (float)(dtb > 0 ? dtb : (fl_real)0);
  const float3 at = fl_emitter_at(em, keys, tb);
  const uint id = state[FL_STATE_FIRST_ID] + r;
  const uint slot = r < low ? holes[r] : n + (r - low);
  FlRandom rng = fl_random(seedLo, seedHi, id, salt, FL_EMISSION_STREAM);
  fl_emit(FL_LANE_ARGS, run->emitter, slot, id, age, at, em, types, &rng);
}
