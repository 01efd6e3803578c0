/* Deaths on the device, without the host waiting for anything.
 *
 * fl_birth (tail.cl) wrote the step's newborns behind the live particles and the act kernel
 * left a kill code per particle, newborns included (0: alive). As on the CPU, the holes
 * below the new size are then closed from the tail. Which hole a tail particle takes comes
 * from a prefix sum over tiles of FL_TILE particles:
 *   fl_count  per tile: its dead                      (one work item per tile)
 *   fl_scan   prefix over the tiles, the step's counts (one work item)
 *   fl_list   per tile: hole list (holes below the new size, ascending) and tail list
 *             (survivors at or above the new size, ascending); kills tallied per action
 *   fl_tail   (tail.cl) moves tail[low - 1 - j] into holes[j]
 * Small groups (up to kSmallTiles tiles) run fl_scan_list: those three in one launch.
 * The state's size is the live count at the start of the step until fl_scan writes the new
 * one; the host only knows an upper bound (nBound), so every kernel reads the count from
 * the state (fl_step_range) and ignores particles past it. */

/* The particles a step acts on: the live ones (n0, the state's size at the start of the
 * step) and the newborns that fit behind them. Every kernel of the step before fl_scan
 * computes it so (fl_scan then writes the state). */
FL_INLINE uint fl_step_range(__global const uint* state, uint births, uint capacity) {
  const uint n0 = state[FL_STATE_SIZE];
  const uint room = capacity - n0;
  return n0 + (births < room ? births : room);
}


/* Nonzero bytes of a word (no carries between bytes). */
FL_INLINE uint fl_nonzero_bytes(uint w) {
  return popcount(((((w & 0x7F7F7F7Fu) + 0x7F7F7F7Fu) | w) & 0x80808080u));
}

FL_INLINE uint fl_count_range(__global const uchar* codes, uint begin, uint end) {
  uint c = 0;
  uint i = begin;
  if (end - begin == FL_TILE) {
    __global const uint4* w = (__global const uint4*)(codes + begin);
    for (int k = 0; k < FL_TILE / 16; ++k) {
      const uint4 q = w[k];
      c += fl_nonzero_bytes(q.x) + fl_nonzero_bytes(q.y) + fl_nonzero_bytes(q.z) +
           fl_nonzero_bytes(q.w);
    }
    return c;
  }
  for (; i < end; ++i) c += codes[i] != 0 ? 1u : 0u;
  return c;
}

__kernel void fl_count(__global const uchar* codes, __global uint* tileDead,
                       __global const uint* state, uint births, uint capacity) {
  const uint t = get_global_id(0);
  const uint n = fl_step_range(state, births, capacity);
  const uint begin = t * FL_TILE;
  const uint end = min(n, begin + FL_TILE);
  tileDead[t] = begin < end ? fl_count_range(codes, begin, end) : 0u;
}

/* The step's bookkeeping; tiles == 0 when the list kills nothing. */
FL_INLINE void fl_scan_body(__global const uchar* codes, __global const uint* tileDead,
                            __global uint* tileOff, __global uint* state, uint tiles,
                            uint births, uint capacity) {
  const uint n0 = state[FL_STATE_SIZE];
  const uint n = fl_step_range(state, births, capacity), born = n - n0;
  uint dead = 0;
  for (uint t = 0; t < tiles; ++t) {
    tileOff[t] = dead;
    dead += tileDead[t];
  }
  const uint m = n - dead;
  uint low = dead;
  if (m < n) { /* holes below m: those of the tiles before m's, and of its part before m */
    const uint t = m / FL_TILE;
    low = tileOff[t] + fl_count_range(codes, t * FL_TILE, m);
  }
  state[FL_STATE_OLD_SIZE] = n;
  state[FL_STATE_DEAD] = dead;
  state[FL_STATE_BORN] = born;
  state[FL_STATE_LOW_HOLES] = low;
  state[FL_STATE_FIRST_ID] = state[FL_STATE_NEXT_ID];
  state[FL_STATE_NEXT_ID] += born;
  state[FL_STATE_DROPPED] += births - born;
  state[FL_STATE_SIZE] = m;
}

FL_INLINE void fl_list_body(uint t, __global const uchar* codes, __global const uint* tileOff,
                            __global uint* holes, __global uint* tail,
                            __global uint* state) {
  const uint n = state[FL_STATE_OLD_SIZE], m = state[FL_STATE_SIZE];
  const uint low = state[FL_STATE_LOW_HOLES];
  const uint begin = t * FL_TILE;
  const uint end = min(n, begin + FL_TILE);
  if (begin >= end) return;
  uint dp = tileOff[t];
  uint runCode = 0, runCount = 0; /* kills tallied in runs: few atomics */
  for (uint i = begin; i < end; ++i) {
    const uint code = codes[i];
    if (code != 0u) {
      if (i < m) holes[dp] = i;
      ++dp;
      if (code != runCode) {
        if (runCount) atomic_add(&state[FL_STATE_KILLS + runCode - 1u], runCount);
        runCode = code;
        runCount = 0;
      }
      ++runCount;
    } else if (i >= m) {
      tail[(i - m) - (dp - low)] = i;
    }
  }
  if (runCount) atomic_add(&state[FL_STATE_KILLS + runCode - 1u], runCount);
}

__kernel void fl_scan(__global const uchar* codes, __global const uint* tileDead,
                      __global uint* tileOff, __global uint* state, uint tiles, uint births,
                      uint capacity) {
  fl_scan_body(codes, tileDead, tileOff, state, tiles, births, capacity);
}

__kernel void fl_list(__global const uchar* codes, __global const uint* tileOff,
                      __global const uint* tileDead, __global uint* holes, __global uint* tail,
                      __global uint* state) {
  const uint t = get_global_id(0);
  const uint begin = t * FL_TILE;
  /* A tile with no dead that lies wholly below the new size has nothing to list. */
  if (tileDead[t] == 0u && begin + FL_TILE <= state[FL_STATE_SIZE]) return;
  fl_list_body(t, codes, tileOff, holes, tail, state);
}

/* Small groups (a few tiles): count, scan and list in one work item. */
FL_INLINE void fl_scan_list_body(__global const uchar* codes, __global uint* tileDead,
                                 __global uint* tileOff, __global uint* holes,
                                 __global uint* tail, __global uint* state, uint births,
                                 uint capacity, uint tiles) {
  const uint n = fl_step_range(state, births, capacity);
  for (uint t = 0; t < tiles; ++t) {
    const uint begin = t * FL_TILE, end = min(n, begin + FL_TILE);
    tileDead[t] = begin < end ? fl_count_range(codes, begin, end) : 0u;
  }
  fl_scan_body(codes, tileDead, tileOff, state, tiles, births, capacity);
  for (uint t = 0; t < tiles; ++t) fl_list_body(t, codes, tileOff, holes, tail, state);
}

__kernel void fl_scan_list(__global const uchar* codes, __global uint* tileDead,
                           __global uint* tileOff, __global uint* holes, __global uint* tail,
                           __global uint* state, uint births, uint capacity, uint tiles) {
  fl_scan_list_body(codes, tileDead, tileOff, holes, tail, state, births, capacity, tiles);
}

/* An event's first six words (fl_births, fl_deaths): particle i's position and velocity
 * (zeros where `velocity` is 0). */
FL_INLINE void fl_event_motion(__global uint* e, uint i, __global const float* px,
                               __global const float* py, __global const float* pz,
                               __global const float* vx, __global const float* vy,
                               __global const float* vz, uint velocity) {
  e[0] = as_uint(px[i]);
  e[1] = as_uint(py[i]);
  e[2] = as_uint(pz[i]);
  e[3] = velocity ? as_uint(vx[i]) : 0u;
  e[4] = velocity ? as_uint(vy[i]) : 0u;
  e[5] = velocity ? as_uint(vz[i]) : 0u;
}

/* Birth events (a sub-emitter on birth; group.cpp recordBirths on the CPU): the step's
 * newborns where fl_birth wrote them, before the act kernel moves them on. events[0] gets
 * their count; newborn r is 8 words from events + 8 + 8r: position, velocity (zeros where
 * `velocity` is 0: vx..vz then alias px), id and the part of the step it had left (tau, by slot). */
__kernel void fl_births(__global const uint* state, uint births, uint capacity,
                        __global const float* px, __global const float* py,
                        __global const float* pz, __global const float* vx,
                        __global const float* vy, __global const float* vz, uint velocity,
                        __global const uint* id, __global const float* tau,
                        __global uint* events) {
  const uint r = get_global_id(0);
  const uint n0 = state[FL_STATE_SIZE];
  const uint born = fl_step_range(state, births, capacity) - n0;
  if (r == 0u) events[0] = born;
  if (r >= born) return;
  const uint i = n0 + r;
  __global uint* e = events + 8u + 8u * r;
  fl_event_motion(e, i, px, py, pz, vx, vy, vz, velocity);
  e[6] = id[i];
  e[7] = as_uint(tau[i]);
}

/* Death events (Group::recordDeaths; group.cpp recordDeaths on the CPU): the step's dead in
 * particle order, the first `room` of them, each as 8 words: position, velocity (zeros
 * where `velocity` is 0: vx..vz then alias px), id and kill code. After the scan (tileOff)
 * and before fl_tail moves survivors into the holes. One work item per tile. */
__kernel void fl_deaths(__global const uchar* codes, __global const uint* tileOff,
                        __global const uint* state, __global const float* px,
                        __global const float* py, __global const float* pz,
                        __global const float* vx, __global const float* vy,
                        __global const float* vz, uint velocity, __global const uint* id,
                        __global uint* events, uint room, uint tiles) {
  const uint t = get_global_id(0);
  if (t >= tiles) return;
  const uint n = state[FL_STATE_OLD_SIZE];
  const uint begin = t * FL_TILE;
  const uint end = min(n, begin + FL_TILE);
  uint at = tileOff[t];
  for (uint i = begin; i < end && at < room; ++i) {
    const uint code = codes[i];
    if (code == 0u) continue;
    __global uint* e = events + 8u * at;
    fl_event_motion(e, i, px, py, pz, vx, vy, vz, velocity);
    e[6] = id[i];
    e[7] = code;
    ++at;
  }
}

/* The fastest particle's |v|^2 into the state, for sub-steps by distance (fused_pass.cpp
 * makePlan), newborns included. Non-negative floats order as their bits; NaN is left out, as std::max does. */
__kernel void fl_max_speed(__global const float* restrict vx, __global const float* restrict vy,
                           __global const float* restrict vz, __global uint* state,
                           uint births, uint capacity) {
  __local uint best[64];
  const uint i = get_global_id(0), l = get_local_id(0);
  float m = 0.0f;
  const uint n = fl_step_range(state, births, capacity);
  for (uint j = i; j < n; j += get_global_size(0)) {
    const float v2 = vx[j] * vx[j] + vy[j] * vy[j] + vz[j] * vz[j];
    m = v2 > m ? v2 : m;
  }
  best[l] = as_uint(m);
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = get_local_size(0) / 2; s > 0; s >>= 1) {
    if (l < s) best[l] = max(best[l], best[l + s]);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0) atomic_max(&state[FL_STATE_MAX_SPEED2], best[0]);
}
