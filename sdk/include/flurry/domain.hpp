// Domains: the shapes particles are emitted from, deflected by, absorbed in and hidden by.
//
// Every domain can draw a point uniformly from itself (by length, area or volume), say
// whether a point is inside, and give the distance to, the nearest point of, and the unit
// normal at its surface. Shapes are plain structs so that the backends can test whole
// arrays of particles against them in vectorised loops; build them through the Domain
// factories, which validate (a zero-radius sphere, a zero-area triangle, a NaN corner
// throw InvalidArgument naming the parameter) and precompute normals.
#pragma once

#include <cstdint>
#include <memory>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "flurry/math.hpp"
#include "flurry/random.hpp"
#include "flurry/transform.hpp"

namespace flurry {

/// A single point.
struct PointDomain {
  Vec3 p;
};
/// The segment p0-p1.
struct LineDomain {
  Vec3 p0, p1;
};
/// The triangle p0 p1 p2; normal = normalize(cross(p1 - p0, p2 - p0)).
struct TriangleDomain {
  Vec3 p0, p1, p2;
  Vec3 normal;
};
/// The infinite plane through `point` with unit `normal`. "Inside" is the half-space the
/// normal points into (the classic Particle System API's convention); sampling returns
/// `point`, since an infinite plane has no uniform distribution.
struct PlaneDomain {
  Vec3 point;
  Vec3 normal;
};
/// The parallelogram origin + s*u + t*v, s, t in [0, 1]; normal = normalize(cross(u, v)).
struct RectangleDomain {
  Vec3 origin, u, v;
  Vec3 normal;
};
/// The annulus around `center` in the plane of unit `normal`, innerRadius <= r <= outerRadius.
struct DiscDomain {
  Vec3 center, normal;
  float outerRadius, innerRadius;
};
/// The axis-aligned box [min, max].
struct BoxDomain {
  Vec3 min, max;
};
/// The ball of outerRadius around `center`, hollowed to innerRadius. innerRadius == 0: a
/// solid ball; 0 < innerRadius < outerRadius: a thick shell; innerRadius == outerRadius: the
/// sphere's surface alone (sampled on the surface, contains nothing).
struct SphereDomain {
  Vec3 center;
  float outerRadius, innerRadius;
};
/// The cylinder with axis p0-p1, hollowed like SphereDomain (inner == outer: the curved
/// surface alone).
struct CylinderDomain {
  Vec3 p0, p1;
  float outerRadius, innerRadius;
};
/// The cone with its tip at `apex` and a base of outerRadius at `base`, hollowed like
/// SphereDomain (the radii are the base's; inner == outer: the lateral surface alone).
struct ConeDomain {
  Vec3 apex, base;
  float outerRadius, innerRadius;
};
/// A gaussian blob: samples are normally distributed around `center` with standard
/// deviation `stddev` on each axis. contains() is the ball of radius stddev.
struct BlobDomain {
  Vec3 center;
  float stddev;
};

struct MeshData;
struct UnionData;

/// The surface of a polyhedron given as vertices and triangles (a mesh). Samples are uniform
/// over its area; contains() is the inside of the closed surface (ray-crossing parity); the
/// normal is that of the nearest face, oriented by the triangles' winding.
struct MeshDomain {
  std::shared_ptr<const MeshData> mesh;
};

/// A union of domains. Samples pick a part in proportion to its measure (length, area or
/// volume: mix parts of one kind); contains() is true inside any part.
struct UnionDomain {
  std::shared_ptr<const UnionData> parts;
};

class Domain {
 public:
  using Shape = std::variant<PointDomain, LineDomain, TriangleDomain, PlaneDomain, RectangleDomain,
                             DiscDomain, BoxDomain, SphereDomain, CylinderDomain, ConeDomain,
                             BlobDomain, MeshDomain, UnionDomain>;

  Domain() : shape_(PointDomain{Vec3(0.0f)}) {}

  static Domain point(Vec3 p);
  static Domain line(Vec3 p0, Vec3 p1);
  static Domain triangle(Vec3 p0, Vec3 p1, Vec3 p2);
  static Domain plane(Vec3 point, Vec3 normal);
  static Domain rectangle(Vec3 origin, Vec3 u, Vec3 v);
  static Domain disc(Vec3 center, Vec3 normal, float outerRadius, float innerRadius = 0.0f);
  static Domain box(Vec3 corner0, Vec3 corner1);
  static Domain sphere(Vec3 center, float outerRadius, float innerRadius = 0.0f);
  static Domain cylinder(Vec3 p0, Vec3 p1, float outerRadius, float innerRadius = 0.0f);
  static Domain cone(Vec3 apex, Vec3 base, float outerRadius, float innerRadius = 0.0f);
  static Domain blob(Vec3 center, float stddev);
  /// A polyhedron's surface: each triangle is three indices into `vertices`, counter-clockwise
  /// seen from outside (the normal side).
  static Domain mesh(std::vector<Vec3> vertices, std::vector<glm::uvec3> triangles);
  static Domain unite(std::vector<Domain> parts);

  /// A point drawn uniformly from the domain (gaussian for a blob).
  Vec3 sample(Random& rng) const;
  /// Whether p is inside. Points, segments and plane pieces contain nothing (no volume).
  bool contains(Vec3 p) const;
  /// The nearest point of the domain's surface (of the shape itself for points, segments
  /// and plane pieces; of the boundary for solids).
  Vec3 closestPoint(Vec3 p) const;
  /// Euclidean distance from p to closestPoint(p); >= 0.
  float distance(Vec3 p) const { return glm::length(p - closestPoint(p)); }
  /// Unit normal of the surface at closestPoint(p): outward for solids, the given normal for
  /// plane pieces. For a point or a segment, the direction from the shape towards p.
  Vec3 normal(Vec3 p) const;
  /// Length (segments), area (plane pieces, thin shells) or volume (solids); 0 for a point
  /// and for the infinite plane.
  double measure() const;
  /// True for the shapes with a two-sided planar surface: plane, rectangle, disc, triangle.
  bool isPlanar() const;
  /// The domain carried by `t`: its points through t.point, its normals and axes rotated,
  /// its lengths (radii, edges) scaled. A box stays axis-aligned: it turns only by quarter
  /// turns (throws InvalidArgument "transform.rotation" for another rotation).
  Domain transformed(const Transform& t) const;
  /// "sphere", "box", ...: used in error messages and effect files.
  const char* name() const;

  const Shape& shape() const { return shape_; }

 private:
  explicit Domain(Shape s) : shape_(s) {}
  Shape shape_;
};

struct MeshData {
  std::vector<Vec3> vertices;
  std::vector<glm::uvec3> triangles;
  std::vector<Vec3> normals;           ///< per triangle, unit
  std::vector<double> cumulativeArea;  ///< per triangle, running sum: area-weighted sampling
  Vec3 min{0.0f}, max{0.0f};           ///< bounds
};

struct UnionData {
  std::vector<Domain> parts;
  std::vector<double> cumulativeMeasure;  ///< running sum of the parts' measures
};

}  // namespace flurry
