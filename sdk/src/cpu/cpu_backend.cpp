#include <algorithm>
#include <bit>
#include <cmath>
#include <utility>
#include <vector>

#include "../action_params.hpp"
#include "../action_traits.hpp"
#include "../backend.hpp"
#include "../tick_clock.hpp"
#include "actions_more.hpp"  // (defines what kernels.hpp declares)

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
// Whether an action reads the time itself, not only the step's length.
bool readsTime(const Action& act) {
  if (const auto* t = std::get_if<Turbulence>(&act)) return t->drift != Vec3(0.0f);
  return std::holds_alternative<Explosion>(act) || std::holds_alternative<Restore>(act) ||
         std::holds_alternative<Callback>(act);
}

// Whether action k runs over a batch of newborns, each with its own step length
// (BlockContext::ownDt), in one call like a block. What reads the time itself runs per
// newborn instead, at its own time: an action, or the forces an integrating Move (or a
// bounce on its curved path) evaluates at its stages.
bool takesOwnDt(const std::vector<Action>& acts, const ActionPlan& list, std::size_t k) {
  const auto forcesReadTime = [&](std::size_t move) {
    for (std::uint32_t f : list.forcesOf[move])
      if (readsTime(acts[f])) return true;
    return false;
  };
  if (list.curvedBy[k]) return !forcesReadTime(list.curvedBy[k] - 1);
  if (std::holds_alternative<Move>(acts[k]))
    return list.integrator == Integrator::SemiImplicitEuler || !forcesReadTime(k);
  return !readsTime(acts[k]);
}

// Whether the action's block form takes a factor (an exp) once for the block's step, which
// its own-step form takes per particle: run over a whole block with own step lengths, it
// would cost more than the newborns' runs of their own.
bool factorPerStep(const Action& a) {
  return std::holds_alternative<Damping>(a) || std::holds_alternative<RotDamping>(a) ||
         std::holds_alternative<Vortex>(a) || std::holds_alternative<MatchVelocity>(a) ||
         std::holds_alternative<MatchRotVelocity>(a) || std::holds_alternative<TargetVelocity>(a) ||
         std::holds_alternative<TargetRotVelocity>(a) || std::holds_alternative<TargetColor>(a) ||
         std::holds_alternative<TargetSize>(a);
}

// The axis-aligned box a shape lies in; false for unbounded shapes (plane) and for those
// whose tests are not confined to their bounds exactly enough to rely on (mesh, union).
bool shapeBox(const Domain& d, Vec3& lo, Vec3& hi) {
  const auto& s = d.shape();
  auto points = [&](std::initializer_list<Vec3> ps, float r) {
    lo = Vec3(kInfinity);
    hi = Vec3(-kInfinity);
    for (const Vec3& p : ps) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    lo -= Vec3(r);
    hi += Vec3(r);
    return true;
  };
  if (const auto* x = std::get_if<PointDomain>(&s)) return points({x->p}, 0.0f);
  if (const auto* x = std::get_if<LineDomain>(&s)) return points({x->p0, x->p1}, 0.0f);
  if (const auto* x = std::get_if<TriangleDomain>(&s)) return points({x->p0, x->p1, x->p2}, 0.0f);
  if (const auto* x = std::get_if<RectangleDomain>(&s))
    return points({x->origin, x->origin + x->u, x->origin + x->v, x->origin + x->u + x->v}, 0.0f);
  if (const auto* x = std::get_if<DiscDomain>(&s)) return points({x->center}, x->outerRadius);
  if (const auto* x = std::get_if<BoxDomain>(&s)) return points({x->min, x->max}, 0.0f);
  if (const auto* x = std::get_if<SphereDomain>(&s)) return points({x->center}, x->outerRadius);
  if (const auto* x = std::get_if<CylinderDomain>(&s))
    return points({x->p0, x->p1}, x->outerRadius);
  if (const auto* x = std::get_if<ConeDomain>(&s))
    return points({x->apex, x->base}, x->outerRadius);
  if (const auto* x = std::get_if<BlobDomain>(&s)) return points({x->center}, x->stddev);
  return false;
}

bool finiteFalloff(const Falloff& f) {
  return f.radius > 0.0f && f.radius < kInfinity && f.power > 0.0f;
}

// Where action k can change a particle, as a box: a particle whose path over the step (its
// straight segment p .. p + v·dt) stays out of it, by the rounding margin, is left bitwise
// as it was (each case below was checked against its loop in kernels.hpp and
// actions_more.hpp). Actions that act everywhere, or whose untouched particles are not
// bitwise untouched, have none.
ActionPlan::Reach actionReach(const Action& a, const ActionPlan& plan, std::size_t k) {
  ActionPlan::Reach r;
  Vec3 lo, hi;
  bool box = false;
  if (const auto* b = std::get_if<Bounce>(&a)) {
    // Pieces and closed shapes; not a box keeping particles in (it acts on those outside),
    // nor one bounced on the curved path (its reach grows with the acceleration).
    const auto& s = b->surface.shape();
    const bool piece = std::holds_alternative<RectangleDomain>(s) ||
                       std::holds_alternative<TriangleDomain>(s) ||
                       std::holds_alternative<DiscDomain>(s);
    const bool sphere = std::holds_alternative<SphereDomain>(s);
    const bool outerBox = std::holds_alternative<BoxDomain>(s) && !b->inside;
    if (!plan.curvedBy[k] && (piece || sphere || outerBox)) box = shapeBox(b->surface, lo, hi);
    // A grazing path's root is found to about sqrt(eps)·|p - c|: the margin grows as
    // scale²/R, not with the scale alone.
    if (sphere && box)
      r.quadratic = 1e-6f / std::max(std::get<SphereDomain>(s).outerRadius, 1e-30f);
  } else if (const auto* s = std::get_if<Sink>(&a)) {
    if (s->mode != Sink::Mode::Outside) box = shapeBox(s->region, lo, hi);
  } else if (const auto* b = std::get_if<Block>(&a)) {
    box = shapeBox(b->region, lo, hi);  // the first blocker's reset is done when culled
  } else if (const auto* g = std::get_if<Gravity>(&a)) {
    // Outside the radius the weight is +0: v + a·(dt·0) (run when culled, for -0's sake).
    if (finiteFalloff(g->falloff)) {
      box = true;
      lo = g->falloff.center - Vec3(g->falloff.radius);
      hi = g->falloff.center + Vec3(g->falloff.radius);
    }
  } else if (const auto* d = std::get_if<Damping>(&a)) {
    // Outside the radius v·exp(±0) = v, while rate·dt is finite.
    const Vec3 rate = d->rate;
    const bool finite = std::max({std::abs(rate.x), std::abs(rate.y), std::abs(rate.z)}) < 1e30f;
    if (finiteFalloff(d->falloff) && finite) {
      box = true;
      lo = d->falloff.center - Vec3(d->falloff.radius);
      hi = d->falloff.center + Vec3(d->falloff.radius);
    }
  }
  if (!box) return r;
  float scale = 0.0f;
  for (int c = 0; c < 3; ++c) {
    r.lo[c] = lo[c];
    r.hi[c] = hi[c];
    scale = std::max({scale, std::abs(lo[c]), std::abs(hi[c])});
  }
  r.scale = scale;
  r.cullable = std::isfinite(scale);
  return r;
}

}  // namespace

namespace {
void planStructure(GroupImpl& g, ActionPlan& plan);
}  // namespace

// Here, in a baseline translation unit, and not in the fused pass: the pass is compiled once
// per instruction set, and the vector code it would instantiate here is shared between the
// builds (the SSE2 build would then run the AVX2 copy).
const ActionPlan& planActions(GroupImpl& g) {
  ActionPlan& plan = g.plan;
  if (plan.version == g.actionsVersion) return plan;
  const auto& acts = g.actions.actions();
  // What follows from the kinds of the actions and their order alone, which a move keeps
  // (GroupImpl::actionsStructure): a moved instance takes only the reach of its actions
  // again, every step it moves.
  if (plan.structure != g.actionsStructure || plan.gathered.size() != acts.size())
    planStructure(g, plan);
  plan.reach.assign(acts.size(), {});
  plan.cullable = false;
  for (std::size_t k = 0; k < acts.size(); ++k) {
    plan.reach[k] = actionReach(acts[k], plan, k);
    plan.cullable |= plan.reach[k].cullable;
  }
  plan.version = g.actionsVersion;
  return plan;
}

namespace {
void planStructure(GroupImpl& g, ActionPlan& plan) {
  const auto& acts = g.actions.actions();
  plan.integrator = g.actions.integrator();
  planMoves(g.actions, plan.gathered, plan.forcesOf, plan.guardsOf, plan.curvedBy);
  plan.timeFree.assign(acts.size(), 0);
  for (std::size_t k = 0; k < acts.size(); ++k) plan.timeFree[k] = isTimeFree(acts[k]);
  plan.guarded = false;
  for (const auto& gs : plan.guardsOf) plan.guarded |= !gs.empty();
  {
    std::size_t lastMove = acts.size(), lastChange = acts.size();
    for (std::size_t k = 0; k < acts.size(); ++k) {
      if (std::holds_alternative<Move>(acts[k]))
        lastMove = k;
      else if (movesParticles(acts[k]))
        lastChange = k;
    }
    plan.guardVelocity = plan.integrator != Integrator::SemiImplicitEuler ||
                         lastMove == acts.size() ||
                         (lastChange != acts.size() && lastChange > lastMove);
  }
  plan.ownDt.assign(acts.size(), 0);
  plan.newbornsWithBlock = true;
  for (std::size_t k = 0; k < acts.size(); ++k) {
    plan.ownDt[k] = takesOwnDt(acts, plan, k);
    plan.newbornsWithBlock &=
        !factorPerStep(acts[k]) && (plan.gathered[k] || plan.timeFree[k] || plan.ownDt[k]);
  }
  plan.readsNeighbours = g.actions.readsNeighbours();
  plan.firstBlocker = ~0u;
  for (std::size_t k = 0; k < acts.size(); ++k)
    if (std::holds_alternative<Block>(acts[k])) {
      plan.firstBlocker = std::uint32_t(k);
      break;
    }
  plan.moves.assign(acts.size(), 0);
  for (std::size_t k = 0; k < acts.size(); ++k) plan.moves[k] = movesParticles(acts[k]);
  plan.structure = g.actionsStructure;
}
}  // namespace

const cl::FlActionParams* actionRecords(GroupImpl& g, float dt) {
  ActionPlan& plan = g.plan;
  const auto& acts = g.actions.actions();
  if (plan.recordsVersion != g.actionsVersion || plan.records.size() != acts.size() ||
      std::bit_cast<std::uint32_t>(plan.recordsDt) != std::bit_cast<std::uint32_t>(dt)) {
    plan.records.resize(acts.size());  // resized, not replaced: a moved instance's each step
    for (std::size_t k = 0; k < acts.size(); ++k) plan.records[k] = actionParams(acts[k], dt);
    plan.recordsVersion = g.actionsVersion;
    plan.recordsDt = dt;
  }
  return plan.records.data();
}

namespace {
// Adds the time since `last` to a part of the step (GroupStats::stepSeconds, its total and
// this step's), and moves `last` on.
void lap(std::uint64_t& last, double& total, double& thisStep) {
  const std::uint64_t now = ticksNow();
  thisStep = ticksToSeconds(now - last);
  total += thisStep;
  last = now;
}

class CpuBackend final : public BackendImpl {
 public:
  const char* name() const override { return "cpu"; }
  void step(GroupImpl& group, const StepParams& params) override {
    if (stepFirstPart(group, params)) stepSecondPart(group, params);
  }

  // The newborns first: Context::step runs a few groups' emission, then their act passes and
  // compaction. A game's many small groups then run each phase's code while it is in the
  // instruction cache, and a group's lanes, asked for before its emission, are in the data
  // cache when its pass comes. False when the group is idle (nothing alive and no emitter
  // that will fire): such a step would change nothing (its emitters' state included), so it
  // costs no pass, no clock and no worker.
  bool stepFirstPart(GroupImpl& group, const StepParams& params) override {
    group.lastStepParts = {};
    if (group.size == 0 && !group.hair.enabled && !mayEmit(group, params)) {
      // What a step's planning would have done: count generation 0 (see planBirths).
      if (!group.emitters.empty() && group.stats.emittedByGeneration.empty())
        group.stats.emittedByGeneration.assign(1, 0);
      ++group.stats.idleSteps;
      return false;
    }
    // Each part's time, for GroupStats::stepSeconds (tick_clock.hpp: a cheap clock).
    std::uint64_t last = ticksNow();
    emitNewborns(group, params);
    // A newborn's trail starts where it was born, inside the step.
    if (group.bornCount > 0) group.startTrails(group.bornFirst, group.bornFirst + group.bornCount);
    if (group.birthsFeed) group.recordBirths(params.end);
    lap(last, group.stats.stepSeconds.emit, group.lastStepParts.emit);
    // The rest of a later group's data, asked for here rather than with the first part
    // before this step (StepParams::ahead).
    if (params.ahead) params.ahead->prefetchData(1, 2);
    return true;
  }

  // The act pass, then the dead removed, the budget kept, the trails turned, the strands of
  // hair mode. (The time between the parts counts to neither.)
  void stepSecondPart(GroupImpl& group, const StepParams& params) override {
    std::uint64_t last = ticksNow();
    actFused(group, params);
    lap(last, group.stats.stepSeconds.act, group.lastStepParts.act);
    compact(group, params);
    if (group.size > group.keepAtMost) group.dropOldest(group.size - group.keepAtMost, params);
    group.recordTrails(*params.pool);
    lap(last, group.stats.stepSeconds.compact, group.lastStepParts.compact);
    if (group.hair.enabled) simulateHair(group, params);
  }
};
}  // namespace

std::unique_ptr<BackendImpl> makeCpuBackend() {
  return std::make_unique<CpuBackend>();
}

}  // namespace flurry::detail
