/* A step's emission and its compaction (see emit.cl, compact.cl); after the generated
 * fl_emit(). Work-item gid of gsize (fl_birth / fl_tail: the whole launch; fl_small: one
 * work-group). */

/* Writes the newborns (sdk/src/emission.cpp, draw for draw): newborn r into slot n0 + r,
 * where it was born, and the part of the step it still has to live into tau[n0 + r], by slot
 * as the lanes (the act kernel runs it through the list for that time; its work-items read
 * tau[i] as they read the lanes, consecutively, which a CPU driver vectorises without
 * touching memory outside the buffer). Reads the state, writes none of it. */
FL_INLINE void fl_birth_body(uint gid, uint gsize, FL_LANE_PARAMS, __global float* tau,
                             __global const uint* state, uint births, uint capacity,
                             __global const uchar* tables, uint offEmitters, uint offTypes,
                             uint offKeys, uint offShapes, uint runCount, ulong t1Bits,
                             uint seedLo, uint seedHi, uint salt) {
  /* The step's emission tables, back to back in one buffer (runs first). */
  __global const FlBirthRun* runs = (__global const FlBirthRun*)tables;
  __global const FlEmitter* emitters = (__global const FlEmitter*)(tables + offEmitters);
  __global const FlParticleType* types = (__global const FlParticleType*)(tables + offTypes);
  __global const FlKeyframe* keys = (__global const FlKeyframe*)(tables + offKeys);
  __global const float* shapes = (__global const float*)(tables + offShapes);
  const uint n0 = state[FL_STATE_SIZE];
  const uint born = fl_step_range(state, births, capacity) - n0;
  const uint firstId = state[FL_STATE_NEXT_ID];
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
    tau[n0 + r] = (float)(dtb > 0 ? dtb : (fl_real)0);
    const float3 at = fl_emitter_at(em, keys, tb);
    const uint id = firstId + r;
    FlRandom rng = fl_random(seedLo, seedHi, id, salt, FL_STREAM_EMISSION);
    fl_emit(FL_LANE_ARGS, em->variant, n0 + r, id, at, em, types, &rng, shapes);
  }
}

__kernel void fl_birth(FL_LANE_PARAMS, __global float* tau, __global const uint* state,
                       uint births, uint capacity, __global const uchar* tables,
                       uint offEmitters, uint offTypes, uint offKeys, uint offShapes,
                       uint runCount, ulong t1Bits, uint seedLo, uint seedHi, uint salt) {
  fl_birth_body(get_global_id(0), get_global_size(0), FL_LANE_ARGS, tau, state, births,
                capacity, tables, offEmitters, offTypes, offKeys, offShapes, runCount, t1Bits,
                seedLo, seedHi, salt);
}

/* Closes the holes below the new size from the tail: the lowest hole takes the last
 * survivor, as on the CPU (emission.cpp compact), so both keep one order (neighbour actions
 * read particles by index). */
FL_INLINE void fl_tail_body(uint gid, uint gsize, FL_LANE_PARAMS, __global const uint* holes,
                            __global const uint* tail, __global const uint* state) {
  const uint moves = state[FL_STATE_LOW_HOLES];
  for (uint j = gid; j < moves; j += gsize) {
    const uint src = tail[moves - 1u - j], dst = holes[j];
    FL_COPY_LANES(dst, src);
  }
}

__kernel void fl_tail(FL_LANE_PARAMS, __global const uint* holes, __global const uint* tail,
                      __global const uint* state) {
  fl_tail_body(get_global_id(0), get_global_size(0), FL_LANE_ARGS, holes, tail, state);
}
