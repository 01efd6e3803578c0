/* The tail of a step (see emit.cl); after the generated fl_emit(). Work-item gid of gsize
 * (fl_tail: the whole launch; fl_small: one work-group). */
FL_INLINE void fl_tail_body(uint gid, uint gsize, FL_LANE_PARAMS, __global const uint* holes,
                            __global const uint* tail, __global const uint* state,
                            __global const uchar* tables, uint offEmitters, uint offTypes,
                            uint offKeys, uint offShapes, uint runCount, ulong t1Bits,
                            uint seedLo, uint seedHi, uint salt) {
  /* The step's emission tables, back to back in one buffer (runs first). */
  __global const FlBirthRun* runs = (__global const FlBirthRun*)tables;
  __global const FlEmitter* emitters = (__global const FlEmitter*)(tables + offEmitters);
  __global const FlParticleType* types = (__global const FlParticleType*)(tables + offTypes);
  __global const FlKeyframe* keys = (__global const FlKeyframe*)(tables + offKeys);
  __global const float* shapes = (__global const float*)(tables + offShapes);
  const uint born = state[FL_STATE_BORN], low = state[FL_STATE_LOW_HOLES];
  const uint n = state[FL_STATE_OLD_SIZE];

  /* Holes below the new size that no newborn takes, filled from the tail: the lowest hole
   * takes the last survivor, as on the CPU (emission.cpp), so both keep one order (neighbour
   * actions read particles by index). */
  const uint moves = low > born ? low - born : 0u;
  for (uint j = gid; j < moves; j += gsize) {
    const uint src = tail[moves - 1u - j], dst = holes[born + j];
    FL_COPY_LANES(dst, src);
  }

  for (uint r = gid; r < born; r += gsize) {
    /* The run of newborn r: the last whose start is <= r (starts ascend; live emitters can
     * make hundreds of runs, so a binary search). */
    uint lo = 0, hi = runCount;
    while (hi - lo > 1) {
      const uint mid = (lo + hi) / 2;
      if (runs[mid].start <= r)
        lo = mid;
      else
        hi = mid;
    }
    __global const FlBirthRun* run = runs + lo;
    __global const FlEmitter* em = emitters + run->emitter;
    const ulong q = (ulong)r - run->start;
    /* emission.cpp birthTime. */
    fl_real tb;
    if (run->kind == FL_RUN_RATE)
      tb = fl_real_from_bits(em->start) +
           (fl_real)(run->first + q + 1) / fl_real_from_bits(em->rate);
    else if (run->kind == FL_RUN_BURST)
      tb = fl_real_from_bits(run->time);
    else
      tb = fl_real_from_bits(run->time) +
           fl_real_from_bits(run->dt) *
               (fl_real_from_bits(run->s0) + (fl_real)q * fl_real_from_bits(run->spacing)) /
               fl_real_from_bits(run->span);
    const fl_real dtb = fl_real_from_bits(t1Bits) - tb;
    const float age = (float)(dtb > 0 ? dtb : (fl_real)0);
    const float3 at = fl_emitter_at(em, keys, tb);
    const uint id = state[FL_STATE_FIRST_ID] + r;
    const uint slot = r < low ? holes[r] : n + (r - low);
    FlRandom rng = fl_random(seedLo, seedHi, id, salt, FL_EMISSION_STREAM);
    fl_emit(FL_LANE_ARGS, em->variant, slot, id, age, at, em, types, &rng, shapes);
  }
}

__kernel void fl_tail(FL_LANE_PARAMS, __global const uint* holes, __global const uint* tail,
                      __global const uint* state, __global const uchar* tables,
                      uint offEmitters, uint offTypes, uint offKeys, uint offShapes,
                      uint runCount, ulong t1Bits, uint seedLo, uint seedHi, uint salt) {
  fl_tail_body(get_global_id(0), get_global_size(0), FL_LANE_ARGS, holes, tail, state, tables,
               offEmitters, offTypes, offKeys, offShapes, runCount, t1Bits, seedLo, seedHi,
               salt);
}
