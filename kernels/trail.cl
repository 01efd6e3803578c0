/* Trails on the device (Group::setTrail; sdk/src/group.cpp keeps them on the CPU): a ring of
 * `slots` positions per particle, slot k's x, y, z in trail[(3k + c)·capacity + i], and the
 * slots each particle's trail fills in count[i]. The host keeps the ring's head. A program of
 * its own (after compat_opencl.h, params.h and compact.cl), the same for every group. */

/* This step's newborns start a trail where they were born: slot `head`, one point
 * (startTrails). After fl_birth, before the act kernel moves them. */
__kernel void fl_trail_start(__global const float* px, __global const float* py,
                             __global const float* pz, __global float* trail,
                             __global uint* count, __global const uint* state, uint births,
                             uint capacity, uint head) {
  const uint n0 = state[FL_STATE_SIZE];
  const uint n = fl_step_range(state, births, capacity);
  for (uint i = n0 + get_global_id(0); i < n; i += get_global_size(0)) {
    trail[(3u * head) * capacity + i] = px[i];
    trail[(3u * head + 1u) * capacity + i] = py[i];
    trail[(3u * head + 2u) * capacity + i] = pz[i];
    count[i] = 1u;
  }
}

/* The trails move with their particles: after fl_tail, the same moves (the lowest hole takes
 * the last survivor). `rows` is 3·slots. */
__kernel void fl_trail_tail(__global float* trail, __global uint* count, uint rows,
                            uint capacity, __global const uint* holes,
                            __global const uint* tail, __global const uint* state) {
  const uint moves = state[FL_STATE_LOW_HOLES];
  for (uint j = get_global_id(0); j < moves; j += get_global_size(0)) {
    const uint src = tail[moves - 1u - j], dst = holes[j];
    for (uint k = 0; k < rows; ++k) trail[k * capacity + dst] = trail[k * capacity + src];
    count[dst] = count[src];
  }
}

/* After the step: every live particle's position into the ring's new head (recordTrails). */
__kernel void fl_trail_record(__global const float* px, __global const float* py,
                              __global const float* pz, __global float* trail,
                              __global uint* count, __global const uint* state, uint capacity,
                              uint head, uint slots) {
  const uint n = state[FL_STATE_SIZE];
  for (uint i = get_global_id(0); i < n; i += get_global_size(0)) {
    trail[(3u * head) * capacity + i] = px[i];
    trail[(3u * head + 1u) * capacity + i] = py[i];
    trail[(3u * head + 2u) * capacity + i] = pz[i];
    count[i] = min(count[i] + 1u, slots);
  }
}
