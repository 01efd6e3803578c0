/* Philox4x32-10 (Salmon et al., SC'11), written once for both backends in the kernels' shared
 * C subset (compat_opencl.h, sdk/src/kernel_compat.hpp). The CPU's flurry::Philox4x32 and
 * flurry::Random (sdk/src/domain.cpp) compute these rounds, its vectorised batches
 * (sampling.cpp) use these constants, and the device's streams below call them: both backends
 * draw the same numbers for the same (seed, id, step, stream). */
#ifndef FLURRY_KERNELS_PHILOX_H
#define FLURRY_KERNELS_PHILOX_H

/* The round multipliers and the key's increments (a Weyl sequence). */
#define FL_PHILOX_M0 0xD2511F53u
#define FL_PHILOX_M1 0xCD9E8D57u
#define FL_PHILOX_W0 0x9E3779B9u
#define FL_PHILOX_W1 0xBB67AE85u

/* Stream numbers the SDK reserves (flurry::stream in random.hpp, asserted equal in
 * domain.cpp); an action's draws use its index in the action list. */
#define FL_STREAM_EMISSION 0xFFFF0000u      /* a newborn's attributes */
#define FL_STREAM_EMITTER_EVENT 0xFFFF0001u /* an emitter's bursts and births */
#define FL_STREAM_PASS_THROUGH 0xFFFF0002u  /* a Sink's once-per-particle pass */
#define FL_STREAM_DEATH_EMITTER 0xFFFE0000u /* plus the death emitter's index */

/* The ten rounds on the counter (c0, c1, c2, c3) with the key (k0, k1), in place. 64-bit
 * products rather than mul_hi: PoCL's mul_hi made this ~10x slower. */
FL_INLINE void fl_philox_rounds(uint* c0, uint* c1, uint* c2, uint* c3, uint k0, uint k1) {
  uint a = *c0, b = *c1, c = *c2, d = *c3;
  FL_UNROLL
  for (int r = 0; r < 10; ++r) {
    const ulong p0 = (ulong)FL_PHILOX_M0 * a, p1 = (ulong)FL_PHILOX_M1 * c;
    a = (uint)(p1 >> 32) ^ b ^ k0;
    b = (uint)p1;
    c = (uint)(p0 >> 32) ^ d ^ k1;
    d = (uint)p0;
    k0 += FL_PHILOX_W0;
    k1 += FL_PHILOX_W1;
  }
  *c0 = a;
  *c1 = b;
  *c2 = c;
  *c3 = d;
}

/* 32 random bits as a float in [0, 1) with 24 bits of resolution (flurry::uniformFloat). */
FL_INLINE float fl_uniform_bits(uint u) {
  return (float)(u >> 8) * (1.0f / 16777216.0f);
}

#ifdef __OPENCL_VERSION__
FL_INLINE uint4 fl_philox(uint4 c, uint k0, uint k1) {
  uint a = c.x, b = c.y, d = c.z, e = c.w;
  fl_philox_rounds(&a, &b, &d, &e, k0, k1);
  return (uint4)(a, b, d, e);
}

/* One particle's stream, drawn four words at a time (flurry::Random). */
typedef struct FlRandom {
  uint k0, k1, id, step, stream, counter;
  int pos;
  uint4 block;
} FlRandom;

FL_INLINE FlRandom fl_random(uint seedLo, uint seedHi, uint id, uint step, uint stream) {
  FlRandom r;
  r.k0 = seedLo;
  r.k1 = seedHi;
  r.id = id;
  r.step = step;
  r.stream = stream;
  r.counter = 0;
  r.pos = 4;
  r.block = (uint4)(0);
  return r;
}

FL_INLINE uint fl_bits(FlRandom* r) {
  if (r->pos == 4) {
    r->block = fl_philox((uint4)(r->id, r->step, r->stream, r->counter++), r->k0, r->k1);
    r->pos = 0;
  }
  const uint w = r->pos == 0 ? r->block.x : r->pos == 1 ? r->block.y : r->pos == 2 ? r->block.z
                                                                                    : r->block.w;
  r->pos++;
  return w;
}

FL_INLINE float fl_uniform(FlRandom* r) { return fl_uniform_bits(fl_bits(r)); }

/* Moves the stream to its k-th number (where fl_newborn_draws says a value starts). Where it
 * stands already, or in the same block, it computes nothing. */
FL_INLINE void fl_seek(FlRandom* r, uint k) {
  const uint block = k >> 2, word = k & 3u;
  if (r->pos != 4 && r->counter == block + 1u) {
    r->pos = (int)word;
    return;
  }
  if (r->pos == 4 && r->counter == block && word == 0u) return;
  r->counter = block;
  r->pos = 4;
  if (word != 0u) {
    (void)fl_bits(r);
    r->pos = (int)word;
  }
}
#endif /* __OPENCL_VERSION__ */

#endif /* FLURRY_KERNELS_PHILOX_H */
