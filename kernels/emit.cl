/* A step's newborns (their draws placed by kernels/newborn.h, as on the CPU), written before the act kernel
 * where they were born (tail.cl fl_birth). Needs, from the generated prologue:
 *   FL_LANE_PARAMS / FL_LANE_ARGS  the stored lanes as parameters (l_px, l_vx, ...) / names
 *   FL_COPY_LANES(dst, src)        copies every stored lane's element
 *   FL_HAS_<ATTRIBUTE>             for each stored attribute
 * and after this file, the generated fl_emit(): per emitter and particle type, a call of
 * fl_newborn with the domain kinds and fuzzy modes as literals, so that each newborn's
 * draws compile to straight-line code. */

/* mode (a literal in generated code): 0 constant, 1 uniform, 2 normal. */
FL_INLINE float fl_fuzzy(__global const FlFuzzy* f, uint mode, FlRandom* rng) {
  if (mode == 0) return f->center;
  if (mode == 2) {
    const float ua = fl_uniform(rng), ub = fl_uniform(rng);
    return fl_fuzzy_normal(f->center, f->spread, ua, ub);
  }
  return fl_fuzzy_uniform(f->center, f->spread, fl_uniform(rng));
}

FL_INLINE float fl_fuzzy_nonneg(__global const FlFuzzy* f, uint mode, FlRandom* rng) {
  const float x = fl_fuzzy(f, mode, rng);
  return x < 0.0f ? 0.0f : x; /* std::max(x, 0.0f) */
}

/* Emitter::positionAt (path.h). */
FL_INLINE float3 fl_emitter_at(__global const FlEmitter* e, __global const FlKeyframe* keys,
                               fl_real t) {
  if (e->pathCount == 0)
    return fl_path_linear(fl_v3(e->position), fl_v3(e->velocity), fl_real_from_bits(e->start), t);
  __global const FlKeyframe* k = keys + e->pathFirst;
  const uint last = e->pathCount - 1;
  if (e->pathLoop != 0 && t > fl_real_from_bits(k[last].time))
    t = fl_path_wrap(t, fl_real_from_bits(k[0].time), fl_real_from_bits(k[last].time));
  if (t <= fl_real_from_bits(k[0].time)) return fl_v3(k[0].position);
  if (t >= fl_real_from_bits(k[last].time)) return fl_v3(k[last].position);
  /* The first key later than t (1 <= b <= last, as t is inside the path): a binary search,
   * as the CPU's std::upper_bound (times increase, so every search finds the same key); a
   * newborn of a long path (Orbit2's has thousands of keys) no longer walks them all. */
  uint lo = 1, hi = last;
  while (lo < hi) {
    const uint mid = lo + (hi - lo) / 2u;
    if (t < fl_real_from_bits(k[mid].time))
      hi = mid;
    else
      lo = mid + 1u;
  }
  return fl_path_between(t, fl_real_from_bits(k[lo - 1].time), fl_v3(k[lo - 1].position),
                         fl_real_from_bits(k[lo].time), fl_v3(k[lo].position));
}


/* The first draw of an emitter with several types picks one (newborn.h FL_CHOOSE_TYPE, as
 * emission_plan.hpp chooseType on the CPU). */
FL_INLINE uint fl_choose_type(__global const FlEmitter* em, __global const FlParticleType* types,
                              FlRandom* rng) {
  uint type;
#define FL_WEIGHT_OF(k) types[em->typeFirst + (k)].weight
  FL_CHOOSE_TYPE(type, em->typeCount, FL_WEIGHT_OF, fl_uniform(rng) * em->totalWeight);
#undef FL_WEIGHT_OF
  return type;
}

/* One newborn of type `type`: each value from where kernels/newborn.h says its draws start
 * (the CPU's newborns.cpp takes the same), skipping what is not stored. typeDraws is 1 when
 * the emitter has several types (fl_choose_type drew first). The kinds and modes are
 * literals (a fuzzy mode is its draw count); normalMode is 0 without Emitter::normalSpeed,
 * else 1 + its fuzzy mode. */
FL_INLINE void fl_newborn(FL_LANE_PARAMS, uint slot, uint id, float3 at,
                          __global const FlEmitter* em, __global const FlParticleType* type,
                          FlRandom* rng, __global const float* shapes, uint typeDraws,
                          uint shapeKind, uint velKind, uint colorKind, uint upKind, uint rotKind,
                          uint normalMode, uint lifeMode, uint alphaMode, uint sizeMode,
                          uint massMode, uint chargeMode) {
  uint nLife = 0u, nColor = 0u, nAlpha = 0u, nSize = 0u, nMass = 0u, nCharge = 0u, nUp = 0u,
       nRot = 0u;
#ifdef FL_HAS_LIFETIME
  nLife = lifeMode;
#endif
#ifdef FL_HAS_COLOR
  nColor = fl_domain_draws(&type->color, colorKind);
  nAlpha = alphaMode;
#endif
#ifdef FL_HAS_SIZE
  nSize = sizeMode;
#endif
#ifdef FL_HAS_MASS
  nMass = massMode;
#endif
#ifdef FL_HAS_CHARGE
  nCharge = chargeMode;
#endif
#ifdef FL_HAS_UP
  nUp = fl_domain_draws(&type->up, upKind);
#endif
#ifdef FL_HAS_ROT_VELOCITY
  nRot = fl_domain_draws(&type->rotVelocity, rotKind);
#endif
  const FlNewbornDraws from = fl_newborn_draws(
      typeDraws, fl_domain_draws(&type->velocity, velKind), fl_domain_draws(&em->shape, shapeKind),
      normalMode != 0u ? normalMode - 1u : 0u, nLife, nColor, nAlpha, nSize, nMass, nCharge, nUp,
      nRot);
  fl_seek(rng, from.velocity);
  float3 vel = fl_sample_any(&type->velocity, velKind, rng, shapes);
  fl_seek(rng, from.shape);
  const float3 shape = fl_sample_any(&em->shape, shapeKind, rng, shapes);
  if (normalMode != 0) {
    /* Every face emits along its normal: the shape's normal where the particle was born (a
     * mesh's or a union's from the sample's own draws, drawn again). */
    float u[FL_MAX_DOMAIN_DRAWS];
    if (shapeKind == FL_DOMAIN_MESH || shapeKind == FL_DOMAIN_UNION) {
      fl_seek(rng, from.shape);
      const uint n = fl_domain_draws(&em->shape, shapeKind);
      for (uint k = 0; k < n && k < FL_MAX_DOMAIN_DRAWS; ++k) u[k] = fl_uniform(rng);
    }
    fl_seek(rng, from.normal);
    const float speed = fl_fuzzy(&em->normalSpeed, normalMode - 1, rng);
    vel = vel + fl_sampled_normal(&em->shape, shapeKind, u, shape, shapes) * speed;
  }
  /* Born where the emitter was at its birth time; the act kernel moves it on from there. */
  const float3 pos = shape + at;
  l_px[slot] = pos.x;
  l_py[slot] = pos.y;
  l_pz[slot] = pos.z;
#ifdef FL_HAS_VELOCITY
  l_vx[slot] = vel.x;
  l_vy[slot] = vel.y;
  l_vz[slot] = vel.z;
#endif
#ifdef FL_HAS_PREV_POSITION
  l_prevx[slot] = pos.x;
  l_prevy[slot] = pos.y;
  l_prevz[slot] = pos.z;
#endif
#ifdef FL_HAS_LIFETIME
  fl_seek(rng, from.lifetime);
  l_life[slot] = fl_fuzzy_nonneg(&type->lifetime, lifeMode, rng);
#endif
#ifdef FL_HAS_COLOR
  {
    fl_seek(rng, from.color);
    const float3 rgb = fl_sample_any(&type->color, colorKind, rng, shapes);
    l_r[slot] = rgb.x;
    l_g[slot] = rgb.y;
    l_b[slot] = rgb.z;
    fl_seek(rng, from.alpha);
    l_a[slot] = fl_fuzzy(&type->alpha, alphaMode, rng);
  }
#endif
#ifdef FL_HAS_SIZE
  fl_seek(rng, from.size);
  l_size[slot] = fl_fuzzy_nonneg(&type->size, sizeMode, rng);
#endif
  /* What the curves over life scale (emission.cpp store). */
#if defined(FL_HAS_BIRTH_COLOR) && defined(FL_HAS_COLOR)
  l_birthr[slot] = l_r[slot];
  l_birthg[slot] = l_g[slot];
  l_birthb[slot] = l_b[slot];
  l_birtha[slot] = l_a[slot];
#elif defined(FL_HAS_BIRTH_COLOR)
  l_birthr[slot] = l_birthg[slot] = l_birthb[slot] = l_birtha[slot] = 1.0f;
#endif
#if defined(FL_HAS_BIRTH_SIZE) && defined(FL_HAS_SIZE)
  l_birthsize[slot] = l_size[slot];
#elif defined(FL_HAS_BIRTH_SIZE)
  l_birthsize[slot] = 0.05f; /* Particle::size */
#endif
#ifdef FL_HAS_MASS
  fl_seek(rng, from.mass);
  l_mass[slot] = fl_fuzzy(&type->mass, massMode, rng);
#endif
#ifdef FL_HAS_CHARGE
  fl_seek(rng, from.charge);
  l_charge[slot] = fl_fuzzy(&type->charge, chargeMode, rng);
#endif
#ifdef FL_HAS_UP
  {
    fl_seek(rng, from.up);
    const float3 up = fl_sample_any(&type->up, upKind, rng, shapes);
    l_upx[slot] = up.x;
    l_upy[slot] = up.y;
    l_upz[slot] = up.z;
  }
#endif
#ifdef FL_HAS_ROT_VELOCITY
  {
    fl_seek(rng, from.rot);
    const float3 w = fl_sample_any(&type->rotVelocity, rotKind, rng, shapes);
    l_rotx[slot] = w.x;
    l_roty[slot] = w.y;
    l_rotz[slot] = w.z;
  }
#endif
#ifdef FL_HAS_AGE
  l_age[slot] = 0.0f;
#endif
  l_id[slot] = id;
#ifdef FL_HAS_VISIBLE
  l_vis[slot] = 1u;
#endif
#ifdef FL_HAS_USER_DATA
  l_user[slot] = 0.0f;
#endif
  /* The rest pose and second velocity start as a new lane's do (GroupImpl::ensureStorage):
   * the birth position and zero, not what the slot's last particle left. */
#ifdef FL_HAS_POSITION_B
  l_pbx[slot] = pos.x;
  l_pby[slot] = pos.y;
  l_pbz[slot] = pos.z;
#endif
#ifdef FL_HAS_VELOCITY_B
  l_vbx[slot] = 0.0f;
  l_vby[slot] = 0.0f;
  l_vbz[slot] = 0.0f;
#endif
  (void)colorKind, (void)upKind, (void)rotKind, (void)lifeMode, (void)alphaMode, (void)sizeMode;
  (void)massMode, (void)chargeMode, (void)nLife, (void)nColor, (void)nAlpha, (void)nSize;
  (void)nMass, (void)nCharge, (void)nUp, (void)nRot;
}
