#include <cmath>
#include <string>
#include <type_traits>

#include "action_traits.hpp"
#include "effect/check_fields.hpp"
#include "effect/descriptors.hpp"
#include "flurry/actions.hpp"
#include "flurry/error.hpp"

namespace flurry {

namespace {

/// The descriptor's name (effect/descriptors.hpp); Callback has none (no effect file holds it).
template <class T>
constexpr const char* nameOf() {
  if constexpr (desc::Described<T>)
    return desc::Describe<T>::name;
  else
    return "Callback";
}

// Each field against its descriptor's limit (effect/check_fields.hpp), then what no single
// field says (the Validator).

struct Validator {
  std::string where;

  void require(bool ok, const char* field, const std::string& why) const {
    if (!ok) throw InvalidArgument(where + "." + field, why);
  }
  template <class A>
  void operator()(const A&) const {}  // its fields say all
  void operator()(const SampledField& a) const {
    require(a.field != nullptr, "field", "no field given");
    a.field->validate((where + ".field").c_str());
  }
  void operator()(const SpeedClamp& a) const {
    require(a.maxSpeed >= a.minSpeed, "maxSpeed", "must be >= minSpeed");
  }
  // (Each key's fields are checked by their descriptors.)
  template <class Keys>
  void keys(const Keys& k) const {
    require(!k.empty(), "keys", "needs at least one key");
    for (std::size_t i = 1; i < k.size(); ++i)
      require(k[i].t >= k[i - 1].t, "keys", "key times must not decrease");
  }
  void operator()(const ColorOverLife& a) const { keys(a.keys); }
  void operator()(const SizeOverLife& a) const { keys(a.keys); }
  void operator()(const Bounce& a) const {
    const auto& s = a.surface.shape();
    const bool closed =
        std::holds_alternative<SphereDomain>(s) || std::holds_alternative<BoxDomain>(s);
    const bool ok = a.surface.isPlanar() || closed || std::holds_alternative<LineDomain>(s);
    if (!ok)
      throw InvalidArgument(where + ".surface",
                            std::string("a ") + a.surface.name() +
                                " cannot deflect (use a plane, rectangle, disc, triangle, sphere, "
                                "box, or a line segment in 2-D)");
    require(!a.inside || closed, "inside", "only a sphere or a box can keep particles inside");
    if (std::holds_alternative<LineDomain>(s)) {
      const auto& l = std::get<LineDomain>(s);
      const Vec3 n = glm::cross(l.p1 - l.p0, a.planeNormal);
      require(glm::dot(n, n) > 0, "planeNormal", "the segment lies along the plane's normal");
    }
  }
  void operator()(const Sink& a) const {
    require(a.mode != Sink::Mode::Hit || a.region.isPlanar(), "mode",
            "Hit needs a plane piece (plane, rectangle, disc, triangle)");
  }
  void operator()(const Callback& a) const {
    require(bool(a.function), "function", "no function given");
  }
};

using A = Attribute;

struct Uses {
  AttributeSet operator()(const Gravity&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Damping&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const RotDamping&) const { return {A::RotVelocity}; }
  AttributeSet operator()(const OrbitPoint&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const OrbitLine&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Gravitate&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Vortex&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Jet&) const { return {A::Position, A::Velocity, A::Id}; }
  AttributeSet operator()(const Explosion&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const RandomAccel&) const { return {A::Position, A::Velocity, A::Id}; }
  AttributeSet operator()(const RandomDisplace&) const { return {A::Position, A::Id}; }
  AttributeSet operator()(const RandomVelocity&) const { return {A::Velocity, A::Id}; }
  AttributeSet operator()(const RandomRotVelocity&) const { return {A::RotVelocity, A::Id}; }
  AttributeSet operator()(const Turbulence&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const ElectricField&) const {
    return {A::Position, A::Velocity, A::Charge, A::Mass};
  }
  AttributeSet operator()(const MagneticField&) const {
    return {A::Position, A::Velocity, A::Charge, A::Mass};
  }
  AttributeSet operator()(const SampledField&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Avoid&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Follow&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const MatchVelocity&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const MatchRotVelocity&) const { return {A::Position, A::RotVelocity}; }
  AttributeSet operator()(const TargetVelocity&) const { return {A::Velocity}; }
  AttributeSet operator()(const TargetRotVelocity&) const { return {A::RotVelocity}; }
  AttributeSet operator()(const TargetColor&) const { return {A::Color}; }
  AttributeSet operator()(const TargetSize&) const { return {A::Size}; }
  AttributeSet operator()(const SpeedClamp&) const { return {A::Velocity}; }
  // Multiply reads the birth value: stored only for the lists that multiply.
  AttributeSet operator()(const ColorOverLife& a) const {
    AttributeSet s{A::Color, A::Age, A::Lifetime};
    if (a.mode == OverLifeMode::Multiply) s.insert(A::BirthColor);
    return s;
  }
  AttributeSet operator()(const SizeOverLife& a) const {
    AttributeSet s{A::Size, A::Age, A::Lifetime};
    if (a.mode == OverLifeMode::Multiply) s.insert(A::BirthSize);
    return s;
  }
  AttributeSet operator()(const Bounce&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Sink& a) const {
    AttributeSet s{A::Position};
    if (a.mode == Sink::Mode::Enter || a.mode == Sink::Mode::Leave || a.mode == Sink::Mode::Hit)
      s.insert(A::Velocity);
    return s;
  }
  AttributeSet operator()(const SinkVelocity&) const { return {A::Velocity}; }
  AttributeSet operator()(const Block&) const { return {A::Position, A::Visible}; }
  AttributeSet operator()(const KillOld&) const { return {A::Age, A::Lifetime}; }
  AttributeSet operator()(const Move&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const Constrain2D&) const { return {A::Position, A::Velocity}; }
  AttributeSet operator()(const CopyVertexB& a) const {
    AttributeSet s{A::Position, A::PositionB};
    if (a.copyVelocity) s.insert(A::Velocity).insert(A::VelocityB);
    return s;
  }
  AttributeSet operator()(const Restore&) const { return {A::Position, A::Velocity, A::PositionB}; }
  AttributeSet operator()(const Callback& a) const {
    return AttributeSet{A::Position} | a.attributes;
  }
};

}  // namespace

namespace detail {

bool isForce(const Action& a) {
  return std::holds_alternative<Gravity>(a) || std::holds_alternative<Damping>(a) ||
         std::holds_alternative<OrbitPoint>(a) || std::holds_alternative<OrbitLine>(a) ||
         std::holds_alternative<Gravitate>(a) || std::holds_alternative<Vortex>(a) ||
         std::holds_alternative<Jet>(a) || std::holds_alternative<Explosion>(a) ||
         std::holds_alternative<RandomAccel>(a) || std::holds_alternative<Turbulence>(a) ||
         std::holds_alternative<ElectricField>(a) || std::holds_alternative<MagneticField>(a) ||
         std::holds_alternative<SampledField>(a) || std::holds_alternative<Follow>(a);
}

bool hasClosedForm(const Action& a) {
  return std::holds_alternative<Gravity>(a) || std::holds_alternative<Damping>(a) ||
         std::holds_alternative<ElectricField>(a);
}

}  // namespace detail

namespace {

using detail::hasClosedForm;
using detail::isForce;

void checkExact(const std::vector<Action>& actions) {
  for (std::size_t i = 0; i < actions.size(); ++i)
    if (isForce(actions[i]) && !hasClosedForm(actions[i]))
      throw InvalidArgument("integrator",
                            "Exact needs forces with a closed form (Gravity, Damping, "
                            "ElectricField); actions[" +
                                std::to_string(i) + "] is " + actionName(actions[i]));
  for (const Action& a : actions) {
    const Falloff* f = nullptr;
    if (const auto* g = std::get_if<Gravity>(&a)) f = &g->falloff;
    if (const auto* d = std::get_if<Damping>(&a)) f = &d->falloff;
    if (const auto* e = std::get_if<ElectricField>(&a)) f = &e->falloff;
    if (f && f->radius < kInfinity)
      throw InvalidArgument("integrator", "Exact needs forces without a falloff radius");
  }
}

}  // namespace

const char* integratorName(Integrator i) {
  switch (i) {
    case Integrator::SemiImplicitEuler:
      return "SemiImplicitEuler";
    case Integrator::ExplicitEuler:
      return "ExplicitEuler";
    case Integrator::VelocityVerlet:
      return "VelocityVerlet";
    case Integrator::RK4:
      return "RK4";
    case Integrator::Exact:
      return "Exact";
  }
  return "?";
}

ActionList& ActionList::setIntegrator(Integrator integrator) {
  if (integrator == Integrator::Exact) checkExact(actions_);
  integrator_ = integrator;
  return *this;
}

ActionList& ActionList::setSubsteps(Substeps substeps) {
  if (!std::isfinite(substeps.maxStep) || substeps.maxStep < 0)
    throw InvalidArgument("substeps.maxStep", "must be finite and >= 0");
  if (!std::isfinite(substeps.maxDistance) || substeps.maxDistance < 0)
    throw InvalidArgument("substeps.maxDistance", "must be finite and >= 0");
  if (substeps.maxSubsteps < 1 || substeps.maxSubsteps > 256)
    throw InvalidArgument("substeps.maxSubsteps", "must be in [1, 256]");
  substeps_ = substeps;
  return *this;
}

std::string actionName(const Action& a) {
  return std::visit([](const auto& x) { return std::string(nameOf<std::decay_t<decltype(x)>>()); },
                    a);
}

ActionList& ActionList::add(Action action) {
  const std::string where =
      "actions[" + std::to_string(actions_.size()) + "]." + actionName(action);
  if (actions_.size() >= 250)
    throw InvalidArgument("actions", "an action list holds at most 250 actions");
  std::visit(
      [&](const auto& a) {
        if constexpr (desc::Described<std::decay_t<decltype(a)>>) desc::checkFields(a, where);
        Validator{where}(a);
      },
      action);
  if (integrator_ == Integrator::Exact) {
    std::vector<Action> next = actions_;
    next.push_back(action);
    checkExact(next);
  }
  actions_.push_back(std::move(action));
  return *this;
}

AttributeSet ActionList::attributes() const {
  AttributeSet s;
  for (const Action& a : actions_) s.insert(std::visit(Uses{}, a));
  return s;
}

bool ActionList::kills() const {
  for (const Action& a : actions_)
    if (std::holds_alternative<Sink>(a) || std::holds_alternative<KillOld>(a) ||
        std::holds_alternative<SinkVelocity>(a))
      return true;
  return false;
}

bool ActionList::readsNeighbours() const {
  for (const Action& a : actions_)
    if (std::holds_alternative<Gravitate>(a) || std::holds_alternative<Follow>(a) ||
        std::holds_alternative<MatchVelocity>(a) || std::holds_alternative<MatchRotVelocity>(a))
      return true;
  return false;
}

}  // namespace flurry
