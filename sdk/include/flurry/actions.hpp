// Actions: what happens to a group's particles each step, in the order of the action list
// (the Particle System API's model). A backend compiles the whole list into one fused pass.
#pragma once

#include <cstddef>
#include <string>
#include <variant>
#include <vector>

#include "flurry/attribute.hpp"
#include "flurry/domain.hpp"

namespace flurry {

/// Uniform acceleration (gravity, wind): v += a·dt.
struct Gravity {
  Vec3 acceleration{0.0f, -9.81f, 0.0f};
};

/// Linear drag, dv/dt = -rate ⊙ v per axis, applied exactly (v *= exp(-rate·dt)), so the
/// result does not depend on the step size (the classic API's v *= 1 - k·dt does).
struct Damping {
  Vec3 rate{0.1f};
};

/// A deflector: particles whose motion in the coming Move would cross `surface` are
/// reflected at the time of impact inside the step. The normal part of the velocity is
/// scaled by `restitution`, the tangential part by (1 - friction) unless the tangential
/// speed is below `cutoff`. Surfaces: plane, rectangle, disc, triangle (two-sided), sphere
/// (from outside). Put Bounce after the forces and before Move; it positions the particle so
/// that Move ends it at its reflected place, never behind the surface, at any speed.
struct Bounce {
  Domain surface;
  float restitution = 1.0f;
  float friction = 0.0f;
  float cutoff = 0.0f;
};

/// An absorber: kills particles inside `region` (or outside it, killInside = false).
/// A fraction `passThrough` in [0, 1] of the particles that would be killed survive.
struct Sink {
  Domain region;
  bool killInside = true;
  float passThrough = 0.0f;
};

/// Kills particles whose age exceeds their lifetime.
struct KillOld {};

/// Integrates positions (p += v·dt) and advances ages.
struct Move {};

using Action = std::variant<Gravity, Damping, Bounce, Sink, KillOld, Move>;

/// "Gravity", "Bounce", ...
std::string actionName(const Action& a);

/// An ordered list of actions, applied to a group every step.
class ActionList {
 public:
  ActionList() = default;
  ActionList(std::initializer_list<Action> actions) {
    for (const Action& a : actions) add(a);
  }
  /// Appends an action after validating it (throws InvalidArgument naming the field,
  /// e.g. "actions[1].Bounce.restitution").
  ActionList& add(Action action);

  const std::vector<Action>& actions() const { return actions_; }
  std::size_t size() const { return actions_.size(); }
  bool empty() const { return actions_.empty(); }
  /// The attributes the actions read or write: a group stores these.
  AttributeSet attributes() const;
  /// Whether any action can kill a particle.
  bool kills() const;

 private:
  std::vector<Action> actions_;
};

}  // namespace flurry
