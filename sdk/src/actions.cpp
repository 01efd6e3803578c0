#include <cmath>
#include <type_traits>

#include "action_traits.hpp"
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

bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

struct Validator {
  std::string where;

  void require(bool ok, const char* field, const std::string& why) const {
    if (!ok) throw InvalidArgument(where + "." + field, why);
  }
  void finiteVec(Vec3 v, const char* field) const { require(finite(v), field, "not finite"); }
  void finiteNum(float x, const char* field) const {
    require(std::isfinite(x), field, "not finite");
  }
  void nonNegative(float x, const char* field) const {
    require(std::isfinite(x) && x >= 0, field, "must be finite and >= 0");
  }
  void positive(float x, const char* field) const {
    require(std::isfinite(x) && x > 0, field, "must be finite and > 0");
  }
  // A radius may be infinite ("no limit") but must be > 0.
  void radius(float x, const char* field) const {
    require(!std::isnan(x) && x > 0, field, "must be > 0 (infinity: no limit)");
  }
  void axis(Vec3 v, const char* field) const {
    finiteVec(v, field);
    require(glm::dot(v, v) > 0, field, "zero length");
  }
  void falloff(const Falloff& f) const {
    finiteVec(f.center, "falloff.center");
    radius(f.radius, "falloff.radius");
    nonNegative(f.power, "falloff.power");
  }
  void rate(Vec3 r, const char* field) const {
    finiteVec(r, field);
    require(r.x >= 0 && r.y >= 0 && r.z >= 0, field, "must be >= 0");
  }
  void orbit(float magnitude, float epsilon, float maxRadius) const {
    finiteNum(magnitude, "magnitude");
    positive(epsilon, "epsilon");  // softening: finite at r = 0
    radius(maxRadius, "maxRadius");
  }

  void operator()(const Gravity& a) const {
    finiteVec(a.acceleration, "acceleration");
    falloff(a.falloff);
  }
  void operator()(const Damping& a) const {
    rate(a.rate, "rate");
    falloff(a.falloff);
  }
  void operator()(const RotDamping& a) const { rate(a.rate, "rate"); }
  void operator()(const OrbitPoint& a) const {
    finiteVec(a.center, "center");
    orbit(a.magnitude, a.epsilon, a.maxRadius);
  }
  void operator()(const OrbitLine& a) const {
    finiteVec(a.point, "point");
    axis(a.axis, "axis");
    orbit(a.magnitude, a.epsilon, a.maxRadius);
  }
  void operator()(const Gravitate& a) const { orbit(a.magnitude, a.epsilon, a.maxRadius); }
  void operator()(const Vortex& a) const {
    finiteVec(a.center, "center");
    axis(a.axis, "axis");
    finiteNum(a.aroundSpeed, "aroundSpeed");
    positive(a.coreRadius, "coreRadius");
    nonNegative(a.tightness, "tightness");
    finiteNum(a.inSpeed, "inSpeed");
    finiteNum(a.upSpeed, "upSpeed");
    nonNegative(a.responsiveness, "responsiveness");
    radius(a.maxRadius, "maxRadius");
  }
  void operator()(const Jet& a) const {
    finiteVec(a.center, "center");
    radius(a.radius, "radius");
  }
  void operator()(const Explosion& a) const {
    finiteVec(a.center, "center");
    nonNegative(a.speed, "speed");
    finiteNum(a.magnitude, "magnitude");
    positive(a.stddev, "stddev");
    positive(a.epsilon, "epsilon");
    finiteNum(a.time, "time");
  }
  void operator()(const RandomAccel& a) const { falloff(a.falloff); }
  void operator()(const RandomDisplace&) const {}
  void operator()(const RandomVelocity&) const {}
  void operator()(const RandomRotVelocity&) const {}
  void operator()(const Turbulence& a) const {
    finiteNum(a.amplitude, "amplitude");
    positive(a.frequency, "frequency");
    require(a.octaves >= 1 && a.octaves <= 8, "octaves", "must be in [1, 8]");
    finiteVec(a.drift, "drift");
    falloff(a.falloff);
  }
  void operator()(const ElectricField& a) const {
    finiteVec(a.field, "field");
    falloff(a.falloff);
  }
  void operator()(const MagneticField& a) const {
    finiteVec(a.field, "field");
    falloff(a.falloff);
  }
  void operator()(const SampledField& a) const {
    require(a.field != nullptr, "field", "no field given");
    a.field->validate((where + ".field").c_str());
    finiteNum(a.strength, "strength");
    nonNegative(a.responsiveness, "responsiveness");
    falloff(a.falloff);
  }
  void operator()(const Avoid& a) const {
    finiteNum(a.magnitude, "magnitude");
    positive(a.epsilon, "epsilon");
    nonNegative(a.lookAhead, "lookAhead");
  }
  void operator()(const Follow& a) const { orbit(a.magnitude, a.epsilon, a.maxRadius); }
  void operator()(const MatchVelocity& a) const { orbit(a.magnitude, a.epsilon, a.maxRadius); }
  void operator()(const MatchRotVelocity& a) const { orbit(a.magnitude, a.epsilon, a.maxRadius); }
  void operator()(const TargetVelocity& a) const {
    finiteVec(a.velocity, "velocity");
    nonNegative(a.rate, "rate");
  }
  void operator()(const TargetRotVelocity& a) const {
    finiteVec(a.rotVelocity, "rotVelocity");
    nonNegative(a.rate, "rate");
  }
  void operator()(const TargetColor& a) const {
    finiteVec(a.color, "color");
    finiteNum(a.alpha, "alpha");
    nonNegative(a.rate, "rate");
  }
  void operator()(const TargetSize& a) const {
    nonNegative(a.size, "size");
    nonNegative(a.rate, "rate");
  }
  void operator()(const SpeedClamp& a) const {
    nonNegative(a.minSpeed, "minSpeed");
    require(!std::isnan(a.maxSpeed) && a.maxSpeed >= a.minSpeed, "maxSpeed", "must be >= minSpeed");
  }
  template <class Keys>
  void keys(const Keys& k) const {
    require(!k.empty(), "keys", "needs at least one key");
    for (std::size_t i = 0; i < k.size(); ++i) {
      require(std::isfinite(k[i].t) && k[i].t >= 0 && k[i].t <= 1, "keys",
              "key " + std::to_string(i) + ": t must be in [0, 1]");
      require(i == 0 || k[i].t >= k[i - 1].t, "keys", "key times must not decrease");
    }
  }
  void overLifeMode(OverLifeMode m) const {
    require(m == OverLifeMode::Multiply || m == OverLifeMode::Replace, "mode",
            "must be Multiply or Replace");
  }
  void operator()(const ColorOverLife& a) const {
    overLifeMode(a.mode);
    keys(a.keys);
    for (const auto& k : a.keys)
      require(std::isfinite(k.color.r) && std::isfinite(k.color.g) && std::isfinite(k.color.b) &&
                  std::isfinite(k.color.a),
              "keys", "a color is not finite");
  }
  void operator()(const SizeOverLife& a) const {
    overLifeMode(a.mode);
    keys(a.keys);
    for (const auto& k : a.keys) nonNegative(k.size, "keys");
  }
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
    nonNegative(a.restitution, "restitution");
    require(std::isfinite(a.friction) && a.friction >= 0 && a.friction <= 1, "friction",
            "must be in [0, 1]");
    nonNegative(a.cutoff, "cutoff");
    if (std::holds_alternative<LineDomain>(s)) {
      axis(a.planeNormal, "planeNormal");
      const auto& l = std::get<LineDomain>(s);
      const Vec3 n = glm::cross(l.p1 - l.p0, a.planeNormal);
      require(glm::dot(n, n) > 0, "planeNormal", "the segment lies along the plane's normal");
    }
  }
  void operator()(const Sink& a) const {
    require(std::isfinite(a.passThrough) && a.passThrough >= 0 && a.passThrough <= 1, "passThrough",
            "must be in [0, 1]");
    require(a.mode != Sink::Mode::Hit || a.region.isPlanar(), "mode",
            "Hit needs a plane piece (plane, rectangle, disc, triangle)");
  }
  void operator()(const SinkVelocity&) const {}
  void operator()(const Block&) const {}
  void operator()(const KillOld&) const {}
  void operator()(const Move&) const {}
  void operator()(const Constrain2D& a) const {
    finiteVec(a.point, "point");
    axis(a.normal, "normal");
  }
  void operator()(const CopyVertexB&) const {}
  void operator()(const Restore& a) const {
    finiteNum(a.start, "start");
    positive(a.duration, "duration");
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
  std::visit(Validator{where}, action);
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
