// One descriptor per action (and per emitter part and domain shape): its effect-file name, a
// one-line doc, and each field once, with its JSON name, the member, its unit, its valid values and
// a one-line doc. Defaults are never restated: they are the struct's own member initialisers (a
// default-constructed struct). From these the effect loader reads each action's body, the
// writer (saveEffect) writes it, and the JSON Schema, the reference docs and the fuzz
// dictionary are generated (flurry_effect_docs). Internal: not installed.
//
// Adding an action: its struct in actions.hpp, a Describe<> specialisation here; the reader,
// the writer, the schema and the docs follow.
#pragma once

#include <cstddef>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>

#include "flurry/actions.hpp"
#include "flurry/emitter.hpp"

namespace flurry::desc {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// A numeric field's valid values as validation checks them (ActionList::add for actions;
/// test_effect_descriptors checks the two agree): [min, max], min excluded when minOpen;
/// `infinite`: +inf is valid too ("no limit"); `nonZero`: a vector that must not be zero;
/// `checked` false: any number, checked elsewhere or not at all.
struct Limit {
  double min = -kInf;
  double max = kInf;
  bool minOpen = false;
  bool infinite = false;
  bool nonZero = false;
  bool checked = true;
};
inline constexpr Limit kAny{.checked = false};
inline constexpr Limit kFinite{};
inline constexpr Limit kNonNegative{.min = 0};
inline constexpr Limit kPositive{.min = 0, .minOpen = true};
inline constexpr Limit kRadius{.min = 0, .minOpen = true, .infinite = true};
inline constexpr Limit kUnitInterval{.min = 0, .max = 1};
inline constexpr Limit kNonZero{.nonZero = true};
inline constexpr Limit kUpToInfinity{.min = 0, .infinite = true};

/// Marks a field required; the text says what it is ("missing (the deflecting surface...)").
inline constexpr const char* kRequired = "required";

template <class S, class T>
struct Field {
  using Struct = S;
  using Type = T;
  const char* name;  ///< the JSON key
  T S::*member;
  const char* unit;  ///< "" when it has none
  Limit limit;
  const char* doc;
  const char* required = nullptr;  ///< null: optional (the struct's default)
};

template <class S, class T>
constexpr Field<S, T> field(const char* name, T S::*member, const char* unit, Limit limit,
                            const char* doc, const char* required = nullptr) {
  return {name, member, unit, limit, doc, required};
}

/// Describe<S>::name, ::doc and ::fields (a tuple of Field<S, ...>), for each described struct.
template <class S>
struct Describe;

template <class S>
concept Described = requires {
  Describe<S>::name;
  Describe<S>::fields;
};

/// The effect-file names of an enum's values, in order.
template <class E>
struct EnumNames;

template <class E>
concept NamedEnum = requires {
  EnumNames<E>::values;
};

/// Calls f(field) for each field of S, in order.
template <class S, class F>
constexpr void forEachField(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, Describe<S>::fields);
}

/// Calls f(std::type_identity<A>{}) for each action an effect file can hold, in the Action
/// variant's order (Callback runs C++ code and has no descriptor).
template <class F>
void forEachAction(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          using A = std::variant_alternative_t<I, Action>;
          if constexpr (Described<A>) f(std::type_identity<A>{});
        }(),
        ...);
  }
  (std::make_index_sequence<std::variant_size_v<Action>>{});
}

// ---- enums ----------------------------------------------------------------------------------

template <>
struct EnumNames<OverLifeMode> {
  static constexpr std::pair<const char*, OverLifeMode> values[] = {
      {"multiply", OverLifeMode::Multiply}, {"replace", OverLifeMode::Replace}};
};
template <>
struct EnumNames<SampledField::Mode> {
  static constexpr std::pair<const char*, SampledField::Mode> values[] = {
      {"acceleration", SampledField::Mode::Acceleration},
      {"velocity", SampledField::Mode::Velocity}};
};
template <>
struct EnumNames<Sink::Mode> {
  static constexpr std::pair<const char*, Sink::Mode> values[] = {{"inside", Sink::Mode::Inside},
                                                                  {"outside", Sink::Mode::Outside},
                                                                  {"enter", Sink::Mode::Enter},
                                                                  {"leave", Sink::Mode::Leave},
                                                                  {"hit", Sink::Mode::Hit}};
};

template <>
struct EnumNames<DeathEmitter::Trigger> {
  static constexpr std::pair<const char*, DeathEmitter::Trigger> values[] = {
      {"death", DeathEmitter::Trigger::Death},
      {"collision", DeathEmitter::Trigger::Collision},
      {"birth", DeathEmitter::Trigger::Birth}};
};

// ---- parts shared by actions ----------------------------------------------------------------

template <>
struct Describe<Falloff> {
  static constexpr const char* name = "Falloff";
  static constexpr const char* doc =
      "Where a force acts: full strength at center, fading as (1 - d/radius)^power to 0 at "
      "radius.";
  static constexpr auto fields = std::tuple{
      field("center", &Falloff::center, "units", kFinite, "where the force is strongest"),
      field("radius", &Falloff::radius, "units", kRadius, "where it fades to 0 (inf: nowhere)"),
      field("power", &Falloff::power, "", kNonNegative, "the exponent of the fade"),
  };
};
template <>
struct Describe<ColorOverLife::Key> {
  static constexpr const char* name = "ColorKey";
  static constexpr const char* doc = "A key of a colour gradient over life.";
  static constexpr auto fields = std::tuple{
      field("t", &ColorOverLife::Key::t, "", kUnitInterval, "age / lifetime", kRequired),
      field("color", &ColorOverLife::Key::color, "", kFinite, "[r, g, b] or [r, g, b, a]",
            kRequired),
  };
};
template <>
struct Describe<SizeOverLife::Key> {
  static constexpr const char* name = "SizeKey";
  static constexpr const char* doc = "A key of a size curve over life.";
  static constexpr auto fields = std::tuple{
      field("t", &SizeOverLife::Key::t, "", kUnitInterval, "age / lifetime", kRequired),
      field("size", &SizeOverLife::Key::size, "", kNonNegative, "size (or factor)", kRequired),
  };
};

// ---- forces ---------------------------------------------------------------------------------

template <>
struct Describe<Gravity> {
  static constexpr const char* name = "Gravity";
  static constexpr const char* doc = "Uniform acceleration (gravity, wind): v += a·dt.";
  static constexpr auto fields = std::tuple{
      field("acceleration", &Gravity::acceleration, "units/s²", kFinite, "the acceleration"),
      field("falloff", &Gravity::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<Damping> {
  static constexpr const char* name = "Damping";
  static constexpr const char* doc = "Linear drag per axis, exact: v *= exp(-rate·dt).";
  static constexpr auto fields = std::tuple{
      field("rate", &Damping::rate, "1/s", kNonNegative, "drag rate per axis"),
      field("falloff", &Damping::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<RotDamping> {
  static constexpr const char* name = "RotDamping";
  static constexpr const char* doc = "Angular drag on the angular velocity, exact like Damping.";
  static constexpr auto fields = std::tuple{
      field("rate", &RotDamping::rate, "1/s", kNonNegative, "drag rate per axis"),
  };
};
template <>
struct Describe<OrbitPoint> {
  static constexpr const char* name = "OrbitPoint";
  static constexpr const char* doc =
      "Point gravity with softening: a = magnitude·d / (|d|² + epsilon)^(3/2).";
  static constexpr auto fields = std::tuple{
      field("center", &OrbitPoint::center, "units", kFinite, "the attracting point"),
      field("magnitude", &OrbitPoint::magnitude, "", kFinite, "strength (negative repels)"),
      field("epsilon", &OrbitPoint::epsilon, "units²", kPositive, "softening near the center"),
      field("maxRadius", &OrbitPoint::maxRadius, "units", kRadius, "no effect beyond it"),
  };
};
template <>
struct Describe<OrbitLine> {
  static constexpr const char* name = "OrbitLine";
  static constexpr const char* doc =
      "Like OrbitPoint, towards the nearest point of an infinite line.";
  static constexpr auto fields = std::tuple{
      field("point", &OrbitLine::point, "units", kFinite, "a point of the line"),
      field("axis", &OrbitLine::axis, "", kNonZero, "the line's direction"),
      field("magnitude", &OrbitLine::magnitude, "", kFinite, "strength (negative repels)"),
      field("epsilon", &OrbitLine::epsilon, "units²", kPositive, "softening near the line"),
      field("maxRadius", &OrbitLine::maxRadius, "units", kRadius, "no effect beyond it"),
  };
};
template <>
struct Describe<Gravitate> {
  static constexpr const char* name = "Gravitate";
  static constexpr const char* doc = "Mutual gravity between the group's particles (O(n²)).";
  static constexpr auto fields = std::tuple{
      field("magnitude", &Gravitate::magnitude, "", kFinite, "strength (negative repels)"),
      field("epsilon", &Gravitate::epsilon, "units²", kPositive, "softening"),
      field("maxRadius", &Gravitate::maxRadius, "units", kRadius, "no effect beyond it"),
  };
};
template <>
struct Describe<Vortex> {
  static constexpr const char* name = "Vortex";
  static constexpr const char* doc =
      "A swirl about an axis (a Rankine vortex) that particles are carried towards.";
  static constexpr auto fields = std::tuple{
      field("center", &Vortex::center, "units", kFinite, "a point of the axis"),
      field("axis", &Vortex::axis, "", kNonZero, "the axis' direction"),
      field("aroundSpeed", &Vortex::aroundSpeed, "units/s", kFinite, "speed at coreRadius"),
      field("coreRadius", &Vortex::coreRadius, "units", kPositive, "solid-body rotation inside"),
      field("tightness", &Vortex::tightness, "", kNonNegative, "fall-off exponent outside"),
      field("inSpeed", &Vortex::inSpeed, "units/s", kFinite, "speed towards the axis"),
      field("upSpeed", &Vortex::upSpeed, "units/s", kFinite, "speed along the axis"),
      field("responsiveness", &Vortex::responsiveness, "1/s", kNonNegative,
            "how fast particles take the swirl's velocity"),
      field("maxRadius", &Vortex::maxRadius, "units", kRadius, "no effect beyond it"),
  };
};
template <>
struct Describe<Jet> {
  static constexpr const char* name = "Jet";
  static constexpr const char* doc =
      "Particles near a point get an acceleration drawn from a domain.";
  static constexpr auto fields = std::tuple{
      field("center", &Jet::center, "units", kFinite, "the jet's center"),
      field("radius", &Jet::radius, "units", kRadius, "acts within this distance"),
      field("acceleration", &Jet::acceleration, "units/s²", kAny, "drawn per particle"),
  };
};
template <>
struct Describe<Explosion> {
  static constexpr const char* name = "Explosion";
  static constexpr const char* doc =
      "A spherical shock front leaving center at time, pushing particles outward.";
  static constexpr auto fields = std::tuple{
      field("center", &Explosion::center, "units", kFinite, "where it starts"),
      field("speed", &Explosion::speed, "units/s", kNonNegative, "speed of the front"),
      field("magnitude", &Explosion::magnitude, "", kFinite, "strength"),
      field("stddev", &Explosion::stddev, "units", kPositive, "thickness of the front"),
      field("epsilon", &Explosion::epsilon, "units²", kPositive, "softening near the center"),
      field("time", &Explosion::time, "s", kFinite, "when it starts"),
  };
};
template <>
struct Describe<RandomAccel> {
  static constexpr const char* name = "RandomAccel";
  static constexpr const char* doc = "A random acceleration drawn each step from a domain.";
  static constexpr auto fields = std::tuple{
      field("acceleration", &RandomAccel::acceleration, "units/s²", kAny, "drawn each step"),
      field("falloff", &RandomAccel::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<RandomDisplace> {
  static constexpr const char* name = "RandomDisplace";
  static constexpr const char* doc = "A random displacement each step (p += sample·dt).";
  static constexpr auto fields = std::tuple{
      field("displacement", &RandomDisplace::displacement, "units/s", kAny, "drawn each step"),
  };
};
template <>
struct Describe<RandomVelocity> {
  static constexpr const char* name = "RandomVelocity";
  static constexpr const char* doc = "Replaces the velocity with one drawn from a domain.";
  static constexpr auto fields = std::tuple{
      field("velocity", &RandomVelocity::velocity, "units/s", kAny, "drawn each step"),
  };
};
template <>
struct Describe<RandomRotVelocity> {
  static constexpr const char* name = "RandomRotVelocity";
  static constexpr const char* doc = "Replaces the angular velocity with one drawn from a domain.";
  static constexpr auto fields = std::tuple{
      field("rotVelocity", &RandomRotVelocity::rotVelocity, "rad/s", kAny, "drawn each step"),
  };
};
template <>
struct Describe<Turbulence> {
  static constexpr const char* name = "Turbulence";
  static constexpr const char* doc = "Divergence-free curl noise as an acceleration.";
  static constexpr auto fields = std::tuple{
      field("amplitude", &Turbulence::amplitude, "units/s²", kFinite, "strength"),
      field("frequency", &Turbulence::frequency, "1/units", kPositive, "spatial frequency"),
      field("octaves", &Turbulence::octaves, "", Limit{.min = 1, .max = 8},
            "octaves of fractal detail"),
      field("drift", &Turbulence::drift, "units/s", kFinite, "how the field moves in time"),
      field("falloff", &Turbulence::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<ElectricField> {
  static constexpr const char* name = "ElectricField";
  static constexpr const char* doc = "A uniform electric field: a = (charge / mass)·E.";
  static constexpr auto fields = std::tuple{
      field("field", &ElectricField::field, "", kFinite, "the field E"),
      field("falloff", &ElectricField::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<MagneticField> {
  static constexpr const char* name = "MagneticField";
  static constexpr const char* doc =
      "A uniform magnetic field: the Lorentz force as an exact rotation (no work done).";
  static constexpr auto fields = std::tuple{
      field("field", &MagneticField::field, "", kFinite, "the field B"),
      field("falloff", &MagneticField::falloff, "", kAny, "scales the rotation angle"),
  };
};
template <>
struct Describe<SampledField> {
  static constexpr const char* name = "SampledField";
  static constexpr const char* doc =
      "A vector field sampled trilinearly from a grid, as an acceleration or a velocity.";
  static constexpr auto fields = std::tuple{
      field("field", &SampledField::field, "", kAny, "a dense grid or {\"vdb\": file, \"grid\"}",
            "a dense grid or {\"vdb\": file}"),
      field("mode", &SampledField::mode, "", kAny, "what the field's values are"),
      field("strength", &SampledField::strength, "", kFinite, "scales the field"),
      field("responsiveness", &SampledField::responsiveness, "1/s", kNonNegative,
            "velocity mode: how fast particles take the field's velocity"),
      field("falloff", &SampledField::falloff, "", kAny, "where it acts"),
  };
};
template <>
struct Describe<Avoid> {
  static constexpr const char* name = "Avoid";
  static constexpr const char* doc = "Steers particles away from an obstacle ahead of them.";
  static constexpr auto fields = std::tuple{
      field("obstacle", &Avoid::obstacle, "", kAny, "the domain to avoid"),
      field("magnitude", &Avoid::magnitude, "", kFinite, "strength"),
      field("epsilon", &Avoid::epsilon, "units²", kPositive, "softening"),
      field("lookAhead", &Avoid::lookAhead, "s", kNonNegative, "how far ahead to look"),
  };
};
template <>
struct Describe<Follow> {
  static constexpr const char* name = "Follow";
  static constexpr const char* doc = "Each particle accelerates towards the next one (by index).";
  static constexpr auto fields = std::tuple{
      field("magnitude", &Follow::magnitude, "", kFinite, "strength"),
      field("epsilon", &Follow::epsilon, "units²", kPositive, "softening"),
      field("maxRadius", &Follow::maxRadius, "units", kRadius, "no effect beyond it"),
  };
};
template <>
struct Describe<MatchVelocity> {
  static constexpr const char* name = "MatchVelocity";
  static constexpr const char* doc =
      "Each particle accelerates towards its neighbours' mean velocity.";
  static constexpr auto fields = std::tuple{
      field("magnitude", &MatchVelocity::magnitude, "", kFinite, "strength"),
      field("epsilon", &MatchVelocity::epsilon, "units²", kPositive, "softening"),
      field("maxRadius", &MatchVelocity::maxRadius, "units", kRadius, "neighbours within it"),
  };
};
template <>
struct Describe<MatchRotVelocity> {
  static constexpr const char* name = "MatchRotVelocity";
  static constexpr const char* doc =
      "Each particle accelerates towards its neighbours' mean angular velocity.";
  static constexpr auto fields = std::tuple{
      field("magnitude", &MatchRotVelocity::magnitude, "", kFinite, "strength"),
      field("epsilon", &MatchRotVelocity::epsilon, "units²", kPositive, "softening"),
      field("maxRadius", &MatchRotVelocity::maxRadius, "units", kRadius, "neighbours within it"),
  };
};
template <>
struct Describe<TargetVelocity> {
  static constexpr const char* name = "TargetVelocity";
  static constexpr const char* doc = "The velocity approaches a target exponentially.";
  static constexpr auto fields = std::tuple{
      field("velocity", &TargetVelocity::velocity, "units/s", kFinite, "the target"),
      field("rate", &TargetVelocity::rate, "1/s", kNonNegative, "how fast"),
  };
};
template <>
struct Describe<TargetRotVelocity> {
  static constexpr const char* name = "TargetRotVelocity";
  static constexpr const char* doc = "The angular velocity approaches a target exponentially.";
  static constexpr auto fields = std::tuple{
      field("rotVelocity", &TargetRotVelocity::rotVelocity, "rad/s", kFinite, "the target"),
      field("rate", &TargetRotVelocity::rate, "1/s", kNonNegative, "how fast"),
  };
};
template <>
struct Describe<TargetColor> {
  static constexpr const char* name = "TargetColor";
  static constexpr const char* doc = "The colour approaches a target exponentially.";
  static constexpr auto fields = std::tuple{
      field("color", &TargetColor::color, "", kFinite, "the target [r, g, b]"),
      field("alpha", &TargetColor::alpha, "", kFinite, "the target alpha"),
      field("rate", &TargetColor::rate, "1/s", kNonNegative, "how fast"),
  };
};
template <>
struct Describe<TargetSize> {
  static constexpr const char* name = "TargetSize";
  static constexpr const char* doc = "The size approaches a target exponentially.";
  static constexpr auto fields = std::tuple{
      field("size", &TargetSize::size, "units", kNonNegative, "the target"),
      field("rate", &TargetSize::rate, "1/s", kNonNegative, "how fast"),
  };
};
template <>
struct Describe<SpeedClamp> {
  static constexpr const char* name = "SpeedClamp";
  static constexpr const char* doc = "Clamps the speed into [minSpeed, maxSpeed].";
  static constexpr auto fields = std::tuple{
      field("minSpeed", &SpeedClamp::minSpeed, "units/s", kNonNegative, "the least speed"),
      field("maxSpeed", &SpeedClamp::maxSpeed, "units/s", kUpToInfinity,
            "the most speed (>= minSpeed)"),
  };
};
template <>
struct Describe<ColorOverLife> {
  static constexpr const char* name = "ColorOverLife";
  static constexpr const char* doc =
      "A colour gradient over life that scales (multiply) or sets (replace) the colour.";
  static constexpr auto fields = std::tuple{
      field("mode", &ColorOverLife::mode, "", kAny, "scale the birth colour, or set it"),
      field("keys", &ColorOverLife::keys, "", kAny, "the gradient, keys sorted by t"),
  };
};
template <>
struct Describe<SizeOverLife> {
  static constexpr const char* name = "SizeOverLife";
  static constexpr const char* doc =
      "A size curve over life that scales (multiply) or sets (replace) the size.";
  static constexpr auto fields = std::tuple{
      field("mode", &SizeOverLife::mode, "", kAny, "scale the birth size, or set it"),
      field("keys", &SizeOverLife::keys, "", kAny, "the curve, keys sorted by t"),
  };
};

// ---- deflectors, absorbers, blockers --------------------------------------------------------

template <>
struct Describe<Bounce> {
  static constexpr const char* name = "Bounce";
  static constexpr const char* doc = "A deflector: reflects particles that would cross a surface.";
  static constexpr auto fields = std::tuple{
      field("surface", &Bounce::surface, "", kAny,
            "plane, rectangle, disc, triangle, sphere, box; a line in 2-D",
            "the deflecting surface, a domain"),
      field("restitution", &Bounce::restitution, "", kNonNegative, "scales the normal velocity"),
      field("friction", &Bounce::friction, "", kUnitInterval,
            "takes this fraction of the tangential velocity"),
      field("cutoff", &Bounce::cutoff, "units/s", kNonNegative,
            "no friction below this tangential speed"),
      field("inside", &Bounce::inside, "", kAny, "sphere, box: keep particles in"),
      field("planeNormal", &Bounce::planeNormal, "", kNonZero, "a line's 2-D plane"),
  };
};
template <>
struct Describe<Sink> {
  static constexpr const char* name = "Sink";
  static constexpr const char* doc =
      "An absorber: kills particles inside, outside, entering, "
      "leaving or hitting a region.";
  static constexpr auto fields = std::tuple{
      field("region", &Sink::region, "", kAny, "a domain",
            "the absorbing region or surface, a domain"),
      field("passThrough", &Sink::passThrough, "", kUnitInterval,
            "the fraction of particles that pass"),
      field("mode", &Sink::mode, "", kAny,
            "when a particle is absorbed (the deprecated \"killInside\": false is \"outside\")"),
  };
};
template <>
struct Describe<SinkVelocity> {
  static constexpr const char* name = "SinkVelocity";
  static constexpr const char* doc = "Kills particles whose velocity lies inside a domain.";
  static constexpr auto fields = std::tuple{
      field("velocity", &SinkVelocity::velocity, "units/s", kAny, "a domain of velocities"),
      field("killInside", &SinkVelocity::killInside, "", kAny, "false: kill outside"),
  };
};
template <>
struct Describe<Block> {
  static constexpr const char* name = "Block";
  static constexpr const char* doc = "A blocker: hides the particles inside a region.";
  static constexpr auto fields = std::tuple{
      field("region", &Block::region, "", kAny, "a domain",
            "the region that hides particles, a domain"),
  };
};

// ---- life, motion, bookkeeping --------------------------------------------------------------

template <>
struct Describe<KillOld> {
  static constexpr const char* name = "KillOld";
  static constexpr const char* doc = "Kills particles older than their lifetime.";
  static constexpr auto fields = std::tuple{};
};
template <>
struct Describe<Move> {
  static constexpr const char* name = "Move";
  static constexpr const char* doc = "Integrates positions and advances ages.";
  static constexpr auto fields = std::tuple{};
};
template <>
struct Describe<Constrain2D> {
  static constexpr const char* name = "Constrain2D";
  static constexpr const char* doc = "Keeps the group in a plane (2-D mode).";
  static constexpr auto fields = std::tuple{
      field("point", &Constrain2D::point, "units", kFinite, "a point of the plane"),
      field("normal", &Constrain2D::normal, "", kNonZero, "the plane's normal"),
  };
};
template <>
struct Describe<CopyVertexB> {
  static constexpr const char* name = "CopyVertexB";
  static constexpr const char* doc = "Copies position (and velocity) into a rest pose.";
  static constexpr auto fields = std::tuple{
      field("copyPosition", &CopyVertexB::copyPosition, "", kAny, "into positionB"),
      field("copyVelocity", &CopyVertexB::copyVelocity, "", kAny, "into velocityB"),
  };
};
template <>
struct Describe<Restore> {
  static constexpr const char* name = "Restore";
  static constexpr const char* doc =
      "Returns particles to their rest pose, arriving at start + duration.";
  static constexpr auto fields = std::tuple{
      field("start", &Restore::start, "s", kFinite, "when it starts"),
      field("duration", &Restore::duration, "s", kPositive, "how long the return takes"),
  };
};

// ---- emitters (validated by Emitter::validate and friends: limits not restated) -------------

template <>
struct Describe<Burst> {
  static constexpr const char* name = "Burst";
  static constexpr const char* doc = "count particles at once, repeated.";
  static constexpr auto fields = std::tuple{
      field("time", &Burst::time, "s", kFinite, "when"),
      field("count", &Burst::count, "", kAny, "how many", kRequired),
      field("interval", &Burst::interval, "s", kNonNegative, "between repeats"),
      field("repeat", &Burst::repeat, "", kAny, "how many bursts"),
  };
};
template <>
struct Describe<Keyframe> {
  static constexpr const char* name = "Keyframe";
  static constexpr const char* doc = "A point of an emitter's path.";
  static constexpr auto fields = std::tuple{
      field("time", &Keyframe::time, "s", kFinite, "when", kRequired),
      field("position", &Keyframe::position, "units", kFinite, "where", kRequired),
  };
};
template <>
struct Describe<ParticleType> {
  static constexpr const char* name = "ParticleType";
  static constexpr const char* doc = "What an emitter's particles are born with.";
  static constexpr auto fields = std::tuple{
      field("weight", &ParticleType::weight, "", kNonNegative, "relative share of this type"),
      field("velocity", &ParticleType::velocity, "units/s", kAny, "initial velocity"),
      field("color", &ParticleType::color, "", kAny, "rgb"),
      field("alpha", &ParticleType::alpha, "", kAny, "opacity"),
      field("size", &ParticleType::size, "units", kAny, "radius"),
      field("mass", &ParticleType::mass, "", kAny, "mass"),
      field("lifetime", &ParticleType::lifetime, "s", kAny, "lifetime"),
      field("charge", &ParticleType::charge, "", kAny, "electric charge"),
      field("up", &ParticleType::up, "", kAny, "initial up vector"),
      field("rotVelocity", &ParticleType::rotVelocity, "rad/s", kAny, "angular velocity"),
  };
};

/// The fields an emitter and a prime emitter share: where, when and how many.
template <class E>
constexpr auto countingFields() {
  return std::tuple{
      field("name", &E::name, "", kAny, "names it in statistics"),
      field("shape", &E::shape, "units", kAny, "where particles are born"),
      field("rate", &E::rate, "1/s", kNonNegative, "births per second"),
      field("bursts", &E::bursts, "", kAny, "births at given times"),
      field("position", &E::position, "units", kFinite, "offset of the shape"),
      field("velocity", &E::velocity, "units/s", kFinite, "the emitter's own motion"),
      field("path", &E::path, "", kAny, "keyframed positions"),
      field("pathLoop", &E::pathLoop, "", kAny, "repeat the path after its last key"),
      field("start", &E::start, "s", kFinite, "emits from"),
      field("stop", &E::stop, "s", kAny, "emits until (inf: for ever)"),
  };
}
template <>
struct Describe<Emitter> {
  static constexpr const char* name = "Emitter";
  static constexpr const char* doc = "Emits particles of one or more types.";
  static constexpr auto fields = std::tuple_cat(
      countingFields<Emitter>(),
      std::tuple{
          field("types", &Emitter::types, "", kAny, "particle types, drawn by weight"),
          field("spacing", &Emitter::spacing, "units", kNonNegative, "a birth per distance moved"),
          field("normalSpeed", &Emitter::normalSpeed, "units/s", kAny,
                "speed along the shape's normal"),
      });
};
template <>
struct Describe<EmitterSpec> {
  static constexpr const char* name = "EmitterSpec";
  static constexpr const char* doc = "The emitters a prime emitter emits, level by level.";
  static constexpr auto fields = std::tuple{
      field("emitter", &EmitterSpec::emitter, "", kAny, "what each spawned emitter emits"),
      field("velocity", &EmitterSpec::velocity, "units/s", kAny, "initial velocity"),
      field("inheritVelocity", &EmitterSpec::inheritVelocity, "", kFinite,
            "fraction of the parent's velocity"),
      field("lifetime", &EmitterSpec::lifetime, "s", kAny, "lifetime"),
      field("acceleration", &EmitterSpec::acceleration, "units/s²", kFinite, "acceleration"),
      field("drag", &EmitterSpec::drag, "1/s", kNonNegative, "linear drag rate"),
      field("deathBurst", &EmitterSpec::deathBurst, "", kAny, "particles emitted at death"),
      field("deathChildren", &EmitterSpec::deathChildren, "", kAny,
            "next-level emitters spawned at death"),
      field("next", &EmitterSpec::next, "", kAny, "the next level"),
  };
};
template <>
struct Describe<PrimeEmitter> {
  static constexpr const char* name = "PrimeEmitter";
  static constexpr const char* doc = "Emits emitters.";
  static constexpr auto fields = std::tuple_cat(
      countingFields<PrimeEmitter>(), std::tuple{
                                          field("child", &PrimeEmitter::child, "", kAny,
                                                "the emitters it emits", "the emitters it emits"),
                                          field("maxEmitters", &PrimeEmitter::maxEmitters, "",
                                                Limit{.min = 1}, "live emitters at most"),
                                      });
};

template <>
struct Describe<DeathEmitter> {
  static constexpr const char* name = "DeathEmitter";
  static constexpr const char* doc =
      "Emits where another group's particles die (a sub-emitter on death), or with \"on\": "
      "\"collision\" where a Bounce deflects them (a sub-emitter on collision).";
  static constexpr auto fields = std::tuple{
      field("name", &DeathEmitter::name, "", kAny, "names it in statistics"),
      field("source", &DeathEmitter::source, "", kAny, "the group whose deaths emit", kRequired),
      field("count", &DeathEmitter::count, "", kAny, "newborns a death (a fraction a chance)"),
      field("inheritVelocity", &DeathEmitter::inheritVelocity, "", kFinite,
            "fraction of the dead particle's velocity"),
      field("shape", &DeathEmitter::shape, "units", kAny, "where, around the death place"),
      field("types", &DeathEmitter::types, "", kAny, "particle types, drawn by weight"),
      field("cause", &DeathEmitter::cause, "", Limit{.min = -1},
            "only deaths by this action of the source's list, or collisions with this Bounce "
            "(-1: all)"),
      field("on", &DeathEmitter::on, "", kAny,
            "what emits: the source's deaths, its collisions (Bounce deflections) or its births"),
  };
};

// ---- domains (mesh and union hold lists: read and written by hand) --------------------------

/// Calls f(std::type_identity<S>{}) for each described domain shape, in Domain::Shape's order.
template <class F>
void forEachDomainKind(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          using S = std::variant_alternative_t<I, Domain::Shape>;
          if constexpr (Described<S>) f(std::type_identity<S>{});
        }(),
        ...);
  }
  (std::make_index_sequence<std::variant_size_v<Domain::Shape>>{});
}

template <>
struct Describe<PointDomain> {
  static constexpr const char* name = "point";
  static constexpr const char* doc = "A point (also written [x, y, z]).";
  static constexpr auto fields =
      std::tuple{field("point", &PointDomain::p, "units", kAny, "the point")};
  static Domain make(const PointDomain& s) { return Domain::point(s.p); }
};
template <>
struct Describe<LineDomain> {
  static constexpr const char* name = "line";
  static constexpr const char* doc = "A line segment.";
  static constexpr auto fields = std::tuple{
      field("p0", &LineDomain::p0, "units", kAny, "one end", kRequired),
      field("p1", &LineDomain::p1, "units", kAny, "the other end", kRequired),
  };
  static Domain make(const LineDomain& s) { return Domain::line(s.p0, s.p1); }
};
template <>
struct Describe<TriangleDomain> {
  static constexpr const char* name = "triangle";
  static constexpr const char* doc = "A triangle.";
  static constexpr auto fields = std::tuple{
      field("p0", &TriangleDomain::p0, "units", kAny, "a corner", kRequired),
      field("p1", &TriangleDomain::p1, "units", kAny, "a corner", kRequired),
      field("p2", &TriangleDomain::p2, "units", kAny, "a corner", kRequired),
  };
  static Domain make(const TriangleDomain& s) { return Domain::triangle(s.p0, s.p1, s.p2); }
};
template <>
struct Describe<PlaneDomain> {
  static constexpr const char* name = "plane";
  static constexpr const char* doc = "An infinite plane.";
  static constexpr auto fields = std::tuple{
      field("point", &PlaneDomain::point, "units", kAny, "a point of the plane"),
      field("normal", &PlaneDomain::normal, "", kNonZero, "its normal", kRequired),
  };
  static Domain make(const PlaneDomain& s) { return Domain::plane(s.point, s.normal); }
};
template <>
struct Describe<RectangleDomain> {
  static constexpr const char* name = "rectangle";
  static constexpr const char* doc = "A parallelogram: origin + s·u + t·v, s and t in [0, 1].";
  static constexpr auto fields = std::tuple{
      field("origin", &RectangleDomain::origin, "units", kAny, "a corner"),
      field("u", &RectangleDomain::u, "units", kAny, "one edge", kRequired),
      field("v", &RectangleDomain::v, "units", kAny, "the other edge", kRequired),
  };
  static Domain make(const RectangleDomain& s) { return Domain::rectangle(s.origin, s.u, s.v); }
};
template <>
struct Describe<DiscDomain> {
  static constexpr const char* name = "disc";
  static constexpr const char* doc = "A disc, or a ring between innerRadius and outerRadius.";
  static constexpr auto fields = std::tuple{
      field("center", &DiscDomain::center, "units", kAny, "its center"),
      field("normal", &DiscDomain::normal, "", kNonZero, "its normal", kRequired),
      field("outerRadius", &DiscDomain::outerRadius, "units", kAny, "its radius", "the radius"),
      field("innerRadius", &DiscDomain::innerRadius, "units", kAny, "a ring's inner radius"),
  };
  static Domain make(const DiscDomain& s) {
    return Domain::disc(s.center, s.normal, s.outerRadius, s.innerRadius);
  }
};
template <>
struct Describe<BoxDomain> {
  static constexpr const char* name = "box";
  static constexpr const char* doc = "An axis-aligned box.";
  static constexpr auto fields = std::tuple{
      field("min", &BoxDomain::min, "units", kAny, "a corner", kRequired),
      field("max", &BoxDomain::max, "units", kAny, "the opposite corner", kRequired),
  };
  static Domain make(const BoxDomain& s) { return Domain::box(s.min, s.max); }
};
template <>
struct Describe<SphereDomain> {
  static constexpr const char* name = "sphere";
  static constexpr const char* doc = "A ball, or a shell between innerRadius and outerRadius.";
  static constexpr auto fields = std::tuple{
      field("center", &SphereDomain::center, "units", kAny, "its center"),
      field("outerRadius", &SphereDomain::outerRadius, "units", kAny, "its radius", "the radius"),
      field("innerRadius", &SphereDomain::innerRadius, "units", kAny, "a shell's inner radius"),
  };
  static Domain make(const SphereDomain& s) {
    return Domain::sphere(s.center, s.outerRadius, s.innerRadius);
  }
};
template <>
struct Describe<CylinderDomain> {
  static constexpr const char* name = "cylinder";
  static constexpr const char* doc = "A solid or hollow cylinder from p0 to p1.";
  static constexpr auto fields = std::tuple{
      field("p0", &CylinderDomain::p0, "units", kAny, "one end's center", kRequired),
      field("p1", &CylinderDomain::p1, "units", kAny, "the other end's center", kRequired),
      field("outerRadius", &CylinderDomain::outerRadius, "units", kAny, "its radius", "the radius"),
      field("innerRadius", &CylinderDomain::innerRadius, "units", kAny, "a tube's inner radius"),
  };
  static Domain make(const CylinderDomain& s) {
    return Domain::cylinder(s.p0, s.p1, s.outerRadius, s.innerRadius);
  }
};
template <>
struct Describe<ConeDomain> {
  static constexpr const char* name = "cone";
  static constexpr const char* doc = "A solid or hollow cone from its apex to its base's center.";
  static constexpr auto fields = std::tuple{
      field("apex", &ConeDomain::apex, "units", kAny, "its apex"),
      field("base", &ConeDomain::base, "units", kAny, "its base's center", kRequired),
      field("outerRadius", &ConeDomain::outerRadius, "units", kAny, "the base's radius",
            "the radius"),
      field("innerRadius", &ConeDomain::innerRadius, "units", kAny, "a hollow cone's inner radius"),
  };
  static Domain make(const ConeDomain& s) {
    return Domain::cone(s.apex, s.base, s.outerRadius, s.innerRadius);
  }
};
template <>
struct Describe<BlobDomain> {
  static constexpr const char* name = "blob";
  static constexpr const char* doc = "A gaussian blob.";
  static constexpr auto fields = std::tuple{
      field("center", &BlobDomain::center, "units", kAny, "its center"),
      field("stddev", &BlobDomain::stddev, "units", kAny, "its standard deviation", kRequired),
  };
  static Domain make(const BlobDomain& s) { return Domain::blob(s.center, s.stddev); }
};

}  // namespace flurry::desc
