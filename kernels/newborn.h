/* A newborn's draws, written once for both backends (sdk/src/newborns.cpp on the CPU,
 * emit.cl fl_newborn on the device): where each of its values starts in its stream of
 * uniform numbers (Philox, FL_STREAM_EMISSION, keyed by its id), in the order both take them.
 * The n* are each value's draw count (sampling.cpp drawCount, domain.h fl_draw_count, a
 * fuzzy value's mode), 0 for a value the group does not store, or for nNormal an emitter
 * without a speed along its shape's normal; nType is 1 when the emitter has several particle
 * types (its first draw picks one), else 0. */
#ifndef FLURRY_KERNELS_NEWBORN_H
#define FLURRY_KERNELS_NEWBORN_H

typedef struct FlNewbornDraws {
  uint type, velocity, shape, normal, lifetime, color, alpha, size, mass, charge, up, rot;
  uint total; /* the draws of the newborn */
} FlNewbornDraws;

FL_INLINE FlNewbornDraws fl_newborn_draws(uint nType, uint nVelocity, uint nShape, uint nNormal,
                                          uint nLifetime, uint nColor, uint nAlpha, uint nSize,
                                          uint nMass, uint nCharge, uint nUp, uint nRot) {
  FlNewbornDraws d;
  uint at = 0u;
  d.type = at;
  at += nType;
  d.velocity = at;
  at += nVelocity;
  d.shape = at;
  at += nShape;
  d.normal = at;
  at += nNormal;
  d.lifetime = at;
  at += nLifetime;
  d.color = at;
  at += nColor;
  d.alpha = at;
  at += nAlpha;
  d.size = at;
  at += nSize;
  d.mass = at;
  at += nMass;
  d.charge = at;
  at += nCharge;
  d.up = at;
  at += nUp;
  d.rot = at;
  at += nRot;
  d.total = at;
  return d;
}

/* The type a newborn of an emitter with several types takes, into `out`: the first of `count`
 * types whose weight its draw `u` (a uniform times the weights' total) falls under, taking
 * each weight off as it passes; the last if rounding carries u past them all. `weightOf(k)`
 * is type k's weight, read from each side's own storage (the CPU's ParticleType vector, the
 * device's type table): a macro, as OpenCL C 1.2 has neither templates nor one pointer for
 * both address spaces. */
#define FL_CHOOSE_TYPE(out, count, weightOf, u)                                  \
  do {                                                                           \
    float fl_left_ = (u);                                                        \
    (out) = (count)-1u;                                                          \
    for (unsigned int fl_k_ = 0u; fl_k_ < (count); ++fl_k_) {                    \
      const float fl_w_ = weightOf(fl_k_);                                       \
      if (fl_left_ < fl_w_) {                                                    \
        (out) = fl_k_;                                                           \
        break;                                                                   \
      }                                                                          \
      fl_left_ -= fl_w_;                                                         \
    }                                                                            \
  } while (0)

#endif /* FLURRY_KERNELS_NEWBORN_H */
