#include "transform.hpp"

#include <cmath>
#include <memory>
#include <type_traits>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>

#include "flurry/error.hpp"

namespace flurry {

namespace {

bool finite3(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Rotation only: for velocities, accelerations, directions (a domain of them included).
Transform rotationOf(const Transform& t) {
  return Transform{Vec3(0.0f), t.rotation, 1.0f};
}
/// Rotation and scale: for an offset from a moving point (an emitter's shape).
Transform linearOf(const Transform& t) {
  return Transform{Vec3(0.0f), t.rotation, t.scale};
}

}  // namespace

Transform Transform::fromMatrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) throw InvalidArgument("matrix", "not finite");
  if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
    throw InvalidArgument("matrix", "has a projective row (its last row must be 0 0 0 1)");
  const Vec3 c0(m[0]), c1(m[1]), c2(m[2]);
  const float s = std::cbrt(glm::determinant(glm::mat3(m)));
  if (!(s > 0.0f)) throw InvalidArgument("matrix", "zero scale or a mirror (determinant <= 0)");
  const glm::mat3 r = glm::mat3(c0 / s, c1 / s, c2 / s);
  // Orthonormal up to rounding: no shear, no non-uniform scale.
  const glm::mat3 e = glm::transpose(r) * r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(e[i][j] - (i == j ? 1.0f : 0.0f)) > 1e-4f)
        throw InvalidArgument("matrix",
                              "not a rotation with a uniform scale (shear or "
                              "non-uniform scale)");
  return Transform{Vec3(m[3]), glm::normalize(glm::quat_cast(r)), s};
}

glm::mat4 Transform::matrix() const {
  glm::mat4 m = glm::mat4_cast(rotation) * scale;
  m[3] = glm::vec4(position, 1.0f);
  return m;
}

bool Transform::isIdentity() const {
  return position == Vec3(0.0f) && rotation == glm::quat(1.0f, 0.0f, 0.0f, 0.0f) && scale == 1.0f;
}

void Transform::validate(const std::string& where) const {
  if (!finite3(position)) throw InvalidArgument(where + ".position", "not finite");
  const float n = glm::length(glm::vec4(rotation.x, rotation.y, rotation.z, rotation.w));
  if (!std::isfinite(n) || std::abs(n - 1.0f) > 1e-3f)
    throw InvalidArgument(where + ".rotation",
                          "must be a finite unit quaternion (length " + std::to_string(n) + ")");
  if (!std::isfinite(scale) || !(scale > 0.0f))
    throw InvalidArgument(where + ".scale",
                          "must be finite and > 0 (got " + std::to_string(scale) + ")");
}

Domain Domain::transformed(const Transform& t) const {
  const auto P = [&](Vec3 p) { return t.point(p); };
  const auto L = [&](Vec3 v) { return t.rotation * (t.scale * v); };  // an edge
  const auto N = [&](Vec3 n) { return t.rotation * n; };              // a unit normal
  const float s = t.scale;
  return std::visit(
      [&](const auto& d) -> Domain {
        using T = std::decay_t<decltype(d)>;
        if constexpr (std::is_same_v<T, PointDomain>) {
          return Domain(PointDomain{P(d.p)});
        } else if constexpr (std::is_same_v<T, LineDomain>) {
          return Domain(LineDomain{P(d.p0), P(d.p1)});
        } else if constexpr (std::is_same_v<T, TriangleDomain>) {
          return Domain(TriangleDomain{P(d.p0), P(d.p1), P(d.p2), N(d.normal)});
        } else if constexpr (std::is_same_v<T, PlaneDomain>) {
          return Domain(PlaneDomain{P(d.point), N(d.normal)});
        } else if constexpr (std::is_same_v<T, RectangleDomain>) {
          return Domain(RectangleDomain{P(d.origin), L(d.u), L(d.v), N(d.normal)});
        } else if constexpr (std::is_same_v<T, DiscDomain>) {
          return Domain(DiscDomain{P(d.center), N(d.normal), d.outerRadius * s, d.innerRadius * s});
        } else if constexpr (std::is_same_v<T, BoxDomain>) {
          // Axis-aligned after the turn only if the rotation permutes the axes.
          const glm::mat3 r = glm::mat3_cast(t.rotation);
          for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) {
              const float a = std::abs(r[c][k]);
              if (a > 1e-6f && std::abs(a - 1.0f) > 1e-6f)
                throw InvalidArgument("transform.rotation",
                                      "a box stays axis-aligned: it turns only by quarter turns "
                                      "(use a mesh for a box at another angle)");
            }
          const Vec3 a = P(d.min), b = P(d.max);
          return Domain(BoxDomain{glm::min(a, b), glm::max(a, b)});
        } else if constexpr (std::is_same_v<T, SphereDomain>) {
          return Domain(SphereDomain{P(d.center), d.outerRadius * s, d.innerRadius * s});
        } else if constexpr (std::is_same_v<T, CylinderDomain>) {
          return Domain(CylinderDomain{P(d.p0), P(d.p1), d.outerRadius * s, d.innerRadius * s});
        } else if constexpr (std::is_same_v<T, ConeDomain>) {
          return Domain(ConeDomain{P(d.apex), P(d.base), d.outerRadius * s, d.innerRadius * s});
        } else if constexpr (std::is_same_v<T, BlobDomain>) {
          return Domain(BlobDomain{P(d.center), d.stddev * s});
        } else if constexpr (std::is_same_v<T, MeshDomain>) {
          std::vector<Vec3> v = d.mesh->vertices;
          for (Vec3& p : v) p = P(p);
          return Domain::mesh(std::move(v), d.mesh->triangles);
        } else {
          static_assert(std::is_same_v<T, UnionDomain>);
          std::vector<Domain> parts;
          parts.reserve(d.parts->parts.size());
          for (const Domain& part : d.parts->parts) parts.push_back(part.transformed(t));
          return Domain::unite(std::move(parts));
        }
      },
      shape_);
}

namespace detail {

namespace {

void carry(ParticleType& type, const Transform& t) {
  const Transform r = rotationOf(t);
  type.velocity = type.velocity.transformed(r);
  type.up = type.up.transformed(r);
  type.rotVelocity = type.rotVelocity.transformed(r);
}

template <class E>
void carryMotion(E& e, const Transform& t) {
  e.shape = e.shape.transformed(linearOf(t));
  e.position = t.point(e.position);
  e.velocity = t.direction(e.velocity);
  for (Keyframe& k : e.path) k.position = t.point(k.position);
}

// A prime emitter's children: their emission (shape relative to the moving child, particle
// types) and their launch velocities; their acceleration is a world one, like Gravity. The
// `next` levels are shared with the frame's: each is replaced by a carried copy.
void carrySpec(EmitterSpec& c, const Transform& t) {
  c.emitter.shape = c.emitter.shape.transformed(linearOf(t));
  c.emitter.velocity = t.direction(c.emitter.velocity);
  for (ParticleType& type : c.emitter.types) carry(type, t);
  c.emitter.spacing *= t.scale;
  c.velocity = c.velocity.transformed(rotationOf(t));
  if (c.next) {
    auto n = std::make_shared<EmitterSpec>(*c.next);
    carrySpec(*n, t);
    c.next = std::move(n);
  }
}

// What a transform does to each kind of geometry. The identity leaves every value as it is
// (carried through t, -0 would become +0 and an infinite coordinate NaN).
struct Carrier {
  const Transform& t;
  Transform r;  // the rotation alone
  float s, s2;
  bool identity;
  explicit Carrier(const Transform& tr)
      : t(tr), r(rotationOf(tr)), s(tr.scale), s2(tr.scale * tr.scale), identity(tr.isIdentity()) {}
  Vec3 point(Vec3 p) const { return identity ? p : t.point(p); }
  Vec3 direction(Vec3 v) const { return identity ? v : t.direction(v); }
  float length(float x) const { return identity ? x : x * s; }
  float area(float x) const { return identity ? x : x * s2; }
  Domain place(const Domain& d) const { return identity ? d : d.transformed(t); }
  Domain turn(const Domain& d) const { return identity ? d : d.transformed(r); }
  Falloff falloff(Falloff f) const {
    f.center = point(f.center);
    f.radius = length(f.radius);
    return f;
  }
};

// Writes into w (a copy of l, or l's image under another transform: the same kind) the
// geometry of l's image under c; what has no geometry is left as w has it.
void carryAction(Action& w, const Action& l, const Carrier& c) {
  std::visit(
      [&](auto& x) {
        using T = std::decay_t<decltype(x)>;
        const T& y = std::get<T>(l);
        if constexpr (std::is_same_v<T, Gravity> || std::is_same_v<T, Damping> ||
                      std::is_same_v<T, Turbulence> || std::is_same_v<T, SampledField>) {
          x.falloff = c.falloff(y.falloff);  // world fields; where they act follows
        } else if constexpr (std::is_same_v<T, OrbitPoint>) {
          x.center = c.point(y.center);
          x.epsilon = c.area(y.epsilon);  // a squared length
          x.maxRadius = c.length(y.maxRadius);
        } else if constexpr (std::is_same_v<T, OrbitLine>) {
          x.point = c.point(y.point);
          x.axis = c.direction(y.axis);
          x.epsilon = c.area(y.epsilon);
          x.maxRadius = c.length(y.maxRadius);
        } else if constexpr (std::is_same_v<T, Gravitate> || std::is_same_v<T, Follow> ||
                             std::is_same_v<T, MatchVelocity> ||
                             std::is_same_v<T, MatchRotVelocity>) {
          x.epsilon = c.area(y.epsilon);
          x.maxRadius = c.length(y.maxRadius);
        } else if constexpr (std::is_same_v<T, Vortex>) {
          x.center = c.point(y.center);
          x.axis = c.direction(y.axis);
          x.coreRadius = c.length(y.coreRadius);
          x.maxRadius = c.length(y.maxRadius);
        } else if constexpr (std::is_same_v<T, Jet>) {
          x.center = c.point(y.center);
          x.radius = c.length(y.radius);
          x.acceleration = c.turn(y.acceleration);
        } else if constexpr (std::is_same_v<T, Explosion>) {
          x.center = c.point(y.center);
          x.stddev = c.length(y.stddev);
          x.epsilon = c.area(y.epsilon);
        } else if constexpr (std::is_same_v<T, RandomAccel>) {
          x.acceleration = c.turn(y.acceleration);
          x.falloff = c.falloff(y.falloff);
        } else if constexpr (std::is_same_v<T, RandomDisplace>) {
          x.displacement = c.turn(y.displacement);
        } else if constexpr (std::is_same_v<T, RandomVelocity>) {
          x.velocity = c.turn(y.velocity);
        } else if constexpr (std::is_same_v<T, RandomRotVelocity>) {
          x.rotVelocity = c.turn(y.rotVelocity);
        } else if constexpr (std::is_same_v<T, ElectricField> || std::is_same_v<T, MagneticField>) {
          x.field = c.direction(y.field);
          x.falloff = c.falloff(y.falloff);
        } else if constexpr (std::is_same_v<T, Avoid>) {
          x.obstacle = c.place(y.obstacle);
          x.epsilon = c.area(y.epsilon);
        } else if constexpr (std::is_same_v<T, TargetVelocity>) {
          x.velocity = c.direction(y.velocity);
        } else if constexpr (std::is_same_v<T, TargetRotVelocity>) {
          x.rotVelocity = c.direction(y.rotVelocity);
        } else if constexpr (std::is_same_v<T, Bounce>) {
          x.surface = c.place(y.surface);
          x.planeNormal = c.direction(y.planeNormal);
        } else if constexpr (std::is_same_v<T, Sink> || std::is_same_v<T, Block>) {
          x.region = c.place(y.region);
        } else if constexpr (std::is_same_v<T, SinkVelocity>) {
          x.velocity = c.turn(y.velocity);
        } else if constexpr (std::is_same_v<T, Constrain2D>) {
          x.point = c.point(y.point);
          x.normal = c.direction(y.normal);
        }
        // The rest has no geometry (ages, colours, sizes, speeds, callbacks).
      },
      w);
}

Substeps carrySubsteps(Substeps sub, const Carrier& c) {
  sub.maxDistance = c.length(sub.maxDistance);
  return sub;
}

}  // namespace

/// Gives the library's own code the list's actions to rewrite in place.
struct ActionListAccess {
  static std::vector<Action>& actions(ActionList& list) { return list.actions_; }
};

void carryEmitter(Emitter& e, const Transform& t) {
  carryMotion(e, t);
  for (ParticleType& type : e.types) carry(type, t);
  e.spacing *= t.scale;  // a length travelled
}

void carryPrime(PrimeEmitter& e, const Transform& t) {
  carryMotion(e, t);
  carrySpec(e.child, t);
}

Emitter transformEmitter(const Emitter& e, const Transform& t) {
  Emitter w = e;
  carryEmitter(w, t);
  return w;
}

PrimeEmitter transformPrime(const PrimeEmitter& e, const Transform& t) {
  PrimeEmitter w = e;
  carryPrime(w, t);
  return w;
}

ActionList transformActions(const ActionList& list, const Transform& t) {
  const Carrier c(t);
  ActionList out;
  out.setIntegrator(list.integrator());
  out.setSubsteps(carrySubsteps(list.substeps(), c));
  for (const Action& a : list.actions()) {
    Action w = a;
    carryAction(w, a, c);
    out.add(std::move(w));
  }
  return out;
}

bool placeActions(ActionList& world, const ActionList& local, const Transform& t) {
  std::vector<Action>& w = ActionListAccess::actions(world);
  const std::vector<Action>& l = local.actions();
  if (w.size() != l.size()) return false;
  for (std::size_t k = 0; k < w.size(); ++k)
    if (w[k].index() != l[k].index()) return false;
  const Carrier c(t);
  world.setSubsteps(carrySubsteps(local.substeps(), c));
  world.setIntegrator(local.integrator());
  for (std::size_t k = 0; k < w.size(); ++k) carryAction(w[k], l[k], c);
  return true;
}

}  // namespace detail
}  // namespace flurry
