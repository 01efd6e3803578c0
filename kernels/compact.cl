/* Deaths and births on the device, without the host waiting for anything.
 *
 * The act kernel leaves a kill code per particle (0: alive). Then, as on the CPU, newborns
 * take the dead's slots and only the holes no newborn fills are closed from the tail, so a
 * steady effect moves almost nothing. Which hole a newborn or a tail particle takes comes
 * from a prefix sum over tiles of FL_TILE particles:
 *   fl_count  per tile: its dead                      (one work item per tile)
 *   fl_scan   prefix over the tiles, the step's counts (one work item)
 *   fl_list   per tile: hole list (holes below the new size, ascending) and tail list
 *             (survivors at or above the new size, ascending); kills tallied per action
 *   fl_tail   (emit.cl) moves tail[j] into holes[born + j] and writes the newborns
 * Small groups (up to kSmallTiles tiles) run fl_scan_list: those three in one launch.
 * n is the live count the device holds; the host only knows an upper bound (nBound), so
 * every kernel reads n from the state and ignores particles past it. */

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
                       __global const uint* state) {
  const uint t = get_global_id(0);
  const uint n = state[FL_STATE_SIZE];
  const uint begin = t * FL_TILE;
  const uint end = min(n, begin + FL_TILE);
  tileDead[t] = begin < end ? fl_count_range(codes, begin, end) : 0u;
}

/* The step's bookkeeping; tiles == 0 when the list kills nothing. */
FL_INLINE void fl_scan_body(__global const uchar* codes, __global const uint* tileDead,
                            __global uint* tileOff, __global uint* state, uint tiles,
                            uint births, uint capacity) {
  const uint n = state[FL_STATE_SIZE];
  uint dead = 0;
  for (uint t = 0; t < tiles; ++t) {
    tileOff[t] = dead;
    dead += tileDead[t];
  }
  const uint live = n - dead;
  const uint room = capacity - live;
  const uint born = births < room ? births : room;
  const uint m = live + born;
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
  const uint n = state[FL_STATE_SIZE];
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

/* The fastest particle's |v|^2 into the state, for sub-steps by distance (fused_pass.cpp
 * makePlan). Non-negative floats order as their bits; NaN is left out, as std::max does. */
__kernel void fl_max_speed(__global const float* restrict vx, __global const float* restrict vy,
                           __global const float* restrict vz, __global uint* state) {
  __local uint best[64];
  const uint i = get_global_id(0), l = get_local_id(0);
  float m = 0.0f;
  const uint n = state[FL_STATE_SIZE];
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
