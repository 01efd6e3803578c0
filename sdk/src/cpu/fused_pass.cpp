// The CPU backend's act phase: the whole action list as one fused pass over the group.
//
// Actions are built at run time (effect files), so the pass cannot be one compiled loop per
// list. Instead it is blocked: every action runs over a block of particles small enough to
// stay in cache, so each particle is read from and written to memory once per step however
// many actions there are, and each action's loop is vectorised on its own.
#include <algorithm>
#include <vector>

#include "../backend.hpp"
#include "actions_more.hpp"
#include "kernels.hpp"

#ifndef FLURRY_ISA
#define FLURRY_ISA baseline
#endif

namespace flurry::detail::FLURRY_ISA {

namespace {

constexpr std::size_t kDefaultBlock = 1024;
constexpr std::size_t kParticlesPerTask = 32768;  // below this a group is stepped inline

void runActions(const std::vector<Action>& acts, std::size_t first, std::size_t last,
                const Lanes& lanes, std::size_t n, cpu::BlockContext ctx) {
  for (std::size_t k = first; k < last; ++k) {
    ctx.action = std::uint32_t(k);
    std::visit([&](const auto& a) { cpu::apply(a, lanes, n, ctx); }, acts[k]);
  }
}

// Records a block's dead (ascending) in the block's own slice of deadIndex.
std::uint32_t collectDead(GroupImpl& g, std::size_t base, std::size_t n,
                          const std::uint32_t* dead) {
  std::uint32_t count = 0;
  std::uint32_t* idx = g.deadIndex.data() + base;
  std::uint8_t* code = g.deadCode.data() + base;
  for (std::size_t i = 0; i < n; ++i) {
    if (dead[i] == 0u) continue;
    idx[count] = std::uint32_t(base + i);
    code[count] = std::uint8_t(dead[i]);
    ++count;
  }
  return count;
}

}  // namespace

void actFusedImpl(GroupImpl& g, const StepParams& sp) {
  g.holes.clear();
  const std::size_t n = g.size;
  const auto& acts = g.actions.actions();
  if (n == 0 || acts.empty()) return;

  const std::size_t B = sp.blockSize ? sp.blockSize : kDefaultBlock;
  const std::size_t blocks = (n + B - 1) / B;
  const std::size_t blocksPerTask = std::max<std::size_t>(1, kParticlesPerTask / B);
  const std::size_t tasks = (blocks + blocksPerTask - 1) / blocksPerTask;
  const bool kills = g.actions.kills();
  if (kills) {
    g.deadIndex.resize(n);
    g.deadCode.resize(n);
    g.deadCount.assign(blocks, 0);
  }
  const Lanes lanes = g.lanePointers();
  cpu::BlockContext base{float(sp.dt), sp.seed, std::uint32_t(sp.step), g.index << 16, 0, nullptr};
  base.time = sp.time;
  for (std::size_t k = 0; k < acts.size(); ++k)
    if (std::holds_alternative<Block>(acts[k])) {
      base.firstBlocker = std::uint32_t(k);
      break;
    }
  // Actions that read other particles read them as they were at the start of the step, so
  // the result does not depend on which block ran first.
  cpu::Snapshot snapshot;
  if (g.actions.readsNeighbours()) {
    g.snapshot.resize(9 * n);
    float* out = g.snapshot.data();
    auto keep = [&](float* const* src, const float** dst) {
      for (int d = 0; d < 3; ++d, out += n) {
        if (!src[d]) continue;
        std::copy_n(src[d], n, out);
        dst[d] = out;
      }
    };
    keep(lanes.p, snapshot.p);
    keep(lanes.v, snapshot.v);
    keep(lanes.rot, snapshot.rot);
    snapshot.size = n;
    base.snapshot = &snapshot;
  }

  if (sp.fused) {
    sp.pool->parallelFor(tasks, [&](std::size_t t) {
      thread_local std::vector<std::uint32_t> deadStore;
      std::vector<std::uint32_t>& dead = deadStore;  // one TLS lookup, not one per use
      if (kills && dead.size() < B) dead.resize(B);
      const std::size_t end = std::min(blocks, (t + 1) * blocksPerTask);
      for (std::size_t b = t * blocksPerTask; b < end; ++b) {
        const std::size_t first = b * B, m = std::min(B, n - first);
        cpu::BlockContext ctx = base;
        ctx.base = first;
        if (kills) {
          std::fill_n(dead.data(), m, 0u);
          ctx.dead = dead.data();
        }
        runActions(acts, 0, acts.size(), lanes.offset(first), m, ctx);
        if (kills) g.deadCount[b] = collectDead(g, first, m, dead.data());
      }
    });
  } else {
    // The unfused baseline: one parallel pass over the whole group per action.
    if (kills) g.deadFlags.assign(n, 0u);
    for (std::size_t k = 0; k < acts.size(); ++k) {
      sp.pool->parallelFor(tasks, [&](std::size_t t) {
        const std::size_t end = std::min(blocks, (t + 1) * blocksPerTask);
        for (std::size_t b = t * blocksPerTask; b < end; ++b) {
          const std::size_t first = b * B, m = std::min(B, n - first);
          cpu::BlockContext ctx = base;
          ctx.base = first;
          if (kills) ctx.dead = g.deadFlags.data() + first;
          runActions(acts, k, k + 1, lanes.offset(first), m, ctx);
        }
      });
    }
    if (kills) {
      sp.pool->parallelFor(blocks, [&](std::size_t b) {
        const std::size_t first = b * B, m = std::min(B, n - first);
        g.deadCount[b] = collectDead(g, first, m, g.deadFlags.data() + first);
      });
    }
  }

  if (!kills) return;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t* idx = g.deadIndex.data() + b * B;
    const std::uint8_t* code = g.deadCode.data() + b * B;
    for (std::uint32_t j = 0; j < g.deadCount[b]; ++j) {
      g.holes.push_back(idx[j]);
      const std::size_t k = code[j] - 1u;
      ++g.stats.killedByAction[k];
      if (std::holds_alternative<KillOld>(acts[k]))
        ++g.stats.killedByAge;
      else
        ++g.stats.absorbed;
    }
  }
}

}  // namespace flurry::detail::FLURRY_ISA
