/* Philox4x32-10 (Salmon et al., SC'11) in OpenCL C: the same function as flurry::Philox4x32
 * and flurry::Random in <flurry/random.hpp>, so the two backends draw the same numbers for
 * the same (seed, id, step, stream). */
#ifndef FLURRY_KERNELS_PHILOX_H
#define FLURRY_KERNELS_PHILOX_H

FL_INLINE uint4 fl_philox(uint4 c, uint k0, uint k1) {
  /* Defined by the generated source from flurry::Philox4x32 (codegen.cpp). */
  const uint M0 = FL_PHILOX_M0, M1 = FL_PHILOX_M1;
  const uint W0 = FL_PHILOX_W0, W1 = FL_PHILOX_W1;
  uint c0 = c.x, c1 = c.y, c2 = c.z, c3 = c.w;
  /* 64-bit products rather than mul_hi: PoCL's mul_hi made this ~10x slower. */
#pragma unroll
  for (int r = 0; r < 10; ++r) {
    const ulong p0 = (ulong)M0 * c0, p1 = (ulong)M1 * c2;
    const uint hi0 = (uint)(p0 >> 32), lo0 = (uint)p0;
    const uint hi1 = (uint)(p1 >> 32), lo1 = (uint)p1;
    c0 = hi1 ^ c1 ^ k0;
    c1 = lo1;
    c2 = hi0 ^ c3 ^ k1;
    c3 = lo0;
    k0 += W0;
    k1 += W1;
  }
  return (uint4)(c0, c1, c2, c3);
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

/* Uniform in [0, 1) with 24 bits (flurry::uniformFloat). */
FL_INLINE float fl_uniform(FlRandom* r) { return (float)(fl_bits(r) >> 8) * (1.0f / 16777216.0f); }

#endif /* FLURRY_KERNELS_PHILOX_H */
