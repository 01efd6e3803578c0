// Emitters: invisible sources that create particles at a rate and in bursts, from a shape,
// moving along a path; each emits one or more particle types with fuzzy attributes.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "flurry/domain.hpp"
#include "flurry/fuzzy.hpp"

namespace flurry {

/// One kind of particle an emitter creates. Vector attributes are drawn from domains
/// (a point domain gives a constant), scalars from fuzzy values.
struct ParticleType {
  float weight = 1.0f;                          ///< relative share of this type
  Domain velocity = Domain::point(Vec3(0.0f));  ///< initial velocity, units/s
  Domain color = Domain::point(Vec3(1.0f));     ///< rgb
  Fuzzy alpha = 1.0f;
  Fuzzy size = 0.05f;  ///< radius, scene units
  Fuzzy mass = 1.0f;
  Fuzzy lifetime =
      5.0f;  ///< seconds (the seed's "60 frames ± 25%" is Fuzzy::percent(2, 25) at 30 fps)
  Fuzzy charge = 0.0f;
  Domain up = Domain::point(Vec3(0.0f, 1.0f, 0.0f));
  Domain rotVelocity = Domain::point(Vec3(0.0f));
};

/// `count` particles at `time`, repeated `repeat` times every `interval` seconds. A step
/// finds its occurrences arithmetically: any `repeat` (up to 2^32 - 1, "forever") costs the
/// same per step.
struct Burst {
  double time = 0.0;
  std::uint32_t count = 0;
  double interval = 0.0;
  std::uint32_t repeat = 1;
};

/// A keyframe of an emitter's path; positions are interpolated linearly between keys.
/// Before the first key the emitter stays at it; after the last it stays there too, or, with
/// the emitter's `pathLoop`, the path repeats: time wraps to the first key's time, every
/// `last.time - first.time` seconds. A closed loop repeats the first key's position last.
struct Keyframe {
  double time = 0.0;
  Vec3 position{0.0f};
};

struct Emitter {
  std::string name;
  /// Where particles are born, relative to the emitter's current position.
  Domain shape = Domain::point(Vec3(0.0f));
  /// Particles per second. Fractional rates are exact over time: 10.5/s for 10 s gives 105
  /// (exact up to 2^53 births since `start`). A step asking for more than the group holds
  /// fills it and counts the rest as GroupStats::droppedAtCapacity, up to 2^40 a step.
  double rate = 0.0;
  std::vector<Burst> bursts;
  /// The emitter's position at time `start`; it then moves at `velocity`, or follows `path`
  /// when that is not empty. A particle born inside a step starts where the emitter was at
  /// its birth time and runs the action list for the rest of the step, so a moving emitter
  /// leaves an even trail at any frame rate.
  Vec3 position{0.0f};
  Vec3 velocity{0.0f};
  std::vector<Keyframe> path;
  /// After the path's last key, start it again from the first (needs two keys or more).
  bool pathLoop = false;
  double start = 0.0;
  double stop = std::numeric_limits<double>::infinity();
  std::vector<ParticleType> types{ParticleType{}};
  /// Emission by distance: one particle per `spacing` units the emitter travels, with birth
  /// times and places interpolated inside the step, so a fast emitter leaves an even trail
  /// with no gaps. 0 turns it off. Adds to `rate` and `bursts`. A spacing so small that a
  /// step asks for more births than the group holds fills the group from the start of the
  /// step's path, and counts the rest as dropped (up to 2^40 a step).
  float spacing = 0.0f;
  /// Adds the shape's outward normal where each particle is born, times this speed, to its
  /// velocity: every face of a polyhedron (Domain::mesh) emits along its normal, each
  /// particle along that of the face it was born on (of a union, the part it was born on).
  Fuzzy normalSpeed = 0.0f;

  /// The emitter's position at time t (seconds).
  Vec3 positionAt(double t) const;
  /// Throws InvalidArgument naming the field (prefixed by `where`, e.g. "emitters[2]").
  void validate(const std::string& where = "emitter") const;
};

/// What a prime emitter creates: emitters that move (initial velocity, gravity, drag), live
/// a fuzzy time, emit their own particles as `emitter` describes (its shape relative to the
/// moving emitter, its rate, its bursts timed from its birth, its spacing), and at death burst
/// `deathBurst` particles and spawn `deathChildren` emitters of the next level: showers of
/// showers, as deep as the chain of `next` goes.
struct EmitterSpec {
  Emitter emitter;
  Domain velocity = Domain::sphere(Vec3(0.0f), 5.0f);  ///< a spawned emitter's initial velocity
  float inheritVelocity = 0.0f;  ///< plus this fraction of its parent's velocity
  Fuzzy lifetime = 1.0f;
  Vec3 acceleration{0.0f, -9.81f, 0.0f};
  float drag = 0.0f;  ///< linear drag rate, 1/s
  std::uint32_t deathBurst = 0;
  std::uint32_t deathChildren = 0;
  std::shared_ptr<const EmitterSpec> next;

  void validate(const std::string& where) const;
};

/// An emitter that emits emitters (the seed's "prime" or "super" emitter). It moves and
/// counts like an Emitter; each birth is an emitter of `child`.
///
/// Like a group's particles, its live emitters have a capacity: at most `maxEmitters` of
/// them (its children and all their descendants, every level together) live at once. A
/// spawn past it (by rate, burst or `deathChildren`) is dropped and counted in
/// GroupStats::emittersDropped. A dying emitter keeps its place until the end of the step
/// it dies in, so its `deathChildren` need room beside it.
struct PrimeEmitter {
  std::string name;
  Domain shape = Domain::point(Vec3(0.0f));
  double rate = 0.0;
  std::vector<Burst> bursts;
  Vec3 position{0.0f};
  Vec3 velocity{0.0f};
  std::vector<Keyframe> path;
  bool pathLoop = false;  ///< as Emitter::pathLoop
  double start = 0.0;
  double stop = std::numeric_limits<double>::infinity();
  EmitterSpec child;
  /// The most live emitters this prime emitter's showers hold at once (>= 1). Their storage
  /// grows as they spawn, never past the group's primes' maxEmitters together.
  std::uint32_t maxEmitters = 4096;

  Vec3 positionAt(double t) const;
  void validate(const std::string& where = "primeEmitter") const;
};

/// Emits particles where another group's particles die: a sub-emitter on death (a rocket's
/// burst of sparks, a raindrop's splash where it hit the floor). After each step, every death
/// the `source` group had in it (by age or by an absorber: see Group::deaths; one for a NaN
/// has no place and gives none) gives
/// `count` newborns to the group holding this emitter. They are born at the end of that step,
/// at the dead particle's place plus a sample of `shape`, with a type's velocity plus
/// `inheritVelocity` times the dead particle's, and age 0: the next step runs them through
/// the whole action list. Deaths are taken in the source's particle order and the newborns
/// written in that order, so the result is the same on any thread count. `shape` and the
/// types' domains are in the world's frame, as Gravity is: a splash rises whichever way an
/// instance turns. Both backends run them (the host makes the newborns and a device takes only
/// those; a device context refuses them for a group in hair mode).
///
/// With `on` = Trigger::Collision it emits where the source's particles are deflected by a
/// Bounce instead (a sub-emitter on collision: sparks where a grinder's chips hit a wall):
/// each deflection (see Group::collisions) gives `count` newborns at the point of impact, with
/// `inheritVelocity` times the velocity the particle arrived with; `cause` is then the index
/// of a Bounce in the source's list (-1: all its Bounces).
///
/// With `on` = Trigger::Birth it emits where the source's emitters give birth (a sub-emitter
/// on birth: a muzzle flash for each tracer, a puff where each spark leaves the wheel): each
/// newborn of the source gives `count` newborns at the place it was born, with
/// `inheritVelocity` times its velocity at birth; `cause` must be -1 (a birth has none).
struct DeathEmitter {
  /// What of the source's particles emits.
  enum class Trigger { Death, Collision, Birth };
  std::string name;
  /// The group whose deaths emit, by name (it may be this group); it must exist when the
  /// context steps, which records its deaths from then on (all of them: room for its
  /// capacity).
  std::string source;
  /// Newborns a death gives; a fraction is a chance (2.5: two, and a third half the time).
  Fuzzy count = 1.0f;
  float inheritVelocity = 0.0f;  ///< this fraction of the dead particle's velocity is added
  Domain shape = Domain::point(Vec3(0.0f));  ///< where around the death place they are born
  std::vector<ParticleType> types{ParticleType{}};
  /// Only deaths by this entry of the source's action list (e.g. its Sink on the floor);
  /// -1: every death.
  std::int32_t cause = -1;
  Trigger on = Trigger::Death;

  void validate(const std::string& where = "deathEmitter") const;
};

}  // namespace flurry
