// Emitters: invisible sources that create particles at a rate and in bursts, from a shape,
// moving along a path; each emits one or more particle types with fuzzy attributes.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "flurry/domain.hpp"
#include "flurry/fuzzy.hpp"

namespace flurry {

/// One kind of particle an emitter creates. Vector attributes are drawn from domains
/// (a point domain gives a constant), scalars from fuzzy values.
struct ParticleType {
  float weight = 1.0f;                         ///< relative share of this type
  Domain velocity = Domain::point(Vec3(0.0f));  ///< initial velocity, units/s
  Domain color = Domain::point(Vec3(1.0f));     ///< rgb
  Fuzzy alpha = 1.0f;
  Fuzzy size = 0.05f;     ///< radius, scene units
  Fuzzy mass = 1.0f;
  Fuzzy lifetime = 5.0f;  ///< seconds (the seed's "60 frames ± 25%" is Fuzzy::percent(2, 25) at 30 fps)
  Fuzzy charge = 0.0f;
  Domain up = Domain::point(Vec3(0.0f, 1.0f, 0.0f));
  Domain rotVelocity = Domain::point(Vec3(0.0f));
};

/// `count` particles at `time`, repeated `repeat` times every `interval` seconds.
struct Burst {
  double time = 0.0;
  std::uint32_t count = 0;
  double interval = 0.0;
  std::uint32_t repeat = 1;
};

/// A keyframe of an emitter's path; positions are interpolated linearly between keys.
struct Keyframe {
  double time = 0.0;
  Vec3 position{0.0f};
};

struct Emitter {
  std::string name;
  /// Where particles are born, relative to the emitter's current position.
  Domain shape = Domain::point(Vec3(0.0f));
  /// Particles per second. Fractional rates are exact over time: 10.5/s for 10 s gives 105.
  double rate = 0.0;
  std::vector<Burst> bursts;
  /// The emitter's position at time `start`; it then moves at `velocity`, or follows `path`
  /// when that is not empty. A particle born inside a step is placed where the emitter was
  /// at its birth time and aged by the rest of the step, so a moving emitter leaves an even
  /// trail at any frame rate.
  Vec3 position{0.0f};
  Vec3 velocity{0.0f};
  std::vector<Keyframe> path;
  double start = 0.0;
  double stop = std::numeric_limits<double>::infinity();
  std::vector<ParticleType> types{ParticleType{}};

  /// The emitter's position at time t (seconds).
  Vec3 positionAt(double t) const;
  /// Throws InvalidArgument naming the field (prefixed by `where`, e.g. "emitters[2]").
  void validate(const std::string& where = "emitter") const;
};

}  // namespace flurry
