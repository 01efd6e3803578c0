#include <chrono>
#include <utility>
#include <vector>

#include "../action_traits.hpp"
#include "../backend.hpp"
#include "kernels.hpp"

namespace flurry::detail {

namespace {
bool isTimeFree(const Action& a) {
  if (const auto* sink = std::get_if<Sink>(&a))
    return sink->mode == Sink::Mode::Inside || sink->mode == Sink::Mode::Outside;
  return std::holds_alternative<SinkVelocity>(a) || std::holds_alternative<Block>(a) ||
         std::holds_alternative<KillOld>(a) || std::holds_alternative<RandomVelocity>(a) ||
         std::holds_alternative<RandomRotVelocity>(a) || std::holds_alternative<SpeedClamp>(a) ||
         std::holds_alternative<ColorOverLife>(a) || std::holds_alternative<SizeOverLife>(a) ||
         std::holds_alternative<Constrain2D>(a) || std::holds_alternative<CopyVertexB>(a);
}
}  // namespace

// Here, in a baseline translation unit, and not in the fused pass: the pass is compiled once
// per instruction set, and the vector code it would instantiate here is shared between the
// builds (the SSE2 build would then run the AVX2 copy).
const ActionPlan& planActions(GroupImpl& g) {
  ActionPlan& plan = g.plan;
  if (plan.version == g.actionsVersion) return plan;
  const auto& acts = g.actions.actions();
  plan.integrator = g.actions.integrator();
  plan.gathered.assign(acts.size(), 0);
  plan.forcesOf.assign(acts.size(), {});
  plan.guardsOf.assign(acts.size(), {});
  plan.curvedBy.assign(acts.size(), 0);
  plan.timeFree.assign(acts.size(), 0);
  for (std::size_t k = 0; k < acts.size(); ++k) plan.timeFree[k] = isTimeFree(acts[k]);
  // Explicit Euler moves on the straight line p + v·dt: the plain bounce is its own path.
  const bool curved = plan.integrator == Integrator::Exact ||
                      plan.integrator == Integrator::VelocityVerlet ||
                      plan.integrator == Integrator::RK4;
  if (plan.integrator != Integrator::SemiImplicitEuler) {
    std::vector<std::uint32_t> pending, bounces;
    for (std::uint32_t k = 0; k < acts.size(); ++k) {
      if (isForce(acts[k])) pending.push_back(k);
      if (std::holds_alternative<Bounce>(acts[k])) bounces.push_back(k);
      if (std::holds_alternative<Move>(acts[k])) {
        for (std::uint32_t f : pending) plan.gathered[f] = 1;
        for (std::uint32_t b : bounces)
          if (curved && !pending.empty() && cpu::isPlanarBounce(std::get<Bounce>(acts[b])))
            plan.curvedBy[b] = k + 1;
        plan.forcesOf[k] = std::move(pending);
        plan.guardsOf[k] = std::move(bounces);
        pending.clear();
        bounces.clear();
      }
    }
  }
  plan.guarded = false;
  for (const auto& gs : plan.guardsOf) plan.guarded |= !gs.empty();
  plan.readsNeighbours = g.actions.readsNeighbours();
  plan.firstBlocker = ~0u;
  for (std::size_t k = 0; k < acts.size(); ++k)
    if (std::holds_alternative<Block>(acts[k])) {
      plan.firstBlocker = std::uint32_t(k);
      break;
    }
  plan.version = g.actionsVersion;
  return plan;
}

namespace {
class CpuBackend final : public BackendImpl {
 public:
  const char* name() const override { return "cpu"; }
  void step(GroupImpl& group, const StepParams& params) override {
    // Idle: nothing alive and no emitter that will fire. Such a step would change nothing
    // (its emitters' state included), so it costs no pass, no clock and no worker.
    if (group.size == 0 && !group.hair.enabled && !mayEmit(group, params)) {
      // What a step's planning would have done: count generation 0 (see planBirths).
      if (!group.emitters.empty() && group.stats.emittedByGeneration.empty())
        group.stats.emittedByGeneration.assign(1, 0);
      ++group.stats.idleSteps;
      return;
    }
    // Each part's time, for GroupStats::stepSeconds.
    using Clock = std::chrono::steady_clock;
    auto last = Clock::now();
    auto lap = [&](double& total) {
      const auto now = Clock::now();
      total += std::chrono::duration<double>(now - last).count();
      last = now;
    };
    emitNewborns(group, params);
    lap(group.stats.stepSeconds.emit);
    actFused(group, params);
    lap(group.stats.stepSeconds.act);
    compact(group, params);
    lap(group.stats.stepSeconds.compact);
    if (group.hair.enabled) simulateHair(group, params);
  }
};
}  // namespace

std::unique_ptr<BackendImpl> makeCpuBackend() {
  return std::make_unique<CpuBackend>();
}

}  // namespace flurry::detail
