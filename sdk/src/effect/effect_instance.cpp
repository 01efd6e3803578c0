// An effect built into a Context: Effect::build and instantiate, and EffectInstance, the
// handle a game places, moves, stops and restarts. (The loader is effect.cpp.)
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "backend.hpp"
#include "effect/effect_parts.hpp"
#include "flurry/effect.hpp"
#include "group_impl.hpp"

namespace flurry {

using detail::index;

namespace {
std::uint32_t scaledCount(std::uint32_t n, double f) {
  if (n == 0) return 0;
  return std::uint32_t(std::clamp(std::round(double(n) * f), 1.0, 4294967295.0));
}
void scaleEmitter(Emitter& e, double f) {
  e.rate *= f;
  if (e.spacing > 0.0f) e.spacing = float(double(e.spacing) / f);
  for (Burst& b : e.bursts) b.count = scaledCount(b.count, f);
}
void scaleSpec(EmitterSpec& spec, double f, int depth) {
  if (depth > 1000) throw InvalidArgument("child.next", "more than 1000 levels: a cycle");
  scaleEmitter(spec.emitter, f);
  spec.deathBurst = scaledCount(spec.deathBurst, f);
  if (spec.next) {
    auto next = std::make_shared<EmitterSpec>(*spec.next);  // shared with other copies
    scaleSpec(*next, f, depth + 1);
    spec.next = std::move(next);
  }
}
}  // namespace

void Effect::scaleSpawning(double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor))
    throw InvalidArgument("factor", "must be finite and > 0");
  for (EffectGroup& g : groups) {
    g.capacity = std::size_t(
        std::clamp(std::round(double(g.capacity) * factor), 1.0, double(std::uint32_t(~0u))));
    for (Emitter& e : g.emitters) scaleEmitter(e, factor);
    for (PrimeEmitter& p : g.primeEmitters) scaleSpec(p.child, factor, 0);
  }
}

ContextOptions Effect::contextOptions() const {
  ContextOptions o;
  o.seed = seed;
  o.dt = dt;
  return o;
}

namespace {
// An effect's times count from its start: one built at t0 on the context's clock has them
// moved by t0 (its emitters' start, stop, bursts and path keys; Explosion's time, Restore's
// start), so that an effect built mid-game bursts, emits and explodes as one built at time
// 0 does. A spawned emitter's times count from its own birth and stay as they are.
template <class E>
void delayTimes(E& e, double t0) {
  e.start += t0;
  e.stop += t0;  // infinity stays infinity
  for (Burst& b : e.bursts) b.time += t0;
  for (Keyframe& k : e.path) k.time += t0;
}
ActionList delayedActions(const ActionList& list, double t0) {
  ActionList out;
  out.setIntegrator(list.integrator());
  out.setSubsteps(list.substeps());
  for (Action a : list.actions()) {
    if (auto* x = std::get_if<Explosion>(&a)) x->time = float(double(x->time) + t0);
    if (auto* r = std::get_if<Restore>(&a)) r->start = float(double(r->start) + t0);
    out.add(std::move(a));
  }
  return out;
}
}  // namespace

std::vector<Group*> Effect::build(Context& ctx, std::size_t maxCapacity,
                                  std::string_view instance) const {
  const std::string where = file.empty() ? name : file.string();
  const double t0 = ctx.time();
  std::vector<Group*> made;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const EffectGroup& eg = groups[i];
    const std::string path = index("groups", i);
    try {
      const std::size_t cap = maxCapacity > 0 ? std::min(eg.capacity, maxCapacity) : eg.capacity;
      Group& g =
          ctx.createGroup(instance.empty() ? eg.name : eg.name + "@" + std::string(instance), cap);
      // What restart() builds again (the effect's own times: moved once, to then).
      auto origin = std::make_shared<detail::GroupOrigin>();
      origin->actions = eg.actions;
      g.setActions(t0 == 0.0 ? eg.actions : delayedActions(eg.actions, t0));
      if (eg.hair.enabled) g.setHair(eg.hair);
      if (eg.trail.length > 0) g.setTrail(eg.trail);
      g.setBudgetPolicy(eg.budget);
      g.require(eg.require);
      if (space == Space::Local) g.setSpace(Space::Local);
      for (Emitter e : eg.emitters) {
        origin->emitters.push_back(e);
        delayTimes(e, t0);
        g.addEmitter(std::move(e));
      }
      for (PrimeEmitter p : eg.primeEmitters) {
        origin->primes.push_back(p);
        delayTimes(p, t0);
        g.addPrimeEmitter(std::move(p));
      }
      detail::implOf(g).origin = std::move(origin);
      for (DeathEmitter de : eg.deathEmitters) {
        if (!instance.empty()) (de.source += '@') += instance;  // its own instance's
        g.addDeathEmitter(std::move(de));
      }
      made.push_back(&g);
    } catch (const InvalidArgument& e) {
      throw EffectError(where, path, e.what());
    } catch (const Error& e) {
      throw EffectError(where, path, e.what());
    }
  }
  return made;
}

EffectInstance Effect::instantiate(Context& ctx, std::string_view instance,
                                   std::size_t maxCapacity) const {
  EffectInstance fx;
  fx.groups_ = build(ctx, maxCapacity, instance);
  fx.context_ = &ctx;
  for (std::size_t k = 0; k < std::size(fx.impls_) && k < fx.groups_.size(); ++k)
    fx.impls_[k] = &detail::implOf(*fx.groups_[k]);
  return fx;
}

EffectInstance& EffectInstance::setTransform(const Transform& transform) {
  // All or nothing: a group that refuses it (a box turned by other than quarter turns) puts
  // back the ones already moved.
  const Transform before = this->transform();
  std::size_t moved = 0;
  try {
    for (; moved < groups_.size(); ++moved) groups_[moved]->setTransform(transform);
  } catch (...) {
    for (std::size_t k = 0; k < moved; ++k) groups_[k]->setTransform(before);
    throw;
  }
  transform_ = groups_.empty() ? transform : groups_.front()->transform();
  return *this;
}

Bounds EffectInstance::bounds() const {
  Bounds all;
  for (std::size_t k = 0; k < groups_.size(); ++k) {
    const Bounds b =
        detail::liveBox(k < std::size(impls_) ? *impls_[k] : detail::implOf(*groups_[k]));
    if (b.empty) continue;
    all.min = all.empty ? b.min : glm::min(all.min, b.min);
    all.max = all.empty ? b.max : glm::max(all.max, b.max);
    all.empty = false;
  }
  return all;
}

std::uint64_t EffectInstance::prewarm(double seconds) {
  if (!context_) throw Error("prewarm: an empty EffectInstance (use Effect::instantiate)");
  return context_->prewarm(groups_, seconds);
}

EffectInstance& EffectInstance::setTimeScale(double scale) {
  if (!context_) throw Error("setTimeScale: an empty EffectInstance (use Effect::instantiate)");
  for (Group* g : groups_) g->setTimeScale(scale);  // the first refuses a bad scale
  return *this;
}

double EffectInstance::timeScale() const {
  return groups_.empty() ? 1.0 : groups_.front()->timeScale();
}

EffectInstance& EffectInstance::setUpdateInterval(std::uint32_t interval) {
  if (!context_)
    throw Error("setUpdateInterval: an empty EffectInstance (use Effect::instantiate)");
  for (Group* g : groups_) {
    g->setUpdateInterval(interval);  // the first refuses a bad interval
    // Its groups step together (death emitters feed on each other's events), on the first's
    // turn.
    detail::implOf(*g).updatePhase = detail::implOf(*groups_.front()).updatePhase;
  }  // (setUpdateInterval told the context: it reads the phases at its next step)
  return *this;
}

EffectInstance& EffectInstance::setSeed(std::uint64_t seed) {
  if (!context_) throw Error("setSeed: an empty EffectInstance (use Effect::instantiate)");
  for (std::size_t k = 0; k < groups_.size(); ++k) groups_[k]->setSeed(seed, std::uint32_t(k));
  return *this;
}

void EffectInstance::stop() {
  if (!context_) throw Error("stop: an empty EffectInstance (use Effect::instantiate)");
  for (Group* g : groups_) detail::stopEmitting(detail::implOf(*g), context_->time(*g), false);
}

void EffectInstance::kill() {
  if (!context_) throw Error("kill: an empty EffectInstance (use Effect::instantiate)");
  for (Group* g : groups_) {
    detail::stopEmitting(detail::implOf(*g), context_->time(*g), true);
    g->clear();
  }
}

void EffectInstance::restart() {
  if (!context_) throw Error("restart: an empty EffectInstance (use Effect::instantiate)");
  kill();
  for (Group* g : groups_) {
    detail::GroupImpl& gi = detail::implOf(*g);
    if (!gi.origin) continue;
    // The effect's times, moved to now on the group's clock.
    const auto& origin = gi.origin;
    const double shift = context_->time(*g);
    detail::clearEmitters(gi);
    for (Emitter e : origin->emitters) {
      delayTimes(e, shift);
      g->addEmitter(std::move(e));
    }
    for (PrimeEmitter p : origin->primes) {
      delayTimes(p, shift);
      g->addPrimeEmitter(std::move(p));
    }
    g->setActions(delayedActions(origin->actions, shift));
  }
}

bool EffectInstance::done() const {
  if (!context_) throw Error("done: an empty EffectInstance (use Effect::instantiate)");
  return std::all_of(groups_.begin(), groups_.end(), [&](const Group* g) {
    return g->size() == 0 && !detail::mayEverEmit(detail::implOf(*g), context_->time(*g));
  });
}

void EffectInstance::destroy() {
  for (Group* g : groups_) context_->destroyGroup(*g);
  groups_.clear();
  std::fill(std::begin(impls_), std::end(impls_), nullptr);
}

}  // namespace flurry
