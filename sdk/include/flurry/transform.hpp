// Transforms: where an effect instance (its groups) stands in the world.
#pragma once

#include <string>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include "flurry/math.hpp"

namespace flurry {

/// A similarity transform: scale, then rotate, then translate (world = position +
/// rotation·(scale·local)). The scale is uniform so that every domain keeps its kind under it
/// (a sphere stays a sphere; a non-uniform scale would make it an ellipsoid, which no domain
/// describes).
///
/// What follows an instance's transform: positions, points, normals, axes and lengths of its
/// emitters and actions (shapes, paths, deflectors, absorbers, blockers, force centres, axes
/// and radii). Velocities, accelerations and directions of fields are rotated but not scaled
/// (a scaled instance's particles are born with the rotated speeds of the effect); Gravity,
/// Damping's per-axis rates, Turbulence's noise and SampledField's grid stay in the world
/// (their falloffs follow).
struct Transform {
  Vec3 position{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  ///< unit (normalised by validate's users)
  float scale = 1.0f;

  /// The transform of a matrix made of a translation, a rotation and a uniform scale; throws
  /// InvalidArgument "matrix" for anything else (shear, non-uniform scale, projection).
  static Transform fromMatrix(const glm::mat4& m);
  glm::mat4 matrix() const;
  /// Whether it is exactly the identity (an instance with it runs bitwise as one without).
  bool isIdentity() const;
  /// A point from the instance's frame to the world.
  Vec3 point(Vec3 p) const { return position + rotation * (scale * p); }
  /// A direction or velocity: rotated only.
  Vec3 direction(Vec3 v) const { return rotation * v; }
  /// Throws InvalidArgument naming the field ("transform.position", "transform.rotation",
  /// "transform.scale", prefixed by `where`'s "transform") for a non-finite position, a
  /// rotation that is not finite or of length far from 1 (it is used normalised), or a scale
  /// that is not finite and > 0.
  void validate(const std::string& where = "transform") const;
};

/// Where an effect's particles live (the effect file's "space").
enum class Space {
  /// Particles, once born, stay where they are when the instance moves; new births and the
  /// action list's geometry follow the instance.
  World,
  /// Particles move with the instance: a transform change carries the live particles
  /// (positions, velocities and the other vector attributes) rigidly with it.
  Local,
};

}  // namespace flurry
