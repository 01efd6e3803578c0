// Domain factories (validation) and the per-shape sampling, nearest-point, normal and measure
// code. Containment lives in shape_math.hpp so that the backends' loops share it.
#include "flurry/domain.hpp"
#include "flurry/fuzzy.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>

#include <glm/common.hpp>

#include "flurry/error.hpp"
#include "sampling.hpp"
#include "shape_math.hpp"

namespace flurry {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kInfinityF = std::numeric_limits<float>::infinity();

// ---- validation --------------------------------------------------------------------------

std::string param(const char* shape, const char* field) {
  return std::string(shape) + "." + field;
}

bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void requireFinite(Vec3 v, const char* shape, const char* field) {
  if (!finite(v)) throw InvalidArgument(param(shape, field), "not finite");
}

void requireFinite(float f, const char* shape, const char* field) {
  if (!std::isfinite(f)) throw InvalidArgument(param(shape, field), "not finite");
}

namespace kern = detail::kernel;  // the domains' math, shared with the OpenCL backend

Vec3 unitOrZero(Vec3 v) {
  return kern::fl_unit_or_zero(v);
}

Vec3 unitOrThrow(Vec3 v, const std::string& parameter) {
  const Vec3 u = unitOrZero(v);
  if (u == Vec3(0.0f)) throw InvalidArgument(parameter, "zero length");
  return u;
}

// b - a, rejected when it overflows (two finite but huge corners).
Vec3 edge(Vec3 a, Vec3 b, const std::string& parameter) {
  const Vec3 d = b - a;
  if (!finite(d)) throw InvalidArgument(parameter, "too large");
  return d;
}

void requireRadii(const char* shape, float outer, float inner) {
  requireFinite(outer, shape, "outerRadius");
  requireFinite(inner, shape, "innerRadius");
  if (!(outer > 0.0f)) throw InvalidArgument(param(shape, "outerRadius"), "must be > 0");
  if (!(inner >= 0.0f)) throw InvalidArgument(param(shape, "innerRadius"), "must be >= 0");
  if (inner > outer) {
    throw InvalidArgument(param(shape, "innerRadius"), "must be <= outerRadius");
  }
}

// Normal of the plane spanned by a and b, computed in double so that the degeneracy test is
// not fooled by float cancellation. Throws when the angle between them is below ~1e-6 rad
// (collinear corners, parallel edges, a zero edge).
Vec3 spanNormal(Vec3 a, Vec3 b, const char* shape) {
  const double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z;
  const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
  const double c = std::sqrt(cx * cx + cy * cy + cz * cz);
  const double la = std::sqrt(ax * ax + ay * ay + az * az);
  const double lb = std::sqrt(bx * bx + by * by + bz * bz);
  if (!(c > 1e-6 * la * lb)) throw InvalidArgument(shape, "zero area");
  return Vec3(float(cx / c), float(cy / c), float(cz / c));
}

// ---- per-shape operations: kernels/domain.h from the shapes' values ------------------------

Vec3 closestShape(const PointDomain& d, Vec3) {
  return d.p;
}
Vec3 closestShape(const LineDomain& d, Vec3 p) {
  return kern::fl_closest_segment(d.p0, d.p1, p);
}
template <class Planar>
requires detail::kPlanarShape<Planar> Vec3 closestShape(const Planar& d, Vec3 p) {
  return detail::closest(d, p);  // (shape_math.hpp: the CPU's planar loops share it)
}
Vec3 closestShape(const BoxDomain& d, Vec3 p) {
  return kern::fl_closest_box(d.min, d.max, p);
}
Vec3 closestShape(const SphereDomain& d, Vec3 p) {
  Vec3 n;
  return kern::fl_closest_ball(d.center, d.outerRadius, d.innerRadius, p, &n);
}
Vec3 closestShape(const BlobDomain& d, Vec3 p) {
  Vec3 n;
  return kern::fl_closest_ball(d.center, d.stddev, 0.0f, p, &n);
}
Vec3 closestShape(const CylinderDomain& d, Vec3 p) {
  return kern::fl_closest_axial(d.p0, d.p1 - d.p0, d.outerRadius, d.innerRadius, 0, p);
}
Vec3 closestShape(const ConeDomain& d, Vec3 p) {
  return kern::fl_closest_axial(d.apex, d.base - d.apex, d.outerRadius, d.innerRadius, 1, p);
}

template <class Shape>
Vec3 normalShape(const Shape& d, Vec3 p) {
  return detail::normal(d, p);  // shape_math.hpp: every shape but a mesh and a union
}

Vec3 closestShape(const MeshDomain& d, Vec3 p) {
  const MeshData& m = *d.mesh;
  Vec3 best = m.vertices[m.triangles[0].x];
  float bestD2 = kInfinityF;
  for (const glm::uvec3& t : m.triangles) {
    const Vec3 c = kern::fl_closest_triangle(m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], p);
    const float d2 = glm::dot(c - p, c - p);
    if (d2 < bestD2) {
      bestD2 = d2;
      best = c;
    }
  }
  return best;
}
Vec3 normalShape(const MeshDomain& d, Vec3 p) {
  const MeshData& m = *d.mesh;
  std::size_t best = 0;
  float bestD2 = kInfinityF;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    const glm::uvec3& t = m.triangles[k];
    const Vec3 c = kern::fl_closest_triangle(m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], p);
    const float d2 = glm::dot(c - p, c - p);
    if (d2 < bestD2) {
      bestD2 = d2;
      best = k;
    }
  }
  return m.normals[best];
}
double measureShape(const MeshDomain& d) {
  return d.mesh->cumulativeArea.back();
}

// The part whose surface is nearest decides a union's closest point and normal.
const Domain& nearestPart(const UnionDomain& d, Vec3 p) {
  const Domain* best = &d.parts->parts.front();
  float bestD = kInfinityF;
  for (const Domain& part : d.parts->parts) {
    const float dist = part.distance(p);
    if (dist < bestD) {
      bestD = dist;
      best = &part;
    }
  }
  return *best;
}
Vec3 closestShape(const UnionDomain& d, Vec3 p) {
  return nearestPart(d, p).closestPoint(p);
}
Vec3 normalShape(const UnionDomain& d, Vec3 p) {
  return nearestPart(d, p).normal(p);
}
double measureShape(const UnionDomain& d) {
  return d.parts->cumulativeMeasure.back();
}

double measureShape(const PointDomain&) {
  return 0.0;
}
double measureShape(const LineDomain& d) {
  return glm::length(d.p1 - d.p0);
}
double measureShape(const TriangleDomain& d) {
  return 0.5 * glm::length(glm::cross(d.p1 - d.p0, d.p2 - d.p0));
}
double measureShape(const PlaneDomain&) {
  return 0.0;
}
double measureShape(const RectangleDomain& d) {
  return glm::length(glm::cross(d.u, d.v));
}
double measureShape(const DiscDomain& d) {
  const double ro = d.outerRadius, ri = d.innerRadius;
  return ri < ro ? kPi * (ro * ro - ri * ri) : 2.0 * kPi * ro;  // inner == outer: a circle
}
double measureShape(const BoxDomain& d) {
  const Vec3 e = d.max - d.min;
  return double(e.x) * e.y * e.z;
}
double measureShape(const SphereDomain& d) {
  const double ro = d.outerRadius, ri = d.innerRadius;
  return ri < ro ? 4.0 / 3.0 * kPi * (ro * ro * ro - ri * ri * ri) : 4.0 * kPi * ro * ro;
}
double measureShape(const CylinderDomain& d) {
  const double ro = d.outerRadius, ri = d.innerRadius, h = glm::length(d.p1 - d.p0);
  return ri < ro ? kPi * h * (ro * ro - ri * ri) : 2.0 * kPi * ro * h;
}
double measureShape(const ConeDomain& d) {
  const double ro = d.outerRadius, ri = d.innerRadius, h = glm::length(d.base - d.apex);
  return ri < ro ? kPi * h * (ro * ro - ri * ri) / 3.0 : kPi * ro * std::sqrt(h * h + ro * ro);
}
double measureShape(const BlobDomain& d) {
  const double s = d.stddev;  // the ball that contains() tests
  return 4.0 / 3.0 * kPi * s * s * s;
}

}  // namespace

// ---- factories -----------------------------------------------------------------------------

Domain Domain::point(Vec3 p) {
  requireFinite(p, "point", "p");
  return Domain(PointDomain{p});
}

Domain Domain::line(Vec3 p0, Vec3 p1) {
  requireFinite(p0, "line", "p0");
  requireFinite(p1, "line", "p1");
  if (unitOrZero(edge(p0, p1, "line")) == Vec3(0.0f)) {
    throw InvalidArgument("line", "zero length");
  }
  return Domain(LineDomain{p0, p1});
}

Domain Domain::triangle(Vec3 p0, Vec3 p1, Vec3 p2) {
  requireFinite(p0, "triangle", "p0");
  requireFinite(p1, "triangle", "p1");
  requireFinite(p2, "triangle", "p2");
  const Vec3 n = spanNormal(edge(p0, p1, "triangle"), edge(p0, p2, "triangle"), "triangle");
  return Domain(TriangleDomain{p0, p1, p2, n});
}

Domain Domain::plane(Vec3 point, Vec3 normal) {
  requireFinite(point, "plane", "point");
  requireFinite(normal, "plane", "normal");
  return Domain(PlaneDomain{point, unitOrThrow(normal, "plane.normal")});
}

Domain Domain::rectangle(Vec3 origin, Vec3 u, Vec3 v) {
  requireFinite(origin, "rectangle", "origin");
  requireFinite(u, "rectangle", "u");
  requireFinite(v, "rectangle", "v");
  const Vec3 n = spanNormal(u, v, "rectangle");
  edge(origin, origin + u + v, "rectangle");  // the far corner must be representable
  return Domain(RectangleDomain{origin, u, v, n});
}

Domain Domain::disc(Vec3 center, Vec3 normal, float outerRadius, float innerRadius) {
  requireFinite(center, "disc", "center");
  requireFinite(normal, "disc", "normal");
  requireRadii("disc", outerRadius, innerRadius);
  const Vec3 n = unitOrThrow(normal, "disc.normal");
  return Domain(DiscDomain{center, n, outerRadius, innerRadius});
}

Domain Domain::box(Vec3 corner0, Vec3 corner1) {
  requireFinite(corner0, "box", "corner0");
  requireFinite(corner1, "box", "corner1");
  const Vec3 lo = glm::min(corner0, corner1), hi = glm::max(corner0, corner1);
  const Vec3 e = edge(lo, hi, "box");
  if (!(e.x > 0.0f && e.y > 0.0f && e.z > 0.0f)) throw InvalidArgument("box", "zero volume");
  return Domain(BoxDomain{lo, hi});
}

Domain Domain::sphere(Vec3 center, float outerRadius, float innerRadius) {
  requireFinite(center, "sphere", "center");
  requireRadii("sphere", outerRadius, innerRadius);
  return Domain(SphereDomain{center, outerRadius, innerRadius});
}

Domain Domain::cylinder(Vec3 p0, Vec3 p1, float outerRadius, float innerRadius) {
  requireFinite(p0, "cylinder", "p0");
  requireFinite(p1, "cylinder", "p1");
  requireRadii("cylinder", outerRadius, innerRadius);
  unitOrThrow(edge(p0, p1, "cylinder.axis"), "cylinder.axis");
  return Domain(CylinderDomain{p0, p1, outerRadius, innerRadius});
}

Domain Domain::cone(Vec3 apex, Vec3 base, float outerRadius, float innerRadius) {
  requireFinite(apex, "cone", "apex");
  requireFinite(base, "cone", "base");
  requireRadii("cone", outerRadius, innerRadius);
  unitOrThrow(edge(apex, base, "cone.axis"), "cone.axis");
  return Domain(ConeDomain{apex, base, outerRadius, innerRadius});
}

Domain Domain::blob(Vec3 center, float stddev) {
  requireFinite(center, "blob", "center");
  requireFinite(stddev, "blob", "stddev");
  if (!(stddev > 0.0f)) throw InvalidArgument("blob.stddev", "must be > 0");
  return Domain(BlobDomain{center, stddev});
}

// ---- queries -------------------------------------------------------------------------------

Domain Domain::mesh(std::vector<Vec3> vertices, std::vector<glm::uvec3> triangles) {
  if (triangles.empty())
    throw InvalidArgument("mesh.triangles", "a mesh needs at least one triangle");
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!finite(vertices[i]))
      throw InvalidArgument("mesh.vertices[" + std::to_string(i) + "]", "not finite");
  auto data = std::make_shared<MeshData>();
  data->normals.reserve(triangles.size());
  data->cumulativeArea.reserve(triangles.size());
  double area = 0;
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const glm::uvec3 t = triangles[k];
    const std::string where = "mesh.triangles[" + std::to_string(k) + "]";
    if (t.x >= vertices.size() || t.y >= vertices.size() || t.z >= vertices.size())
      throw InvalidArgument(
          where, "vertex index out of range (" + std::to_string(vertices.size()) + " vertices)");
    const Vec3 a = vertices[t.x], b = vertices[t.y], c = vertices[t.z];
    data->normals.push_back(spanNormal(b - a, c - a, where.c_str()));
    area += 0.5 * double(glm::length(glm::cross(b - a, c - a)));
    data->cumulativeArea.push_back(area);
  }
  data->min = data->max = vertices[triangles[0].x];
  for (const glm::uvec3& t : triangles)
    for (unsigned v : {t.x, t.y, t.z}) {
      data->min = glm::min(data->min, vertices[v]);
      data->max = glm::max(data->max, vertices[v]);
    }
  data->vertices = std::move(vertices);
  data->triangles = std::move(triangles);
  return Domain(MeshDomain{std::move(data)});
}

Domain Domain::unite(std::vector<Domain> parts) {
  if (parts.empty()) throw InvalidArgument("union.parts", "a union needs at least one part");
  auto data = std::make_shared<UnionData>();
  double total = 0;
  for (const Domain& part : parts) {
    total += part.measure();
    data->cumulativeMeasure.push_back(total);
  }
  if (!(total > 0)) {  // points, or infinite planes: pick parts equally often
    for (std::size_t i = 0; i < parts.size(); ++i) data->cumulativeMeasure[i] = double(i + 1);
  }
  data->parts = std::move(parts);
  Domain d(UnionDomain{std::move(data)});
  if (detail::drawCount(d) > detail::kMaxDomainDraws)
    throw InvalidArgument("union.parts", "unions nested too deeply to sample");
  return d;
}

namespace detail {

bool inside(const MeshDomain& d, Vec3 p) {
  const MeshData& m = *d.mesh;
  if (kern::fl_outside_bounds(m.min, m.max, p)) return false;
  const Vec3 dir = kern::fl_mesh_ray();
  int crossings = 0;
  for (const glm::uvec3& t : m.triangles)
    crossings += kern::fl_ray_crosses(dir, m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], p);
  return (crossings & 1) != 0;
}

bool inside(const UnionDomain& d, Vec3 p) {
  for (const Domain& part : d.parts->parts)
    if (part.contains(p)) return true;
  return false;
}

}  // namespace detail

float detail::standardNormal(float ua, float ub) noexcept {
  return kern::fl_normal_from(ua, ub);
}

// The reserved streams, named once for both backends in kernels/philox.h.
static_assert(stream::kEmission == FL_STREAM_EMISSION);
static_assert(stream::kEmitterEvent == FL_STREAM_EMITTER_EVENT);
static_assert(stream::kPassThrough == FL_STREAM_PASS_THROUGH);
static_assert(stream::kDeathEmitter == FL_STREAM_DEATH_EMITTER);

Philox4x32::Block Philox4x32::generate(std::uint32_t c0, std::uint32_t c1, std::uint32_t c2,
                                       std::uint32_t c3, std::uint32_t k0,
                                       std::uint32_t k1) noexcept {
  kern::fl_philox_rounds(&c0, &c1, &c2, &c3, k0, k1);
  return {{c0, c1, c2, c3}};
}

float uniformFloat(std::uint32_t bits) noexcept {
  return kern::fl_uniform_bits(bits);
}

float Fuzzy::sample(Random& rng) const {
  if (spread == 0.0f) return center;
  const float ua = rng.uniform();
  if (distribution == Distribution::Normal)
    return kern::fl_fuzzy_normal(center, spread, ua, rng.uniform());
  return kern::fl_fuzzy_uniform(center, spread, ua);
}

Vec3 Domain::sample(Random& rng) const {
  // A batch of one through the emitters' batch samplers: the same formulas either way.
  float u[detail::kMaxDomainDraws];
  const float* rows[detail::kMaxDomainDraws];
  const int k = detail::drawCount(*this);
  for (int j = 0; j < k; ++j) {
    u[j] = rng.uniform();
    rows[j] = &u[j];
  }
  float x, y, z;
  detail::sampleBatch(*this, rows, 1, &x, &y, &z);
  return {x, y, z};
}

bool Domain::contains(Vec3 p) const {
  return std::visit([&](const auto& s) { return detail::inside(s, p); }, shape_);
}

Vec3 Domain::closestPoint(Vec3 p) const {
  return std::visit([&](const auto& s) { return closestShape(s, p); }, shape_);
}

Vec3 Domain::normal(Vec3 p) const {
  return std::visit([&](const auto& s) { return normalShape(s, p); }, shape_);
}

double Domain::measure() const {
  return std::visit([](const auto& s) { return measureShape(s); }, shape_);
}

bool Domain::isPlanar() const {
  return std::holds_alternative<PlaneDomain>(shape_) ||
         std::holds_alternative<RectangleDomain>(shape_) ||
         std::holds_alternative<DiscDomain>(shape_) ||
         std::holds_alternative<TriangleDomain>(shape_);
}

const char* Domain::name() const {
  // In the order of Domain::Shape's alternatives.
  static constexpr const char* kNames[] = {"point", "line", "triangle", "plane",    "rectangle",
                                           "disc",  "box",  "sphere",   "cylinder", "cone",
                                           "blob",  "mesh", "union"};
  static_assert(std::size(kNames) == std::variant_size_v<Shape>);
  return kNames[shape_.index()];
}

}  // namespace flurry
