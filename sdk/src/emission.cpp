// Emission, before the act pass, and compaction, after it.
//
// A particle is born inside the step, at its birth time, where its emitter was then; it
// lives what is left of the step like every other particle: the act pass that follows runs
// it through the whole action list for that time (forces, deflectors, absorbers). So the
// newborns are written at the end of the group, each with the time it has left, and the
// holes the pass leaves are filled from the tail afterwards.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "backend.hpp"
#include "emission_plan.hpp"
#include "sampling.hpp"

namespace flurry::detail {

namespace {

constexpr std::size_t kNewbornsPerTask = 8192;  // a multiple of kBatch
constexpr std::size_t kInlineMoves = 16384;     // lane elements compaction copies inline

// Particles a rate has produced by time t: floor(rate·elapsed), with a relative guard so
// that 10.5/s over 10 s gives 105 despite the rounding of the accumulated time.
std::uint64_t producedByRate(double rate, double start, double stop, double t) {
  const double elapsed = std::min(t, stop) - start;
  if (elapsed <= 0) return 0;
  const double x = rate * elapsed;
  return std::uint64_t(std::floor(x + 1e-9 * std::max(1.0, x)));
}
std::uint64_t producedBy(const Emitter& e, double t) {
  return producedByRate(e.rate, e.start, e.stop, t);
}

std::size_t chooseType(const Emitter& e, Random& rng) {
  if (e.types.size() == 1) return 0;
  float total = 0;
  for (const auto& t : e.types) total += t.weight;
  float u = rng.uniform() * total;
  for (std::size_t k = 0; k < e.types.size(); ++k) {
    if (u < e.types[k].weight) return k;
    u -= e.types[k].weight;
  }
  return e.types.size() - 1;
}

constexpr std::size_t kBatch = 256;
constexpr int kMaxDraws = 48;

struct NewbornContext {
  GroupImpl& g;
  Lanes L;
  const StepParams& sp;
  double t1;              // end of the step
  std::uint32_t firstId;  // id of newborn 0 of this step
  std::size_t oldSize;    // newborn i is in slot oldSize + i
  float* remaining;       // newborn i lives remaining[i] of this step

  std::size_t slot(std::size_t i) const { return oldSize + i; }
  // What is left of the step after a birth at tb.
  float left(double tb) const { return float(std::max(0.0, t1 - tb)); }
};

double birthTime(const BirthRun& run, const Emitter& em, std::uint64_t q) {
  switch (run.kind) {
    case BirthRun::Rate:
      return em.start + double(run.first + q + 1) / em.rate;
    case BirthRun::Burst:
      return run.time;
    default:
      return run.time + run.dt * (run.s0 + double(q) * run.spacing) / run.span;
  }
}

const Emitter& emitterOf(const GroupImpl& g, const BirthRun& run) {
  return run.live ? g.live[run.index].emitter : g.emitters[run.index];
}

// One newborn, where and as it was born.
struct Newborn {
  Vec3 pos, vel;
  float lifetime, r, gr, bl, alpha, size, mass, charge;
  Vec3 up, rot;
};

// What the curves over life scale: the colour and size just stored (Particle's defaults for
// a lane not stored).
void storeBirth(const Lanes& L, std::size_t slot) {
  for (int c = 0; c < 4; ++c)
    if (L.birthColor[c]) L.birthColor[c][slot] = L.color[c] ? L.color[c][slot] : 1.0f;
  if (L.birthSize) L.birthSize[slot] = L.size ? L.size[slot] : Particle().size;
}

void store(const NewbornContext& nc, std::size_t slot, std::uint32_t id, const Newborn& b) {
  const Lanes& L = nc.L;
  for (int c = 0; c < 3; ++c) {
    L.p[c][slot] = b.pos[c];
    if (L.v[c]) L.v[c][slot] = b.vel[c];
    if (L.prev[c]) L.prev[c][slot] = b.pos[c];
    // A newborn's rest pose is where it was born, still (as ensureStorage gives a new lane).
    if (L.posB[c]) L.posB[c][slot] = b.pos[c];
    if (L.velB[c]) L.velB[c][slot] = 0.0f;
    if (L.up[c]) L.up[c][slot] = b.up[c];
    if (L.rot[c]) L.rot[c][slot] = b.rot[c];
  }
  if (L.lifetime) L.lifetime[slot] = std::max(b.lifetime, 0.0f);
  if (L.color[0]) {
    L.color[0][slot] = b.r;
    L.color[1][slot] = b.gr;
    L.color[2][slot] = b.bl;
    L.color[3][slot] = b.alpha;
  }
  if (L.size) L.size[slot] = std::max(b.size, 0.0f);
  storeBirth(L, slot);
  if (L.mass) L.mass[slot] = b.mass;
  if (L.charge) L.charge[slot] = b.charge;
  if (L.age) L.age[slot] = 0.0f;
  L.id[slot] = id;
  if (L.visible) L.visible[slot] = 1u;
  if (L.user) L.user[slot] = 0.0f;
}

// Emitters with one particle type: every draw of a batch at once (see sampling.hpp).
void emitBatch(const NewbornContext& nc, const BirthRun& run, const Emitter& em, std::uint64_t q0,
               std::size_t i0, std::size_t m) {
  const Lanes& L = nc.L;
  const ParticleType& type = em.types[0];
  // Scratch per thread, on the heap and reached through a pointer read once: in a shared
  // library every access to a thread_local object goes through __tls_get_addr, and GCC
  // folds a reference to one back into such accesses, once per element of the loops below.
  struct Scratch {
    float rows[kMaxDraws][kBatch];
    float attr[16][kBatch];
    float up[3][kBatch], rot[3][kBatch];
    float age[kBatch];  // zeros
    std::uint32_t slot[kBatch];
  };
  thread_local std::unique_ptr<Scratch> scratch;
  if (!scratch) scratch = std::make_unique<Scratch>();  // once per thread
  Scratch& sc = *scratch;
  auto& rows = sc.rows;
  auto& attr = sc.attr;
  auto& up = sc.up;
  auto& rot = sc.rot;
  auto& age = sc.age;
  auto& slot = sc.slot;
  const float* row[kMaxDraws];
  for (int k = 0; k < kMaxDraws; ++k) row[k] = rows[k];

  // The draws in the order the one-by-one path makes them.
  const bool alongNormal = !(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f);
  int draws = drawCount(type.velocity) + drawCount(em.shape);
  if (alongNormal) draws += drawCount(em.normalSpeed);
  if (L.lifetime) draws += drawCount(type.lifetime);
  if (L.color[0]) draws += drawCount(type.color) + drawCount(type.alpha);
  if (L.size) draws += drawCount(type.size);
  if (L.mass) draws += drawCount(type.mass);
  if (L.charge) draws += drawCount(type.charge);
  if (L.up[0]) draws += drawCount(type.up);
  if (L.rot[0]) draws += drawCount(type.rotVelocity);
  const std::uint32_t firstId = nc.firstId + std::uint32_t(i0);
  for (int blk = 0; blk * 4 < draws; ++blk)
    uniformBatch(nc.sp.seed, firstId, nc.g.index, stream::kEmission, std::uint32_t(blk), m,
                 rows[4 * blk], rows[4 * blk + 1], rows[4 * blk + 2], rows[4 * blk + 3]);

  int cur = 0;
  auto vec = [&](const Domain& d, int a) {
    sampleBatch(d, row + cur, m, attr[a], attr[a + 1], attr[a + 2]);
    cur += drawCount(d);
  };
  auto scalar = [&](const Fuzzy& f, int a) {
    sampleBatch(f, row + cur, m, attr[a]);
    cur += drawCount(f);
  };
  vec(type.velocity, 0);  // attr 0-2
  vec(em.shape, 3);       // 3-5
  if (alongNormal) {
    // Every face emits along its normal: the shape's normal where the particle was born.
    scalar(em.normalSpeed, 15);
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 nrm = em.shape.normal(Vec3(attr[3][k], attr[4][k], attr[5][k]));
      for (int d = 0; d < 3; ++d) attr[d][k] += nrm[d] * attr[15][k];
    }
  }
  if (L.lifetime) scalar(type.lifetime, 6);
  if (L.color[0]) {
    vec(type.color, 7);  // 7-9
    scalar(type.alpha, 10);
  }
  if (L.size) scalar(type.size, 11);
  if (L.mass) scalar(type.mass, 12);
  if (L.charge) scalar(type.charge, 13);
  if (L.up[0]) {
    sampleBatch(type.up, row + cur, m, up[0], up[1], up[2]);
    cur += drawCount(type.up);
  }
  if (L.rot[0]) sampleBatch(type.rotVelocity, row + cur, m, rot[0], rot[1], rot[2]);

  // Birth places: where the emitter was at the birth time; and the time left of the step.
  float* const px = attr[3];
  float* const py = attr[4];
  float* const pz = attr[5];
  for (std::size_t k = 0; k < m; ++k) {
    const double tb = birthTime(run, em, q0 + k);
    nc.remaining[i0 + k] = nc.left(tb);
    const Vec3 e =
        em.path.empty() ? em.position + em.velocity * float(tb - em.start) : em.positionAt(tb);
    px[k] += e.x;
    py[k] += e.y;
    pz[k] += e.z;
    age[k] = 0.0f;
    slot[k] = std::uint32_t(nc.slot(i0 + k));
  }
  // Scatter into the slots, one lane at a time.
  auto put = [&](float* lane, const float* src) {
    if (lane)
      for (std::size_t k = 0; k < m; ++k) lane[slot[k]] = src[k];
  };
  auto putNonNegative = [&](float* lane, float* src) {
    if (!lane) return;
    for (std::size_t k = 0; k < m; ++k) src[k] = std::max(src[k], 0.0f);
    put(lane, src);
  };
  for (int c = 0; c < 3; ++c) {
    put(L.p[c], attr[3 + c]);
    put(L.v[c], attr[c]);
    put(L.prev[c], attr[3 + c]);
    put(L.posB[c], attr[3 + c]);
    if (L.velB[c])
      for (std::size_t k = 0; k < m; ++k) L.velB[c][slot[k]] = 0.0f;
    put(L.up[c], up[c]);
    put(L.rot[c], rot[c]);
  }
  putNonNegative(L.lifetime, attr[6]);
  for (int c = 0; c < 4; ++c) put(L.color[c], attr[7 + c]);
  putNonNegative(L.size, attr[11]);
  put(L.mass, attr[12]);
  put(L.charge, attr[13]);
  put(L.age, age);
  if (L.birthColor[0] || L.birthSize)
    for (std::size_t k = 0; k < m; ++k) storeBirth(L, slot[k]);
  for (std::size_t k = 0; k < m; ++k) L.id[slot[k]] = firstId + std::uint32_t(k);
  if (L.visible)
    for (std::size_t k = 0; k < m; ++k) L.visible[slot[k]] = 1u;
  if (L.user)
    for (std::size_t k = 0; k < m; ++k) L.user[slot[k]] = 0.0f;
}

// Several particle types: each newborn picks its type first, then draws as emitBatch does.
void emitOneByOne(const NewbornContext& nc, const BirthRun& run, const Emitter& em,
                  std::uint64_t q0, std::size_t i0, std::size_t m) {
  const Lanes& L = nc.L;
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t id = nc.firstId + std::uint32_t(i0 + k);
    Random rng(nc.sp.seed, id, nc.g.index, stream::kEmission);
    const ParticleType& type = em.types[chooseType(em, rng)];
    const double tb = birthTime(run, em, q0 + k);
    nc.remaining[i0 + k] = nc.left(tb);
    Newborn b{};
    b.vel = type.velocity.sample(rng);
    const Vec3 local = em.shape.sample(rng);
    if (!(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f))
      b.vel += em.shape.normal(local) * em.normalSpeed.sample(rng);
    b.pos = local + em.positionAt(tb);
    if (L.lifetime) b.lifetime = type.lifetime.sample(rng);
    if (L.color[0]) {
      const Vec3 rgb = type.color.sample(rng);
      b.r = rgb.x;
      b.gr = rgb.y;
      b.bl = rgb.z;
      b.alpha = type.alpha.sample(rng);
    }
    if (L.size) b.size = type.size.sample(rng);
    if (L.mass) b.mass = type.mass.sample(rng);
    if (L.charge) b.charge = type.charge.sample(rng);
    if (L.up[0]) b.up = type.up.sample(rng);
    if (L.rot[0]) b.rot = type.rotVelocity.sample(rng);
    store(nc, nc.slot(i0 + k), id, b);
  }
}

// ---- Planning: who is born this step, by which emitter, when -----------------------------

// The most births one step of a group counts, all its emitters together. No group holds
// more than 2^32 particles, so nothing that could be created is lost; what an absurd rate,
// spacing or burst asks for beyond it (rate 1e25 is 1.7e23 births a step) is neither
// created nor counted, and the 64-bit statistics cannot overflow.
constexpr std::uint64_t kMaxStepBirths = std::uint64_t(1) << 40;

// Below 2^53 a count since the emitter's start is an exact double: rates count exactly.
constexpr double kExactCount = 9007199254740992.0;

// A double count (floored) as an integer, at most `limit`: converting a double past 2^64
// (or NaN) to an integer is undefined behaviour.
std::uint64_t clampCount(double x, std::uint64_t limit) {
  if (!(x >= 1.0)) return 0;
  if (x >= double(limit)) return limit;
  return std::min(limit, std::uint64_t(x));
}

// The runs of one step (or of one prime emitter's spawns) and their births so far. Once
// `written` births are planned the rest can never be created (the group holds no more), so
// later runs are merged into the last one: the runs stay at most `written` long however
// many bursts fire, and the counts stay right.
struct Plan {
  std::vector<BirthRun>& runs;
  std::uint64_t written;
  std::uint64_t total = 0;

  std::uint64_t room() const { return kMaxStepBirths - total; }
  // `run.count` is at most room().
  void add(const BirthRun& run) {
    if (run.count == 0) return;
    if (total >= written && !runs.empty())
      runs.back().count += run.count;
    else
      runs.push_back(run);
    total += run.count;
  }
};

// The first r in [0, n) with pred(r), or n: pred is false then true as r grows.
template <class Pred>
std::uint64_t firstWhere(std::uint64_t n, Pred pred) {
  std::uint64_t lo = 0, hi = n;
  while (lo < hi) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    if (pred(mid))
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// The births of one emitter (static or live) over (t0, t1]: its rate, its bursts in
// [t0, t1), and one birth per `spacing` of the path it travels. Returns the births counted.
std::uint64_t planEmitter(const Emitter& em, EmitterState& state, bool live, std::uint32_t index,
                          double t0, double t1, Plan& plan) {
  const std::uint64_t before = plan.total;
  if (em.rate > 0) {
    const double elapsed = std::min(t1, em.stop) - em.start;
    if (elapsed <= 0 || em.rate * elapsed < kExactCount) {
      const std::uint64_t target = producedBy(em, t1);
      if (target > state.emittedByRate) {
        const std::uint64_t n = std::min(target - state.emittedByRate, plan.room());
        plan.add({BirthRun::Rate, live, index, state.emittedByRate, 0.0, n});
        state.emittedByRate = target;
      }
    } else {
      // Past 2^53 births since the start no integer count is exact: this step's births are
      // the rate times its time, evenly spaced 1/rate apart from its start (as a run of
      // evenly spaced times, which a Distance run is).
      const double x1 = em.rate * elapsed;
      const double x0 = em.rate * std::max(0.0, std::min(t0, em.stop) - em.start);
      const std::uint64_t n =
          clampCount(std::floor(x1 - std::max(x0, double(state.emittedByRate))), plan.room());
      if (n > 0) {
        BirthRun run{BirthRun::Distance, live, index, 0, std::max(t0, em.start), n};
        run.s0 = run.spacing = 1.0 / em.rate;
        run.span = run.dt = 1.0;
        plan.add(run);
      }
      state.emittedByRate = clampCount(x1, ~std::uint64_t(0));
    }
  }
  const double lo = std::max(t0, em.start);
  for (const Burst& b : em.bursts) {
    if (b.count == 0) continue;
    // Occurrence r fires at b.time + r·interval, which never decreases with r: the ones in
    // [lo, t1) and not after the stop are one range, found by bisection whatever `repeat`.
    const auto at = [&](std::uint64_t r) { return b.time + double(r) * b.interval; };
    const std::uint64_t r0 = firstWhere(b.repeat, [&](std::uint64_t r) { return at(r) >= lo; });
    const std::uint64_t r1 =
        firstWhere(b.repeat, [&](std::uint64_t r) { return at(r) >= t1 || at(r) > em.stop; });
    for (std::uint64_t r = r0; r < r1 && plan.room() > 0; ++r) {
      std::uint64_t n = std::min<std::uint64_t>(b.count, plan.room());
      if (plan.total >= plan.written) {
        // None of the rest can be created: count them at once, in the last run.
        const std::uint64_t left = r1 - r;
        n = left > plan.room() / b.count ? plan.room() : left * b.count;
        r = r1 - 1;
      }
      plan.add({BirthRun::Burst, live, index, 0, at(r), n});
    }
  }
  if (em.spacing > 0) {
    const double a = std::max(t0, em.start), b = std::min(t1, em.stop);
    if (b > a) {
      const double span = glm::length(em.positionAt(b) - em.positionAt(a));
      // Births at distances spacing - travelled, + spacing, ... along this step's path.
      const double s0 = em.spacing - state.travelled;
      if (span >= s0) {
        const double gaps = std::floor((span - s0) / em.spacing);  // births after the first
        if (plan.room() > 0) {
          const std::uint64_t count = clampCount(gaps, plan.room() - 1) + 1;
          BirthRun run{BirthRun::Distance, live, index, 0, a, count};
          run.s0 = s0;
          run.spacing = em.spacing;
          run.span = span;
          run.dt = b - a;
          plan.add(run);
        }
        state.travelled = span - (s0 + gaps * em.spacing);
        // Past 2^53 gaps the product is rounded: keep what is left of a gap a part of one.
        if (!(gaps < kExactCount))
          state.travelled = std::isfinite(state.travelled)
                                ? std::clamp(state.travelled, 0.0, double(em.spacing))
                                : 0.0;
      } else {
        state.travelled += span;
      }
    }
  }
  return plan.total - before;
}

// Exact motion under constant acceleration and linear drag over time t.
void fly(const EmitterSpec& spec, Vec3 p0, Vec3 v0, double t, Vec3& p, Vec3& v) {
  const float k = spec.drag, tf = float(t);
  const Vec3 a = spec.acceleration;
  if (k > 0.0f) {
    const float e = std::exp(-k * tf);
    const Vec3 terminal = a / k;
    v = terminal + (v0 - terminal) * e;
    p = p0 + terminal * tf + (v0 - terminal) * ((1.0f - e) / k);
  } else {
    v = v0 + a * tf;
    p = p0 + v0 * tf + a * (0.5f * tf * tf);
  }
}

// Room for one more live emitter of prime emitter `prime`: its own limit, and the group's
// storage grown (geometrically, never past the sum of the limits) so that spawning never
// allocates without bound.
bool reserveLive(GroupImpl& g, std::uint32_t prime) {
  if (g.primeLive[prime] >= g.primes[prime].maxEmitters) return false;
  if (g.live.size() == g.live.capacity()) {
    std::size_t limit = 0;
    for (const PrimeEmitter& p : g.primes) limit += p.maxEmitters;
    g.live.reserve(std::min(limit, std::max<std::size_t>(16, 2 * g.live.capacity())));
  }
  return true;
}

// Spawns up to `count` emitters of prime emitter `prime` at `birth` (as many as its limit
// leaves room for); the rest are counted dropped. Returns how many were spawned.
std::uint64_t spawn(GroupImpl& g, const StepParams& sp, std::uint32_t prime,
                    const std::shared_ptr<const EmitterSpec>& spec, std::uint64_t count,
                    double birth, Vec3 place, Vec3 parentVelocity, std::uint32_t generation,
                    const Domain* shape) {
  std::uint64_t made = 0;
  for (; made < count && reserveLive(g, prime); ++made) {
    const std::uint32_t id = g.nextEmitterId++;
    Random rng(sp.seed, id, g.index, stream::kEmitterEvent);
    LiveEmitter e;
    e.id = id;
    e.prime = prime;
    e.position = place + (shape ? shape->sample(rng) : Vec3(0.0f));
    e.velocity = spec->velocity.sample(rng) + parentVelocity * spec->inheritVelocity;
    const double life = std::max(1e-6f, spec->lifetime.sample(rng));
    e.birth = birth;
    e.death = birth + life;
    e.generation = generation;
    e.emitter = spec->emitter;
    e.emitter.start = birth;
    e.emitter.stop = std::min(e.death, birth + (spec->emitter.stop - spec->emitter.start));
    for (Burst& b : e.emitter.bursts) b.time += birth;  // a spec's bursts are timed from birth
    e.spec = spec.get();
    e.keepAlive = spec;
    g.live.push_back(std::move(e));
    ++g.primeLive[prime];
  }
  g.stats.emittersSpawned += made;
  g.stats.emittersDropped += count - made;
  return made;
}

void countGeneration(GroupImpl& g, std::uint32_t generation, std::uint64_t n) {
  if (g.stats.emittedByGeneration.size() <= generation)
    g.stats.emittedByGeneration.resize(generation + 1, 0);
  g.stats.emittedByGeneration[generation] += n;
}

}  // namespace

std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, std::vector<BirthRun>& runs) {
  const double t0 = sp.time, t1 = sp.time + sp.dt;
  Plan plan{runs, g.capacity};
  for (std::uint32_t e = 0; e < g.emitters.size(); ++e) {
    const std::uint64_t n = planEmitter(g.emitters[e], g.emitterState[e], false, e, t0, t1, plan);
    countGeneration(g, 0, n);
  }
  // Prime emitters spawn emitters at their birth times, where the prime was then.
  if (g.primeSpecs.size() != g.primes.size()) {
    g.primeSpecs.clear();
    for (const PrimeEmitter& p : g.primes)
      g.primeSpecs.push_back(std::make_shared<EmitterSpec>(p.child));
  }
  // Scratch kept between steps: a prime emitter's runs stop growing at its free room.
  thread_local Emitter counter;  // a prime emitter counts like an emitter
  thread_local std::vector<BirthRun> spawnStore;
  for (std::uint32_t k = 0; k < g.primes.size(); ++k) {
    const PrimeEmitter& prime = g.primes[k];
    counter.rate = prime.rate;
    counter.bursts = prime.bursts;
    counter.start = prime.start;
    counter.stop = prime.stop;
    spawnStore.clear();
    const std::uint64_t room =
        prime.maxEmitters > g.primeLive[k] ? prime.maxEmitters - g.primeLive[k] : 0;
    Plan spawns{spawnStore, room};
    planEmitter(counter, g.primeState[k], false, 0, t0, t1, spawns);
    for (const BirthRun& run : spawnStore) {
      std::uint64_t q = 0;
      for (; q < run.count && g.primeLive[k] < prime.maxEmitters; ++q) {
        const double tb = birthTime(run, counter, q);
        spawn(g, sp, k, g.primeSpecs[k], 1, tb, prime.positionAt(tb), prime.velocity, 1,
              &prime.shape);
      }
      g.stats.emittersDropped += run.count - q;  // no room left: counted, not spawned
    }
  }
  // Live emitters (those spawned just now too, and their death children): move, emit, die.
  for (std::size_t k = 0; k < g.live.size(); ++k) {
    LiveEmitter& e = g.live[k];
    const double a = std::max(t0, e.birth), b = std::min(t1, e.death);
    if (b < a) continue;
    const double stateTime = std::max(t0, e.birth);
    Vec3 pb, vb, pm, vm;
    fly(*e.spec, e.position, e.velocity, b - stateTime, pb, vb);
    fly(*e.spec, e.position, e.velocity, 0.5 * (b - stateTime), pm, vm);
    // This step's curved flight as three keys: births inside the step sit on it.
    e.emitter.path = {{a, e.position}, {0.5 * (a + b), pm}, {b, pb}};
    if (!(b > a)) e.emitter.path.resize(1);
    std::uint64_t n = planEmitter(e.emitter, e.state, true, std::uint32_t(k), a, b + 1e-12, plan);
    e.position = pb;
    e.velocity = vb;
    if (e.death <= t1) {
      const EmitterSpec& spec = *e.spec;
      const std::uint64_t burst = std::min<std::uint64_t>(spec.deathBurst, plan.room());
      plan.add({BirthRun::Burst, true, std::uint32_t(k), 0, e.death, burst});
      n += burst;
      // spawn() grows g.live, which may move `e`: take what the children need first. A
      // dying emitter holds its place until the step ends, so live emitters never outnumber
      // the limit.
      const double death = e.death;
      const std::uint32_t generation = e.generation + 1, prime = e.prime;
      if (spec.deathChildren > 0)
        spawn(g, sp, prime, spec.next, spec.deathChildren, death, pb, vb, generation, nullptr);
    }
    countGeneration(g, g.live[k].generation, n);
  }
  return plan.total;
}

namespace {
// Whether planEmitter could plan a birth over (t0, t1] or change the emitter's state, for
// an emitter (or a prime emitter counting like one) with these fields. Conservative: true
// whenever in doubt.
bool mayFire(double rate, const std::vector<Burst>& bursts, double start, double stop,
             double spacing, const EmitterState& s, double t0, double t1) {
  if (rate > 0) {
    const double elapsed = std::min(t1, stop) - start;
    if (elapsed > 0 && !(rate * elapsed < kExactCount)) return true;
    if (producedByRate(rate, start, stop, t1) > s.emittedByRate) return true;
  }
  const double lo = std::max(t0, start);
  for (const Burst& b : bursts) {
    if (b.count == 0 || b.repeat == 0) continue;
    const double last = b.time + double(b.repeat - 1) * b.interval;
    if (!(std::max(b.time, last) < lo) && !(std::min(b.time, last) >= t1) && !(lo > stop))
      return true;
  }
  return spacing > 0 && std::min(t1, stop) > lo;
}
}  // namespace

bool mayEmit(const GroupImpl& g, const StepParams& sp) {
  const double t0 = sp.time, t1 = sp.time + sp.dt;
  if (!g.live.empty()) return true;
  for (std::size_t e = 0; e < g.emitters.size(); ++e) {
    const Emitter& em = g.emitters[e];
    if (mayFire(em.rate, em.bursts, em.start, em.stop, em.spacing, g.emitterState[e], t0, t1))
      return true;
  }
  for (std::size_t k = 0; k < g.primes.size(); ++k) {
    const PrimeEmitter& p = g.primes[k];
    if (mayFire(p.rate, p.bursts, p.start, p.stop, 0.0, g.primeState[k], t0, t1)) return true;
  }
  return false;
}

// Live emitters that died this step go after their last births are written.
void retireDead(GroupImpl& g, double t1) {
  std::erase_if(g.live, [&](const LiveEmitter& e) {
    if (e.death > t1) return false;
    --g.primeLive[e.prime];
    return true;
  });
}

void emitNewborns(GroupImpl& g, const StepParams& sp) {
  const double t1 = sp.time + sp.dt;
  g.bornFirst = g.size;
  g.bornCount = 0;

  // 1. How many are born, by which emitter, when.
  // Scratch kept between steps; named through references because the worker threads below
  // must see this thread's vectors, not their own thread_local ones.
  thread_local std::vector<BirthRun> runsStore;
  thread_local std::vector<std::uint64_t> runStartStore;
  auto& runs = runsStore;
  auto& runStart = runStartStore;
  runs.clear();
  const std::uint64_t total = planBirths(g, sp, runs);
  g.stats.emitted += total;
  const std::size_t accepted = std::size_t(std::min<std::uint64_t>(total, g.capacity - g.size));
  g.stats.droppedAtCapacity += total - accepted;

  // 2. The newborns, in parallel: each one's attributes depend only on its id.
  if (accepted > 0) {
    // Grown geometrically: a step that gives birth to more than any before seldom allocates.
    if (g.bornRemaining.size() < accepted)
      g.bornRemaining.resize(
          std::min<std::size_t>(g.capacity, std::max(accepted, 2 * g.bornRemaining.size())));
    runStart.assign(runs.size() + 1, 0);
    for (std::size_t r = 0; r < runs.size(); ++r) runStart[r + 1] = runStart[r] + runs[r].count;
    NewbornContext nc{g, g.lanePointers(), sp, t1, g.nextId, g.size, g.bornRemaining.data()};
    const std::size_t tasks = (accepted + kNewbornsPerTask - 1) / kNewbornsPerTask;
    sp.pool->parallelFor(tasks, [&](std::size_t task) {
      const std::size_t a = task * kNewbornsPerTask;
      const std::size_t b = std::min(accepted, a + kNewbornsPerTask);
      std::size_t r =
          std::size_t(std::upper_bound(runStart.begin(), runStart.end(), a) - runStart.begin()) - 1;
      // Split the task at run boundaries: a batch shares one emitter and birth rule.
      for (std::size_t i = a; i < b;) {
        while (i >= runStart[r + 1]) ++r;
        const std::size_t end = std::min<std::size_t>(b, runStart[r + 1]);
        const Emitter& em = emitterOf(g, runs[r]);
        for (std::size_t j = i; j < end; j += kBatch) {
          const std::size_t m = std::min(kBatch, end - j);
          if (em.types.size() == 1)
            emitBatch(nc, runs[r], em, j - runStart[r], j, m);
          else
            emitOneByOne(nc, runs[r], em, j - runStart[r], j, m);
        }
        i = end;
      }
    });
    g.nextId += std::uint32_t(accepted);
    g.bornCount = accepted;
    g.size += accepted;
  }

  retireDead(g, t1);
}

void compact(GroupImpl& g, const StepParams& sp) {
  g.bornCount = 0;  // the step's newborns are ordinary particles from now on
  // Close the holes with the live particles at the tail: the lowest hole takes the last.
  if (g.holes.empty()) return;
  const std::uint32_t* left = g.holes.data();  // ascending
  const std::size_t leftCount = g.holes.size();
  const std::size_t newSize = g.size - leftCount;
  thread_local std::vector<std::pair<std::uint32_t, std::uint32_t>> movesStore;
  auto& moves = movesStore;  // (from, to)
  moves.clear();
  // As many as the holes may ever be (their capacity only grows): a step that leaves more
  // holes than any before does not allocate.
  if (moves.capacity() < leftCount) moves.reserve(std::max(leftCount, g.holes.capacity()));
  std::size_t src = g.size;      // candidates below this
  std::size_t back = leftCount;  // holes at or above src are left[back..]
  for (std::size_t h = 0; h < leftCount && left[h] < newSize; ++h) {
    do {
      --src;
    } while (back > 0 && left[back - 1] == src && (--back, true));
    moves.emplace_back(std::uint32_t(src), left[h]);
  }
  g.size = newSize;
  if (moves.empty()) return;
  std::array<std::uint32_t*, std::size_t(Attribute::Count) * 4> stored;  // no allocation
  std::size_t lanes = 0;
  for (auto& attr : g.lanes)
    for (auto& lane : attr)
      if (lane) stored[lanes++] = lane.u();
  auto moveLane = [&](std::uint32_t* lane, std::size_t a, std::size_t b) {
    for (std::size_t k = a; k < b; ++k) lane[moves[k].second] = lane[moves[k].first];
  };
  // A few moves (a small group, or a near-steady one) cost less than waking a worker.
  if (moves.size() * lanes <= kInlineMoves) {
    for (std::size_t l = 0; l < lanes; ++l) moveLane(stored[l], 0, moves.size());
    return;
  }
  const std::size_t perTask = 65536;
  const std::size_t chunks = (moves.size() + perTask - 1) / perTask;
  sp.pool->parallelFor(lanes * chunks, [&](std::size_t t) {
    const std::size_t a = (t % chunks) * perTask;
    moveLane(stored[t / chunks], a, std::min(moves.size(), a + perTask));
  });
}

}  // namespace flurry::detail
