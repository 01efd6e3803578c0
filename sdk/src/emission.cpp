// Emission and compaction, after the act pass (the seed's order: update, delete, produce).
//
// Newborns go first into the slots of this step's dead, then at the end; only when more
// died than were born are the remaining holes filled from the tail. In a steady effect
// births and deaths balance, so compaction moves almost nothing.
#include <algorithm>
#include <cmath>

#include "backend.hpp"

namespace flurry::detail {

namespace {

// One run of births of one emitter: by rate (birth times first/rate apart) or a burst.
struct BirthRun {
  std::uint32_t emitter;
  bool burst;
  std::uint64_t first;  // rate: index of the first birth since the emitter's start
  double burstTime;
  std::uint64_t count;
};

constexpr std::size_t kNewbornsPerTask = 8192;

// Particles a rate has produced by time t: floor(rate·elapsed), with a relative guard so
// that 10.5/s over 10 s gives 105 despite the rounding of the accumulated time.
std::uint64_t producedBy(const Emitter& e, double t) {
  const double elapsed = std::min(t, e.stop) - e.start;
  if (elapsed <= 0) return 0;
  const double x = e.rate * elapsed;
  return std::uint64_t(std::floor(x + 1e-9 * std::max(1.0, x)));
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

}  // namespace

void emitAndCompact(GroupImpl& g, const StepParams& sp) {
  const double t0 = sp.time, t1 = sp.time + sp.dt;

  // 1. How many are born, by which emitter, when.
  // Scratch kept between steps; named through references because the worker threads below
  // must see this thread's vectors, not their own thread_local ones.
  thread_local std::vector<BirthRun> runsStore;
  thread_local std::vector<std::uint64_t> runStartStore;
  auto& runs = runsStore;
  auto& runStart = runStartStore;
  runs.clear();
  std::uint64_t total = 0;
  for (std::uint32_t e = 0; e < g.emitters.size(); ++e) {
    const Emitter& em = g.emitters[e];
    auto& state = g.emitterState[e];
    if (em.rate > 0) {
      const std::uint64_t target = producedBy(em, t1);
      if (target > state.emittedByRate) {
        runs.push_back({e, false, state.emittedByRate, 0.0, target - state.emittedByRate});
        total += target - state.emittedByRate;
        state.emittedByRate = target;
      }
    }
    for (const Burst& b : em.bursts) {
      for (std::uint32_t r = 0; r < b.repeat; ++r) {
        const double tb = b.time + r * b.interval;
        if (tb >= t0 && tb < t1 && b.count > 0) {
          runs.push_back({e, true, 0, tb, b.count});
          total += b.count;
        }
      }
    }
  }

  g.stats.emitted += total;
  const std::size_t holes = g.holes.size();
  const std::size_t live = g.size - holes;
  const std::size_t accepted = std::size_t(std::min<std::uint64_t>(total, g.capacity - live));
  g.stats.droppedAtCapacity += total - accepted;

  // 2. The newborns, in parallel: each one's attributes depend only on its id.
  if (accepted > 0) {
    runStart.assign(runs.size() + 1, 0);
    for (std::size_t r = 0; r < runs.size(); ++r) runStart[r + 1] = runStart[r] + runs[r].count;
    const Lanes L = g.lanePointers();
    const std::uint32_t firstId = g.nextId;
    const std::size_t oldSize = g.size;
    const std::uint32_t* holeIdx = g.holes.data();
    const std::uint32_t salt = g.index;
    const std::size_t tasks = (accepted + kNewbornsPerTask - 1) / kNewbornsPerTask;
    sp.pool->parallelFor(tasks, [&](std::size_t task) {
      const std::size_t a = task * kNewbornsPerTask;
      const std::size_t b = std::min(accepted, a + kNewbornsPerTask);
      std::size_t r = std::size_t(std::upper_bound(runStart.begin(), runStart.end(), a) -
                                  runStart.begin()) - 1;
      for (std::size_t i = a; i < b; ++i) {
        while (i >= runStart[r + 1]) ++r;
        const BirthRun& run = runs[r];
        const Emitter& em = g.emitters[run.emitter];
        const std::uint64_t q = i - runStart[r];
        const double tb = run.burst ? run.burstTime : em.start + double(run.first + q + 1) / em.rate;
        const std::uint32_t id = firstId + std::uint32_t(i);
        const std::size_t slot = i < holes ? holeIdx[i] : oldSize + (i - holes);

        Random rng(sp.seed, id, salt, stream::kEmission);
        const ParticleType& type = em.types[chooseType(em, rng)];
        const float age = float(std::max(0.0, t1 - tb));
        const Vec3 vel = type.velocity.sample(rng);
        // Born at tb where the emitter was then, and carried on for the rest of the step.
        const Vec3 pos = em.shape.sample(rng) + em.positionAt(tb) + vel * age;
        for (int c = 0; c < 3; ++c) {
          L.p[c][slot] = pos[c];
          if (L.v[c]) L.v[c][slot] = vel[c];
          if (L.prev[c]) L.prev[c][slot] = pos[c];
        }
        if (L.lifetime) L.lifetime[slot] = std::max(type.lifetime.sample(rng), 0.0f);
        if (L.color[0]) {
          const Vec3 rgb = type.color.sample(rng);
          for (int c = 0; c < 3; ++c) L.color[c][slot] = rgb[c];
          L.color[3][slot] = type.alpha.sample(rng);
        }
        if (L.size) L.size[slot] = std::max(type.size.sample(rng), 0.0f);
        if (L.mass) L.mass[slot] = type.mass.sample(rng);
        if (L.charge) L.charge[slot] = type.charge.sample(rng);
        if (L.up[0]) {
          const Vec3 up = type.up.sample(rng);
          for (int c = 0; c < 3; ++c) L.up[c][slot] = up[c];
        }
        if (L.rot[0]) {
          const Vec3 w = type.rotVelocity.sample(rng);
          for (int c = 0; c < 3; ++c) L.rot[c][slot] = w[c];
        }
        if (L.age) L.age[slot] = age;
        L.id[slot] = id;
        if (L.visible) L.visible[slot] = 1u;
        if (L.user) L.user[slot] = 0.0f;
      }
    });
    g.nextId += std::uint32_t(accepted);
  }

  // 3. Close the holes no newborn filled, with the live particles at the tail.
  if (accepted >= holes) {
    g.size += accepted - holes;
    return;
  }
  const std::uint32_t* left = g.holes.data() + accepted;  // ascending
  const std::size_t leftCount = holes - accepted;
  const std::size_t newSize = g.size - leftCount;
  thread_local std::vector<std::pair<std::uint32_t, std::uint32_t>> movesStore;
  auto& moves = movesStore;  // (from, to)
  moves.clear();
  std::size_t src = g.size;       // candidates below this
  std::size_t back = leftCount;   // holes at or above src are left[back..]
  for (std::size_t h = 0; h < leftCount && left[h] < newSize; ++h) {
    do {
      --src;
    } while (back > 0 && left[back - 1] == src && (--back, true));
    moves.emplace_back(std::uint32_t(src), left[h]);
  }
  g.size = newSize;
  if (moves.empty()) return;
  std::vector<LaneBuffer*> stored;
  for (auto& attr : g.lanes)
    for (auto& lane : attr)
      if (lane) stored.push_back(&lane);
  const std::size_t perTask = 65536;
  const std::size_t chunks = (moves.size() + perTask - 1) / perTask;
  sp.pool->parallelFor(stored.size() * chunks, [&](std::size_t t) {
    std::uint32_t* lane = stored[t / chunks]->u();
    const std::size_t a = (t % chunks) * perTask, b = std::min(moves.size(), a + perTask);
    for (std::size_t k = a; k < b; ++k) lane[moves[k].second] = lane[moves[k].first];
  });
}

}  // namespace flurry::detail
