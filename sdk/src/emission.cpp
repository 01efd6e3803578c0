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
#include <limits>
#include <span>
#include <utility>

#include "backend.hpp"
#include "emission_plan.hpp"

namespace flurry::detail {

namespace {

constexpr std::size_t kInlineMoves = 16384;  // lane elements compaction copies inline

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

// When occurrence r of a burst fires.
double occurrenceTime(const Burst& b, std::uint64_t r) {
  return b.time + double(r) * b.interval;
}
// The occurrences [r0, r1) of a burst that fire in [lo, t1) and not after `stop`: an
// occurrence's time never decreases with r, so they are one range, found by bisection
// whatever `repeat`.
std::pair<std::uint64_t, std::uint64_t> dueOccurrences(const Burst& b, double lo, double t1,
                                                       double stop) {
  const auto at = [&](std::uint64_t r) { return occurrenceTime(b, r); };
  return {firstWhere(b.repeat, [&](std::uint64_t r) { return at(r) >= lo; }),
          firstWhere(b.repeat, [&](std::uint64_t r) { return at(r) >= t1 || at(r) > stop; })};
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
    const auto [r0, r1] = dueOccurrences(b, lo, t1, em.stop);
    for (std::uint64_t r = r0; r < r1 && plan.room() > 0; ++r) {
      std::uint64_t n = std::min<std::uint64_t>(b.count, plan.room());
      if (plan.total >= plan.written) {
        // None of the rest can be created: count them at once, in the last run.
        const std::uint64_t left = r1 - r;
        n = left > plan.room() / b.count ? plan.room() : left * b.count;
        r = r1 - 1;
      }
      plan.add({BirthRun::Burst, live, index, 0, occurrenceTime(b, r), n});
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
    Random rng(sp.seed, id, g.streamKey(), stream::kEmitterEvent);
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
  const double t0 = sp.time, t1 = sp.end;
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
    if (b.count == 0) continue;
    // planEmitter's occurrences. (Whether the burst's first and last occurrences bracket
    // [lo, t1) is not enough: a burst begun before a stop() that fell between two of its
    // occurrences kept its instance from ever being done().)
    const auto [r0, r1] = dueOccurrences(b, lo, t1, stop);
    if (r0 < r1) return true;
  }
  return spacing > 0 && std::min(t1, stop) > lo;
}
}  // namespace

bool mayEmit(const GroupImpl& g, const StepParams& sp) {
  const double t0 = sp.time, t1 = sp.end;
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

bool mayEverEmit(const GroupImpl& g, double at) {
  StepParams sp;
  sp.time = at;
  sp.dt = sp.end = std::numeric_limits<double>::infinity();
  return mayEmit(g, sp);
}

void stopEmitting(GroupImpl& g, double at, bool showers) {
  // Just before `at`, as a burst at `stop` itself still fires (one an instance made this
  // frame has at `at`); never before the start, and burst occurrences not yet due are
  // dropped.
  const double before = std::nextafter(at, -std::numeric_limits<double>::infinity());
  auto stop = [&](auto& e) {
    e.stop = std::max(e.start, std::min(e.stop, before));
    // A burst keeps only its occurrences before `at`: one begun before an emitter that has
    // not started (its stop then is its start) still fired at the start.
    const double never = std::numeric_limits<double>::infinity();
    for (Burst& b : e.bursts) b.repeat = std::uint32_t(dueOccurrences(b, -never, at, never).second);
    std::erase_if(e.bursts, [](const Burst& b) { return b.repeat == 0; });
  };
  for (Emitter& e : g.emitters) stop(e);
  for (PrimeEmitter& p : g.primes) stop(p);
  if (g.frame) {
    for (Emitter& e : g.frame->emitters) stop(e);
    for (PrimeEmitter& p : g.frame->primes) stop(p);
  }
  if (showers) {
    g.live.clear();
    std::fill(g.primeLive.begin(), g.primeLive.end(), 0u);
  }
  // Both copies are stopped: the world ones need no deriving again, unless edits to the
  // frame's were pending already.
  const bool derived = g.frame && g.frame->emittersDerived == g.emittersVersion;
  ++g.emittersVersion;  // the device's tables: built again
  if (derived) g.frame->emittersDerived = g.emittersVersion;
}

// Live emitters that died this step go after their last births are written.
void retireDead(GroupImpl& g, double t1) {
  std::erase_if(g.live, [&](const LiveEmitter& e) {
    if (e.death > t1) return false;
    --g.primeLive[e.prime];
    return true;
  });
}

namespace {
// Keeps `fit` of the runs' births, the same fraction of each run (BudgetPolicy::ScaleEmission):
// run r keeps the births between the rounded shares of the counts before it and with it.
void thinRuns(std::vector<BirthRun>& runs, std::uint64_t fit) {
  std::uint64_t total = 0;
  for (const BirthRun& r : runs) total += r.count;
  if (total <= fit) return;
  const double scale = double(fit) / double(total);
  std::uint64_t before = 0, keptBefore = 0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    before += runs[k].count;
    const std::uint64_t keptTo =
        k + 1 == runs.size() ? fit : std::min(fit, std::uint64_t(double(before) * scale));
    runs[k].count = keptTo - keptBefore;
    keptBefore = keptTo;
  }
}
}  // namespace

std::size_t fitBirths(GroupImpl& g, std::uint64_t total, std::vector<BirthRun>& runs) {
  std::size_t accepted = std::size_t(std::min<std::uint64_t>(total, g.capacity - g.size));
  g.lastDemand = accepted;  // what a budget's share could be used for (death emitters add)
  g.stats.droppedAtCapacity += total - accepted;
  // Past the group's share of the context's budget (DropOldest makes them all and trims
  // after the step).
  if (g.budgetPolicy != BudgetPolicy::DropOldest && accepted > g.birthAllowance) {
    const std::size_t fit = std::size_t(g.birthAllowance);
    g.stats.droppedAtBudget += accepted - fit;
    if (g.budgetPolicy == BudgetPolicy::ScaleEmission) thinRuns(runs, fit);
    accepted = fit;
  }
  if (g.birthAllowance != ~std::uint64_t(0))
    g.birthAllowance -= std::min<std::uint64_t>(accepted, g.birthAllowance);
  return accepted;
}

void emitNewborns(GroupImpl& g, const StepParams& sp) {
  const double t1 = sp.end;
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
  const std::size_t accepted = fitBirths(g, total, runs);

  // 2. The newborns, in parallel: each one's attributes depend only on its id.
  if (accepted > 0) {
    // Grown geometrically: a step that gives birth to more than any before seldom allocates.
    if (g.bornRemaining.size() < accepted)
      g.bornRemaining.resize(
          std::min<std::size_t>(g.capacity, std::max(accepted, 2 * g.bornRemaining.size())));
    runStart.assign(runs.size() + 1, 0);
    for (std::size_t r = 0; r < runs.size(); ++r) runStart[r + 1] = runStart[r] + runs[r].count;
    writeNewborns(g, sp, runs.data(), runStart.data(), runs.size(), accepted);
    g.nextId += std::uint32_t(accepted);
    g.bornCount = accepted;
    g.size += accepted;
  }

  retireDead(g, t1);
}

namespace {

// An event a DeathEmitter emits from: where, how fast, the particle and the action, and the
// key of its count's random draws. A particle dies once: its id. It may be deflected many
// times: its id, which of its deflections in the step this is (a step's events are in
// particle, sub-step, action order on both backends) and the source's step, all integers, so
// that a device without doubles (its times in float) draws the same counts.
struct Trigger {
  Vec3 position, velocity;
  std::uint32_t id, action, key;
};
Trigger triggerOf(const DeathEvent& d, std::uint32_t, std::uint64_t) {
  return {d.position, d.velocity, d.id, d.action, d.id};
}
Trigger triggerOf(const CollisionEvent& c, std::uint32_t ordinal, std::uint64_t step) {
  std::uint64_t h = (std::uint64_t(c.id) << 32 | ordinal) ^ (step * 0x9E3779B97F4A7C15ull);
  h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull;  // splitmix64's finaliser
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  return {c.position, c.velocity, c.id, c.action, std::uint32_t(h ^ (h >> 32))};
}

template <class Event>
void emitFrom(GroupImpl& g, std::size_t k, std::span<const Event> events, std::uint64_t seed,
              std::uint64_t sourceStep) {
  const DeathEmitter& de = g.deathEmitters[k];
  if (events.empty()) return;
  if (g.mirror) g.mirror->beginAppend(g);  // a device's group: its count, then only the newborns
  g.ensureStorage();
  const Lanes L = g.lanePointers();
  const std::size_t before = g.size;
  std::uint32_t ordinal = 0;
  for (std::size_t e = 0; e < events.size(); ++e) {
    ordinal = e > 0 && events[e].id == events[e - 1].id ? ordinal + 1 : 0;
    const Trigger d = triggerOf(events[e], ordinal, sourceStep);
    // A particle killed for a NaN or an infinity has no place to emit from.
    if (d.action == DeathEvent::kNonFinite) continue;
    if (de.cause >= 0 && d.action != std::uint32_t(de.cause)) continue;
    // How many, keyed by the event, this group and this emitter: two emitters fed by one
    // source draw apart.
    Random counter(seed, d.key, g.streamKey(), stream::kDeathEmitter + std::uint32_t(k));
    const float c = std::min(std::max(de.count.sample(counter), 0.0f), 1e6f);
    std::uint64_t n = std::uint64_t(c);
    if (counter.uniform() < c - float(n)) ++n;
    g.stats.emitted += n;
    const std::uint64_t room = g.capacity - g.size;
    g.lastDemand += std::min(n, room);
    if (n > room) {
      g.stats.droppedAtCapacity += n - room;
      n = room;
    }
    if (g.budgetPolicy != BudgetPolicy::DropOldest && n > g.birthAllowance) {
      g.stats.droppedAtBudget += n - g.birthAllowance;
      n = g.birthAllowance;
    }
    if (g.birthAllowance != ~std::uint64_t(0)) g.birthAllowance -= std::min(n, g.birthAllowance);
    for (std::uint64_t j = 0; j < n; ++j) {
      // A newborn's own stream, as an emitter's newborn has (ids never repeat in a group).
      const std::uint32_t id = g.nextId++;
      Random rng(seed, id, g.streamKey(), stream::kEmission);
      const ParticleType& type = de.types[chooseType(de.types, rng)];
      Particle p;
      p.position = d.position + de.shape.sample(rng);
      p.velocity = type.velocity.sample(rng) + d.velocity * de.inheritVelocity;
      p.prevPosition = p.positionB = p.position;
      p.velocityB = Vec3(0.0f);
      p.age = 0.0f;
      p.id = id;
      // Only the draws of what the group stores, as the emitters' newborns.
      if (L.lifetime) p.lifetime = std::max(type.lifetime.sample(rng), 0.0f);
      if (L.color[0]) p.color = Vec4(type.color.sample(rng), type.alpha.sample(rng));
      if (L.size) p.size = std::max(type.size.sample(rng), 0.0f);
      if (L.mass) p.mass = type.mass.sample(rng);
      if (L.charge) p.charge = type.charge.sample(rng);
      if (L.up[0]) p.up = type.up.sample(rng);
      if (L.rot[0]) p.rotVelocity = type.rotVelocity.sample(rng);
      const std::size_t i = g.size++;
      g.write(i, p);
      for (int c4 = 0; c4 < 4; ++c4)
        if (L.birthColor[c4]) L.birthColor[c4][i] = p.color[c4];
      if (L.birthSize) L.birthSize[i] = p.size;
    }
  }
  g.startTrails(before, g.size);
  if (g.mirror) g.mirror->endAppend(g, before);
  // The step's box, kept by the pass, grows to hold them.
  if (g.boundsValid)
    for (std::size_t i = before; i < g.size; ++i) {
      const Vec3 q(L.p[0][i], L.p[1][i], L.p[2][i]);
      Bounds& b = g.stepBounds;
      b.min = b.empty ? q : glm::min(b.min, q);
      b.max = b.empty ? q : glm::max(b.max, q);
      b.empty = false;
    }
}

}  // namespace

void emitFromDeaths(GroupImpl& g, std::size_t k, const GroupImpl& source, std::uint64_t seed) {
  // (ownSteps: the steps the source took, the same on both backends)
  if (g.deathEmitters[k].on == DeathEmitter::Trigger::Collision)
    emitFrom<CollisionEvent>(g, k, source.collisionEvents, seed, source.ownSteps);
  else if (g.deathEmitters[k].on == DeathEmitter::Trigger::Birth)
    emitFrom<DeathEvent>(g, k, source.birthEvents, seed, source.ownSteps);
  else
    emitFrom<DeathEvent>(g, k, source.deathEvents, seed, source.ownSteps);
}

std::size_t storedLanes(GroupImpl& g, StoredLanes& stored) {
  std::size_t lanes = 0;
  forEachSlot(g.laneCache, g.laneSlots, [&](std::uint32_t* lane) { stored[lanes++] = lane; });
  for (auto& lane : g.trailLanes) stored[lanes++] = lane.u();
  if (g.trailCount) stored[lanes++] = g.trailCount.u();
  return lanes;
}

void compact(GroupImpl& g, const StepParams& sp) {
  g.bornCount = 0;  // the step's newborns are ordinary particles from now on
  // Close the holes with the live particles at the tail: the lowest hole takes the last.
  if (g.holes.empty()) return;
  const std::uint32_t* left = g.holes.data();  // ascending
  const std::size_t leftCount = g.holes.size();
  const std::size_t newSize = g.size - leftCount;
  // Where the act pass stopped filling holes (none filled: from the top).
  const std::size_t filled = std::exchange(g.holesFilled, 0);
  const std::size_t from = filled > 0 ? g.filledFrom : g.size;
  // Holes [filled, filled + count) take the live particles below `from`, highest first.
  const std::size_t count =
      std::size_t(std::lower_bound(left + filled, left + leftCount, newSize) - (left + filled));
  g.size = newSize;
  if (count == 0) return;
  // Move j takes fillers[j] into holes[j].
  thread_local std::vector<std::uint32_t> fillersStore;
  auto& fillers = fillersStore;
  // As many as the holes may ever be (their capacity only grows): a step that leaves more
  // holes than any before does not allocate.
  if (fillers.size() < count) fillers.resize(std::max(count, g.holes.capacity()));
  const std::uint32_t* holes = left + filled;
  StoredLanes stored;
  const std::size_t lanes = storedLanes(g, stored);
  // Moves [a, b): the live particles below `src` (the one move a - 1 took, or `from`) go to
  // holes a on, each lane in turn.
  auto fill = [&](std::size_t a, std::size_t b, std::size_t src) {
    // Holes at or above src are left[back..].
    std::size_t back = std::size_t(std::lower_bound(left, left + leftCount, src) - left);
    for (std::size_t j = a; j < b; ++j) {
      do {
        --src;
      } while (back > 0 && left[back - 1] == src && (--back, true));
      fillers[j] = std::uint32_t(src);
    }
    for (std::size_t l = 0; l < lanes; ++l) {
      std::uint32_t* __restrict lane = stored[l];
      for (std::size_t j = a; j < b; ++j) lane[holes[j]] = lane[fillers[j]];
    }
  };
  // A few moves (a small group, or a near-steady one) cost less than waking a worker.
  if (count * lanes <= kInlineMoves || sp.pool->size() == 1) {
    fill(0, count, from);
    return;
  }
  // In parallel: a piece of the moves starts below the j-th live particle under `from`,
  // found by bisection (the live in [x, from) are those not among the holes there).
  const auto holesBelowFrom = std::size_t(std::lower_bound(left, left + leftCount, from) - left);
  auto liveAbove = [&](std::size_t x) {
    return (from - x) -
           (holesBelowFrom - std::size_t(std::lower_bound(left, left + leftCount, x) - left));
  };
  auto below = [&](std::size_t j) {  // the j-th live particle under from (j = 0: from)
    if (j == 0) return from;
    std::size_t lo = newSize, hi = from;  // the largest x with liveAbove(x) >= j
    while (hi - lo > 1) {
      const std::size_t mid = lo + (hi - lo) / 2;
      (liveAbove(mid) >= j ? lo : hi) = mid;
    }
    return lo;
  };
  constexpr std::size_t kPerTask = 8192;
  const std::size_t tasks = (count + kPerTask - 1) / kPerTask;
  sp.pool->parallelFor(tasks, [&](std::size_t t) {
    const std::size_t a = t * kPerTask;
    fill(a, std::min(count, a + kPerTask), below(a));
  });
}

}  // namespace flurry::detail
