#include <cmath>
#include <type_traits>

#include "flurry/actions.hpp"
#include "flurry/error.hpp"

namespace flurry {

namespace {

template <class T>
constexpr const char* nameOf() {
  if constexpr (std::is_same_v<T, Gravity>) return "Gravity";
  if constexpr (std::is_same_v<T, Damping>) return "Damping";
  if constexpr (std::is_same_v<T, Bounce>) return "Bounce";
  if constexpr (std::is_same_v<T, Sink>) return "Sink";
  if constexpr (std::is_same_v<T, KillOld>) return "KillOld";
  if constexpr (std::is_same_v<T, Move>) return "Move";
}

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct Validator {
  std::string where;
  void require(bool ok, const char* field, const char* why) const {
    if (!ok) throw InvalidArgument(where + "." + field, why);
  }
  void operator()(const Gravity& a) const {
    require(finite(a.acceleration), "acceleration", "not finite");
  }
  void operator()(const Damping& a) const {
    require(finite(a.rate), "rate", "not finite");
    require(a.rate.x >= 0 && a.rate.y >= 0 && a.rate.z >= 0, "rate", "must be >= 0");
  }
  void operator()(const Bounce& a) const {
    const auto& s = a.surface.shape();
    const bool ok = std::holds_alternative<PlaneDomain>(s) ||
                    std::holds_alternative<RectangleDomain>(s) ||
                    std::holds_alternative<DiscDomain>(s) ||
                    std::holds_alternative<TriangleDomain>(s) ||
                    std::holds_alternative<SphereDomain>(s);
    if (!ok)
      throw InvalidArgument(where + ".surface",
                            std::string("a ") + a.surface.name() +
                                " cannot deflect (use a plane, rectangle, disc, triangle or sphere)");
    require(std::isfinite(a.restitution) && a.restitution >= 0, "restitution",
            "must be finite and >= 0");
    require(std::isfinite(a.friction) && a.friction >= 0 && a.friction <= 1, "friction",
            "must be in [0, 1]");
    require(std::isfinite(a.cutoff) && a.cutoff >= 0, "cutoff", "must be finite and >= 0");
  }
  void operator()(const Sink& a) const {
    require(std::isfinite(a.passThrough) && a.passThrough >= 0 && a.passThrough <= 1,
            "passThrough", "must be in [0, 1]");
  }
  void operator()(const KillOld&) const {}
  void operator()(const Move&) const {}
};

struct Uses {
  AttributeSet operator()(const Gravity&) const { return {Attribute::Velocity}; }
  AttributeSet operator()(const Damping&) const { return {Attribute::Velocity}; }
  AttributeSet operator()(const Bounce&) const { return {Attribute::Position, Attribute::Velocity}; }
  AttributeSet operator()(const Sink&) const { return {Attribute::Position}; }
  AttributeSet operator()(const KillOld&) const { return {Attribute::Age, Attribute::Lifetime}; }
  AttributeSet operator()(const Move&) const { return {Attribute::Position, Attribute::Velocity}; }
};

}  // namespace

std::string actionName(const Action& a) {
  return std::visit([](const auto& x) { return std::string(nameOf<std::decay_t<decltype(x)>>()); },
                    a);
}

ActionList& ActionList::add(Action action) {
  const std::string where = "actions[" + std::to_string(actions_.size()) + "]." + actionName(action);
  if (actions_.size() >= 250)
    throw InvalidArgument("actions", "an action list holds at most 250 actions");
  std::visit(Validator{where}, action);
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
    if (std::holds_alternative<Sink>(a) || std::holds_alternative<KillOld>(a)) return true;
  return false;
}

}  // namespace flurry
