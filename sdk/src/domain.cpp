// Domain factories (validation) and the per-shape sampling, nearest-point, normal and measure
// code. Containment lives in shape_math.hpp so that the backends' loops share it.
#include "flurry/domain.hpp"

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

// Unit vector along v, or zero for a zero vector. Dividing by the largest component first keeps
// huge and tiny (denormal) vectors from overflowing or underflowing in the dot product.
Vec3 unitOrZero(Vec3 v) {
  const float m = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (!(m > 0.0f)) return Vec3(0.0f);
  return glm::normalize(v / m);
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

// ---- geometry helpers --------------------------------------------------------------------

// Two unit vectors completing unit n to an orthonormal basis (Duff et al., JCGT 2017):
// branch-free apart from the sign, and stable for every n.
void basis(Vec3 n, Vec3& b1, Vec3& b2) {
  const float s = std::copysign(1.0f, n.z);
  const float a = -1.0f / (s + n.z);
  const float b = n.x * n.y * a;
  b1 = Vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = Vec3(b, s + n.y * n.y * a, -n.y);
}

Vec3 anyPerpendicular(Vec3 n) {
  Vec3 b1, b2;
  basis(n, b1, b2);
  return b1;
}

Vec3 closestOnSegment(Vec3 a, Vec3 b, Vec3 p) {
  const Vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + ab * t;
}

// Ericson, Real-Time Collision Detection, 5.1.5: classify p against the Voronoi regions of
// the vertices and edges, otherwise project onto the face.
Vec3 closestOnTriangle(Vec3 a, Vec3 b, Vec3 c, Vec3 p) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return a;
  const Vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const float denom = 1.0f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Radius of a point drawn uniformly by area from the annulus ri <= r <= ro (double: r² and
// r³ of large radii would overflow or lose bits in float).
// Cylinders and cones are surfaces of revolution: the nearest point lies in the half-plane
// through the axis and p, so the problem reduces to 2-D coordinates (a along the axis, rho
// away from it) and the shape to a few boundary segments, each with its outward normal.
struct AxialFrame {
  Vec3 origin, w, e;  // w: unit axis; e: unit radial direction towards p
  float length;       // of the axis
  float a, rho;       // p's coordinates
};

AxialFrame axialFrame(Vec3 origin, Vec3 tip, Vec3 p) {
  AxialFrame f;
  f.origin = origin;
  const Vec3 axis = tip - origin;
  f.length = glm::length(axis);
  f.w = axis / f.length;
  const Vec3 d = p - origin;
  f.a = glm::dot(d, f.w);
  const Vec3 radial = d - f.w * f.a;
  f.e = unitOrZero(radial);
  if (f.e == Vec3(0.0f)) f.e = anyPerpendicular(f.w);  // on the axis: any azimuth will do
  f.rho = glm::dot(radial, f.e);
  return f;
}

struct Hit2 {
  float a = 0.0f, rho = 0.0f;    // nearest boundary point
  float na = 0.0f, nrho = 0.0f;  // outward unit normal of its segment
  float dist2 = std::numeric_limits<float>::infinity();
};

void segment2(const AxialFrame& f, float a0, float r0, float a1, float r1, float na, float nr,
              Hit2& best) {
  const float da = a1 - a0, dr = r1 - r0;
  const float len2 = da * da + dr * dr;
  float t = len2 > 0.0f ? ((f.a - a0) * da + (f.rho - r0) * dr) / len2 : 0.0f;
  t = std::clamp(t, 0.0f, 1.0f);
  const float ca = a0 + da * t, cr = r0 + dr * t;
  const float d2 = (f.a - ca) * (f.a - ca) + (f.rho - cr) * (f.rho - cr);
  if (d2 < best.dist2) best = Hit2{ca, cr, na, nr, d2};
}

Hit2 nearestCylinder(const CylinderDomain& d, const AxialFrame& f) {
  const float L = f.length, ro = d.outerRadius, ri = d.innerRadius;
  Hit2 h;
  segment2(f, 0.0f, ro, L, ro, 0.0f, 1.0f, h);
  if (ri < ro) {  // a solid or a thick shell has caps; the curved surface alone has none
    segment2(f, 0.0f, ri, 0.0f, ro, -1.0f, 0.0f, h);
    segment2(f, L, ri, L, ro, 1.0f, 0.0f, h);
    if (ri > 0.0f) segment2(f, 0.0f, ri, L, ri, 0.0f, -1.0f, h);
  }
  return h;
}

Hit2 nearestCone(const ConeDomain& d, const AxialFrame& f) {
  const float L = f.length, ro = d.outerRadius, ri = d.innerRadius;
  Hit2 h;
  const float so = std::sqrt(L * L + ro * ro);
  segment2(f, 0.0f, 0.0f, L, ro, -ro / so, L / so, h);
  if (ri < ro) {
    segment2(f, L, ri, L, ro, 1.0f, 0.0f, h);
    if (ri > 0.0f) {
      const float si = std::sqrt(L * L + ri * ri);
      segment2(f, 0.0f, 0.0f, L, ri, ri / si, -L / si, h);
    }
  }
  return h;
}

Vec3 toWorld(const AxialFrame& f, float a, float rho) {
  return f.origin + f.w * a + f.e * rho;
}

// Outward normal of a solid at its nearest boundary point c. Outside the solid (by more than
// rounding) it is the direction from c to p, which is the face normal on a face and the
// distance field's gradient at an edge or corner; inside, and on the surface, it is the
// nearest face's normal.
Vec3 solidNormal(bool inside, Vec3 p, Vec3 c, Vec3 faceNormal, float scale) {
  if (!inside && glm::length(p - c) > 1e-5f * scale) return unitOrZero(p - c);
  return faceNormal;
}

// ---- per-shape operations ----------------------------------------------------------------

Vec3 closestShape(const PointDomain& d, Vec3) {
  return d.p;
}
Vec3 closestShape(const LineDomain& d, Vec3 p) {
  return closestOnSegment(d.p0, d.p1, p);
}
Vec3 closestShape(const TriangleDomain& d, Vec3 p) {
  return closestOnTriangle(d.p0, d.p1, d.p2, p);
}
Vec3 closestShape(const PlaneDomain& d, Vec3 p) {
  return p - d.normal * glm::dot(p - d.point, d.normal);
}
Vec3 closestShape(const RectangleDomain& d, Vec3 p) {
  // Coordinates of p's projection in the (possibly skewed) basis u, v: the normal equations
  // of the 2x2 least-squares problem. |u x v|² is their determinant without cancellation.
  const Vec3 r = p - d.origin;
  const float uu = glm::dot(d.u, d.u), uv = glm::dot(d.u, d.v), vv = glm::dot(d.v, d.v);
  const float ru = glm::dot(r, d.u), rv = glm::dot(r, d.v);
  const Vec3 c = glm::cross(d.u, d.v);
  const float det = glm::dot(c, c);
  const float s = (vv * ru - uv * rv) / det, t = (uu * rv - uv * ru) / det;
  if (s >= 0.0f && s <= 1.0f && t >= 0.0f && t <= 1.0f) return d.origin + d.u * s + d.v * t;
  // Outside: clamping s and t separately is wrong for skewed edges; the nearest point of a
  // convex polygon to an outside point lies on its boundary.
  const Vec3 a = d.origin, b = d.origin + d.u, cc = d.origin + d.u + d.v, e = d.origin + d.v;
  Vec3 best = closestOnSegment(a, b, p);
  float bestD2 = glm::dot(p - best, p - best);
  for (const Vec3 q :
       {closestOnSegment(b, cc, p), closestOnSegment(cc, e, p), closestOnSegment(e, a, p)}) {
    const float d2 = glm::dot(p - q, p - q);
    if (d2 < bestD2) bestD2 = d2, best = q;
  }
  return best;
}
Vec3 closestShape(const DiscDomain& d, Vec3 p) {
  const Vec3 r = p - d.center;
  const Vec3 inPlane = r - d.normal * glm::dot(r, d.normal);
  Vec3 dir = unitOrZero(inPlane);
  if (dir == Vec3(0.0f)) {
    if (d.innerRadius == 0.0f) return d.center;
    dir = anyPerpendicular(d.normal);  // on the axis of a ring: every rim point is as near
  }
  const float rho = std::clamp(glm::dot(inPlane, dir), d.innerRadius, d.outerRadius);
  return d.center + dir * rho;
}

// Box: the face (axis*2 + side) whose plane is nearest, by signed inside-distance; for an
// outside point it is the most violated face.
int nearestBoxFace(const BoxDomain& d, Vec3 p, float& dist) {
  int face = 0;
  dist = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 3; ++i) {
    const float lo = p[i] - d.min[i], hi = d.max[i] - p[i];
    if (lo < dist) dist = lo, face = 2 * i;
    if (hi < dist) dist = hi, face = 2 * i + 1;
  }
  return face;
}
Vec3 closestShape(const BoxDomain& d, Vec3 p) {
  if (!detail::inside(d, p)) return glm::clamp(p, d.min, d.max);
  float dist;
  const int face = nearestBoxFace(d, p, dist);
  Vec3 c = p;
  c[face / 2] = (face & 1) ? d.max[face / 2] : d.min[face / 2];
  return c;
}
Vec3 boxNormal(const BoxDomain& d, Vec3 p) {
  float dist;
  const int face = nearestBoxFace(d, p, dist);
  Vec3 n(0.0f);
  n[face / 2] = (face & 1) ? 1.0f : -1.0f;
  return solidNormal(detail::inside(d, p), p, glm::clamp(p, d.min, d.max), n,
                     glm::length(d.max - d.min));
}

// Ball of `outer` hollowed to `inner` (inner == 0: solid; inner == outer: the surface alone).
// Returns the nearest point and sets n to the outward normal there.
Vec3 closestBall(Vec3 center, float outer, float inner, Vec3 p, Vec3& n) {
  const Vec3 r = p - center;
  Vec3 dir = unitOrZero(r);
  if (dir == Vec3(0.0f)) dir = Vec3(1.0f, 0.0f, 0.0f);  // at the center: any direction
  const bool toInner = inner > 0.0f && inner < outer && glm::length(r) < 0.5f * (inner + outer);
  n = toInner ? -dir : dir;
  return center + dir * (toInner ? inner : outer);
}
Vec3 closestShape(const SphereDomain& d, Vec3 p) {
  Vec3 n;
  return closestBall(d.center, d.outerRadius, d.innerRadius, p, n);
}
Vec3 closestShape(const BlobDomain& d, Vec3 p) {
  Vec3 n;
  return closestBall(d.center, d.stddev, 0.0f, p, n);
}
Vec3 closestShape(const CylinderDomain& d, Vec3 p) {
  const AxialFrame f = axialFrame(d.p0, d.p1, p);
  const Hit2 h = nearestCylinder(d, f);
  return toWorld(f, h.a, h.rho);
}
Vec3 closestShape(const ConeDomain& d, Vec3 p) {
  const AxialFrame f = axialFrame(d.apex, d.base, p);
  const Hit2 h = nearestCone(d, f);
  return toWorld(f, h.a, h.rho);
}

Vec3 normalShape(const PointDomain& d, Vec3 p) {
  const Vec3 n = unitOrZero(p - d.p);
  return n == Vec3(0.0f) ? Vec3(0.0f, 1.0f, 0.0f) : n;
}
Vec3 normalShape(const LineDomain& d, Vec3 p) {
  const Vec3 n = unitOrZero(p - closestOnSegment(d.p0, d.p1, p));
  return n == Vec3(0.0f) ? anyPerpendicular(glm::normalize(d.p1 - d.p0)) : n;
}
Vec3 normalShape(const TriangleDomain& d, Vec3) {
  return d.normal;
}
Vec3 normalShape(const PlaneDomain& d, Vec3) {
  return d.normal;
}
Vec3 normalShape(const RectangleDomain& d, Vec3) {
  return d.normal;
}
Vec3 normalShape(const DiscDomain& d, Vec3) {
  return d.normal;
}
Vec3 normalShape(const BoxDomain& d, Vec3 p) {
  return boxNormal(d, p);
}
Vec3 normalShape(const SphereDomain& d, Vec3 p) {
  Vec3 n;
  closestBall(d.center, d.outerRadius, d.innerRadius, p, n);
  return n;
}
Vec3 normalShape(const BlobDomain& d, Vec3 p) {
  Vec3 n;
  closestBall(d.center, d.stddev, 0.0f, p, n);
  return n;
}
Vec3 normalShape(const CylinderDomain& d, Vec3 p) {
  const AxialFrame f = axialFrame(d.p0, d.p1, p);
  const Hit2 h = nearestCylinder(d, f);
  const Vec3 face = f.w * h.na + f.e * h.nrho;
  if (d.innerRadius == d.outerRadius) return face;  // a bare surface: its outward side
  return solidNormal(detail::inside(d, p), p, toWorld(f, h.a, h.rho), face,
                     f.length + d.outerRadius);
}
Vec3 normalShape(const ConeDomain& d, Vec3 p) {
  const AxialFrame f = axialFrame(d.apex, d.base, p);
  const Hit2 h = nearestCone(d, f);
  const Vec3 face = f.w * h.na + f.e * h.nrho;
  if (d.innerRadius == d.outerRadius) return face;
  return solidNormal(detail::inside(d, p), p, toWorld(f, h.a, h.rho), face,
                     f.length + d.outerRadius);
}

Vec3 closestShape(const MeshDomain& d, Vec3 p) {
  const MeshData& m = *d.mesh;
  Vec3 best = m.vertices[m.triangles[0].x];
  float bestD2 = kInfinityF;
  for (const glm::uvec3& t : m.triangles) {
    const Vec3 c = closestOnTriangle(m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], p);
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
    const Vec3 c = closestOnTriangle(m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], p);
    const float d2 = glm::dot(c - p, c - p);
    if (d2 < bestD2) {
      bestD2 = d2;
      best = k;
    }
  }
  return m.normals[best];
}
double measureShape(const MeshDomain& d) { return d.mesh->cumulativeArea.back(); }

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
Vec3 closestShape(const UnionDomain& d, Vec3 p) { return nearestPart(d, p).closestPoint(p); }
Vec3 normalShape(const UnionDomain& d, Vec3 p) { return nearestPart(d, p).normal(p); }
double measureShape(const UnionDomain& d) { return d.parts->cumulativeMeasure.back(); }

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
  if (triangles.empty()) throw InvalidArgument("mesh.triangles", "a mesh needs at least one triangle");
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
      throw InvalidArgument(where, "vertex index out of range (" + std::to_string(vertices.size()) +
                                       " vertices)");
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
  if (p.x < m.min.x || p.y < m.min.y || p.z < m.min.z || p.x > m.max.x || p.y > m.max.y ||
      p.z > m.max.z)
    return false;
  // Count crossings of a ray from p (Möller-Trumbore). The direction is skewed so that it
  // does not run along the axis-aligned edges and faces that meshes are full of.
  const Vec3 dir = glm::normalize(Vec3(1.0f, 0.1234567f, 0.0765432f));
  int crossings = 0;
  for (const glm::uvec3& t : m.triangles) {
    const Vec3 a = m.vertices[t.x], e1 = m.vertices[t.y] - a, e2 = m.vertices[t.z] - a;
    const Vec3 h = glm::cross(dir, e2);
    const float det = glm::dot(e1, h);
    if (std::abs(det) < 1e-12f) continue;
    const float inv = 1.0f / det;
    const Vec3 s = p - a;
    const float u = glm::dot(s, h) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    const Vec3 q = glm::cross(s, e1);
    const float v = glm::dot(dir, q) * inv;
    if (v < 0.0f || u + v > 1.0f) continue;
    if (glm::dot(e2, q) * inv > 0.0f) ++crossings;
  }
  return (crossings & 1) != 0;
}

bool inside(const UnionDomain& d, Vec3 p) {
  for (const Domain& part : d.parts->parts)
    if (part.contains(p)) return true;
  return false;
}

}  // namespace detail

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
  static constexpr const char* kNames[] = {"point",    "line", "triangle", "plane", "rectangle",
                                           "disc",     "box",  "sphere",   "cylinder", "cone",
                                           "blob",     "mesh", "union"};
  static_assert(std::size(kNames) == std::variant_size_v<Shape>);
  return kNames[shape_.index()];
}

}  // namespace flurry
