// Actions: what happens to a group's particles each step, in the order of the action list
// (the Particle System API's model). A backend compiles the whole list into one fused pass.
//
// Forces change velocities; Move integrates positions; deflectors (Bounce) and absorbers
// (Sink) act on the motion the coming Move will make. Every rate-like parameter is applied
// exactly over the step (exponentials, rotations), so results do not depend on the step
// size where the motion has a closed form.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "flurry/attribute.hpp"
#include "flurry/domain.hpp"
#include "flurry/field.hpp"

namespace flurry {

struct Particle;

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// Where a force field acts: full strength at `center`, fading as (1 - r/radius)^power to
/// zero at `radius`. The default (infinite radius) is no falloff at all.
struct Falloff {
  Vec3 center{0.0f};
  float radius = kInfinity;
  float power = 1.0f;
};

// ---- Forces -------------------------------------------------------------------------------

/// Uniform acceleration (gravity, wind): v += a·dt.
struct Gravity {
  Vec3 acceleration{0.0f, -9.81f, 0.0f};
  Falloff falloff;
};

/// Linear drag, dv/dt = -rate ⊙ v per axis, applied exactly (v *= exp(-rate·dt)), so the
/// result does not depend on the step size (the classic API's v *= 1 - k·dt does).
struct Damping {
  Vec3 rate{0.1f};
  Falloff falloff;
};

/// Angular drag on RotVelocity, exact like Damping.
struct RotDamping {
  Vec3 rate{0.1f};
};

/// Point gravity with softening: a = magnitude·d / (|d|² + epsilon)^(3/2), d = center - p.
/// epsilon > 0 keeps it finite at the center (a particle exactly there feels nothing).
struct OrbitPoint {
  Vec3 center{0.0f};
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = kInfinity;
};

/// Like OrbitPoint, towards the nearest point of the infinite line through `point` along
/// `axis`.
struct OrbitLine {
  Vec3 point{0.0f};
  Vec3 axis{0.0f, 1.0f, 0.0f};
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = kInfinity;
};

/// Mutual gravity between the particles of the group (O(n²): for small groups).
struct Gravitate {
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = kInfinity;
};

/// A swirl about the line through `center` along `axis`: particles are carried towards the
/// velocity field of a Rankine vortex (solid-body rotation inside `coreRadius`, speed falling
/// as (coreRadius/r)^tightness outside), plus `inSpeed` towards and `upSpeed` along the axis,
/// at `responsiveness` per second (exactly: v += (u - v)(1 - exp(-k·dt))). Finite on the axis.
struct Vortex {
  Vec3 center{0.0f};
  Vec3 axis{0.0f, 1.0f, 0.0f};
  float aroundSpeed = 1.0f;
  float coreRadius = 0.5f;
  float tightness = 1.0f;
  float inSpeed = 0.0f;
  float upSpeed = 0.0f;
  float responsiveness = 5.0f;
  float maxRadius = kInfinity;
};

/// Particles within `radius` of `center` get an acceleration drawn from `acceleration`.
struct Jet {
  Vec3 center{0.0f};
  float radius = 1.0f;
  Domain acceleration = Domain::point(Vec3(0.0f, 10.0f, 0.0f));
};

/// A spherical shock front leaving `center` at `time` with `speed`: particles near the front
/// (a gaussian of `stddev` about its radius) are pushed outward with
/// magnitude·exp(-δ²/2σ²)/(r² + epsilon).
struct Explosion {
  Vec3 center{0.0f};
  float speed = 10.0f;
  float magnitude = 10.0f;
  float stddev = 1.0f;
  float epsilon = 1e-3f;
  float time = 0.0f;
};

/// Random acceleration drawn each step from a domain (v += sample·dt).
struct RandomAccel {
  Domain acceleration = Domain::sphere(Vec3(0.0f), 1.0f);
  Falloff falloff;
};
/// Random displacement each step (p += sample·dt).
struct RandomDisplace {
  Domain displacement = Domain::sphere(Vec3(0.0f), 1.0f);
};
/// Replaces the velocity with a random one drawn from a domain.
struct RandomVelocity {
  Domain velocity = Domain::sphere(Vec3(0.0f), 1.0f);
};
/// Replaces the angular velocity with a random one drawn from a domain.
struct RandomRotVelocity {
  Domain rotVelocity = Domain::sphere(Vec3(0.0f), 1.0f);
};

/// Turbulence: divergence-free curl noise (Bridson et al. 2007) of gradient noise, as an
/// acceleration of `amplitude`; `frequency` is spatial (1/units), the field drifts with
/// `drift` (units/s) so it changes in time; `octaves` of fractal detail.
struct Turbulence {
  float amplitude = 1.0f;
  float frequency = 1.0f;
  int octaves = 1;
  Vec3 drift{0.0f};
  Falloff falloff;
};

/// A uniform electric field: a = (charge / mass)·E.
struct ElectricField {
  Vec3 field{0.0f};
  Falloff falloff;
};

/// A uniform magnetic field: the Lorentz force (charge / mass)·v × B, applied as the exact
/// rotation of v about B by (charge / mass)·|B|·dt, so it does no work: speed is unchanged.
struct MagneticField {
  Vec3 field{0.0f, 0.0f, 1.0f};
  Falloff falloff;  ///< scales the field (the rotation angle), so still no work is done
};

/// A vector field sampled trilinearly from a grid (dense, or an OpenVDB grid read by
/// flurry::vdb), used as an acceleration, or as a velocity the particles are carried towards
/// at `responsiveness` per second.
struct SampledField {
  enum class Mode { Acceleration, Velocity };
  std::shared_ptr<const VectorField> field;
  Mode mode = Mode::Acceleration;
  float strength = 1.0f;
  float responsiveness = 5.0f;
  Falloff falloff;
};

/// Steers particles away from an obstacle they would enter within `lookAhead` seconds, with
/// an acceleration of magnitude / (distance² + epsilon) along the obstacle's normal.
struct Avoid {
  Domain obstacle = Domain::sphere(Vec3(0.0f), 1.0f);
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float lookAhead = 1.0f;
};

/// Each particle accelerates towards the next one in the group (by index), like OrbitPoint.
struct Follow {
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = kInfinity;
};

/// Each particle accelerates towards the mean velocity of its neighbours within maxRadius.
struct MatchVelocity {
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = 1.0f;
};
/// The same for angular velocity.
struct MatchRotVelocity {
  float magnitude = 1.0f;
  float epsilon = 1e-3f;
  float maxRadius = 1.0f;
};

/// Velocity, angular velocity, color and size approach a target exponentially at `rate` per
/// second (x += (target - x)(1 - exp(-rate·dt))): never overshooting, at any step size.
struct TargetVelocity {
  Vec3 velocity{0.0f};
  float rate = 1.0f;
};
struct TargetRotVelocity {
  Vec3 rotVelocity{0.0f};
  float rate = 1.0f;
};
struct TargetColor {
  Vec3 color{1.0f};
  float alpha = 1.0f;
  float rate = 1.0f;
};
struct TargetSize {
  float size = 1.0f;
  float rate = 1.0f;
};

/// Clamps the speed into [minSpeed, maxSpeed] keeping the direction.
struct SpeedClamp {
  float minSpeed = 0.0f;
  float maxSpeed = kInfinity;
};

/// How a curve over life sets its attribute: Multiply (the default) scales the value the
/// particle was born with (the emitter's type chose it), so one curve fades particles of every
/// colour or size alike; Replace sets the curve's value itself, as an absolute colour or size.
/// Multiply stores the birth value (Attribute::BirthColor, BirthSize) for the lists that use it.
enum class OverLifeMode { Multiply, Replace };

/// Color and size over life: the particle's age / lifetime in [0, 1] looks up a piecewise
/// linear gradient or curve (keys sorted by t), which scales the birth value (Multiply) or
/// replaces it (Replace), per channel (r, g, b, a).
struct ColorOverLife {
  using Mode = OverLifeMode;
  struct Key {
    float t;
    Vec4 color;
  };
  std::vector<Key> keys{{0.0f, Vec4(1.0f)}, {1.0f, Vec4(1.0f, 1.0f, 1.0f, 0.0f)}};
  Mode mode = Mode::Multiply;
};
struct SizeOverLife {
  using Mode = OverLifeMode;
  struct Key {
    float t;
    float size;
  };
  std::vector<Key> keys{{0.0f, 1.0f}, {1.0f, 0.0f}};
  Mode mode = Mode::Multiply;
};

// ---- Deflectors, absorbers, blockers --------------------------------------------------------

/// A deflector: particles whose motion in the coming Move would cross `surface` are
/// reflected at the time of impact inside the step. The normal part of the velocity is
/// scaled by `restitution`, the tangential part by (1 - friction) unless the tangential
/// speed is below `cutoff`. Surfaces: plane, rectangle, disc, triangle (two-sided), sphere and
/// box (from outside, or keeping particles inside when `inside`), and in 2-D a line segment
/// (its normal in the group's plane). Put Bounce after the forces and before Move: it places
/// the particle so that Move ends it at its reflected place, never behind the surface.
/// A two-sided piece treats its sides alike: a particle born or placed exactly on its plane
/// belongs to neither side and leaves it freely (an emitter on a floor emits through it); one
/// that ends a step on the plane by moving is bounced. With the Exact, VelocityVerlet and RK4
/// integrators a planar piece reflects the velocity at the moment of impact on the step's
/// curved path (second order at the bounce); spheres and boxes use the straight path.
struct Bounce {
  Domain surface;
  float restitution = 1.0f;
  float friction = 0.0f;
  float cutoff = 0.0f;
  bool inside = false;                 ///< sphere, box: keep particles in rather than out
  Vec3 planeNormal{0.0f, 0.0f, 1.0f};  ///< a segment's 2-D plane
};

/// An absorber: kills particles inside (or outside) a region, entering or leaving it in the
/// coming Move, or hitting a plane piece. A fraction `passThrough` in [0, 1] of the particles
/// pass it, in every mode: whether a particle passes is decided once per particle and absorber
/// (a uniform number in [0, 1) hashed from the seed, the particle's id, the group and the
/// absorber's index in the list; it passes iff that is < passThrough), not drawn anew each
/// step, so a particle that passes stays unharmed by this absorber for its whole life.
/// GroupStats::killedByAction counts what each absorber took.
struct Sink {
  enum class Mode { Inside, Outside, Enter, Leave, Hit };
  Domain region;
  float passThrough = 0.0f;
  Mode mode = Mode::Inside;  ///< the classic API's killInside = false is Mode::Outside
};

/// Kills particles whose velocity lies inside (or outside) a domain of velocities.
struct SinkVelocity {
  Domain velocity = Domain::sphere(Vec3(0.0f), 0.01f);
  bool killInside = true;  ///< false: kills those outside (its only switch, unlike Sink's mode)
};

/// A blocker: particles inside `region` are not drawn (Visible = 0); they are still simulated
/// and reappear when they leave. Several blockers hide the union of their regions.
struct Block {
  Domain region = Domain::box(Vec3(-1.0f), Vec3(1.0f));
};

// ---- Life, motion and bookkeeping -----------------------------------------------------------

/// Kills particles whose age exceeds their lifetime.
struct KillOld {};

/// Integrates positions (p += v·dt), rotations' up vectors, and advances ages.
struct Move {};

/// Keeps a group in a plane (2-D mode): removes the normal component of the position's
/// offset from `point` and of the velocity.
struct Constrain2D {
  Vec3 point{0.0f};
  Vec3 normal{0.0f, 0.0f, 1.0f};
};

/// Copies position (and velocity) into PositionB (VelocityB): a rest pose for Restore.
struct CopyVertexB {
  bool copyPosition = true;
  bool copyVelocity = false;
};

/// Returns particles to PositionB, arriving at time `start + duration` (seconds of the
/// context's clock) and staying there; the velocity is set so that they arrive on time.
struct Restore {
  float start = 0.0f;
  float duration = 1.0f;
};

/// What a callback sees besides the particle.
struct CallbackContext {
  float dt;
  double time;
  std::uint64_t step;
};

/// Calls a C++ function on every particle (gathered into a Particle and scattered back).
/// `attributes` names what it reads or writes, so the group stores them.
///
/// On the OpenCL backend `opencl` holds OpenCL C statements run for each particle inside the
/// fused kernel; without it the list cannot run there. They see the attributes named in
/// `attributes` by the variables flurry::kCallbackVariables lists (px py pz, vx vy vz, ...,
/// id read only, vis a uint), float dt and time (the step's start, a double where the
/// device has doubles). `break` ends the callback; `return` is not allowed (it would leave
/// the whole kernel).
///
/// Written once for both: FLURRY_CALLBACK(statements) (flurry/callback.hpp) makes the C++
/// function and the OpenCL C text from one body, and the attributes from the names it uses.
struct Callback {
  std::function<void(Particle&, const CallbackContext&)> function;
  AttributeSet attributes{Attribute::Position, Attribute::Velocity};
  std::string opencl;
};

using Action =
    std::variant<Gravity, Damping, RotDamping, OrbitPoint, OrbitLine, Gravitate, Vortex, Jet,
                 Explosion, RandomAccel, RandomDisplace, RandomVelocity, RandomRotVelocity,
                 Turbulence, ElectricField, MagneticField, SampledField, Avoid, Follow,
                 MatchVelocity, MatchRotVelocity, TargetVelocity, TargetRotVelocity, TargetColor,
                 TargetSize, SpeedClamp, ColorOverLife, SizeOverLife, Bounce, Sink, SinkVelocity,
                 Block, KillOld, Move, Constrain2D, CopyVertexB, Restore, Callback>;

/// "Gravity", "Bounce", ...: the names effect files use.
std::string actionName(const Action& a);

/// How Move integrates the forces before it.
///
/// SemiImplicitEuler (the default) applies each force as its own exact update of the
/// velocity, in list order, then moves with the new velocity: symplectic, first order, and the
/// behaviour of the classic API's Gravity/Move lists. The others gather the force actions that
/// come before a Move (Gravity, Damping, OrbitPoint, OrbitLine, Gravitate, Vortex, Jet,
/// Explosion, RandomAccel, Turbulence, ElectricField, MagneticField, SampledField, Follow;
/// Vortex as k·(u - v)) into one acceleration a(p, v, t) and integrate it inside Move
/// (TargetVelocity keeps its own exact update, so it never overshoots):
/// ExplicitEuler (p += v·dt, v += a·dt: the textbook first-order method), VelocityVerlet
/// (second order, symplectic for position-only forces), RK4 (fourth order), or Exact (closed
/// form for constant acceleration with linear drag: Gravity, Damping, ElectricField only).
enum class Integrator { SemiImplicitEuler, ExplicitEuler, VelocityVerlet, RK4, Exact };

/// "SemiImplicitEuler", "ExplicitEuler", "VelocityVerlet", "RK4", "Exact".
const char* integratorName(Integrator integrator);

/// Sub-stepping: the step is split into n equal sub-steps, each running the whole action
/// list, with n the smallest count that keeps the sub-step at most `maxStep` seconds and the
/// distance the fastest particle of the group travels in one at most `maxDistance`.
/// 0 turns a bound off; `maxSubsteps` caps n.
struct Substeps {
  double maxStep = 0.0;
  float maxDistance = 0.0f;
  std::uint32_t maxSubsteps = 64;
};

namespace detail {
struct ActionListAccess;
}

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
  /// Whether any action reads other particles (Gravitate, Follow, Match*): the pass then
  /// reads them from a snapshot taken at the start of the step.
  bool readsNeighbours() const;

  /// Throws InvalidArgument "integrator" if Exact is asked of forces without a closed form.
  ActionList& setIntegrator(Integrator integrator);
  Integrator integrator() const { return integrator_; }
  /// Throws InvalidArgument "substeps.*" for negative or non-finite bounds.
  ActionList& setSubsteps(Substeps substeps);
  const Substeps& substeps() const { return substeps_; }

 private:
  friend struct detail::ActionListAccess;  // moves an effect instance's list in place
  std::vector<Action> actions_;
  Integrator integrator_ = Integrator::SemiImplicitEuler;
  Substeps substeps_;
};

}  // namespace flurry
