// Per-shape containment tests, inline and branch-free so that the backends' loops over whole
// particle arrays vectorise. Domain::contains() and the CPU kernels share these.
#pragma once

#include "flurry/domain.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

inline bool inside(const PointDomain&, Vec3) { return false; }
inline bool inside(const LineDomain&, Vec3) { return false; }
inline bool inside(const TriangleDomain&, Vec3) { return false; }
inline bool inside(const RectangleDomain&, Vec3) { return false; }
inline bool inside(const DiscDomain&, Vec3) { return false; }

inline bool inside(const PlaneDomain& d, Vec3 p) { return glm::dot(p - d.point, d.normal) >= 0.0f; }

inline bool inside(const BoxDomain& d, Vec3 p) {
  return (p.x >= d.min.x) & (p.x <= d.max.x) & (p.y >= d.min.y) & (p.y <= d.max.y) &
         (p.z >= d.min.z) & (p.z <= d.max.z);
}

inline bool inside(const SphereDomain& d, Vec3 p) {
  const Vec3 r = p - d.center;
  const float r2 = glm::dot(r, r);
  return (r2 <= d.outerRadius * d.outerRadius) & (r2 >= d.innerRadius * d.innerRadius) &
         (d.innerRadius < d.outerRadius);
}

inline bool inside(const CylinderDomain& d, Vec3 p) {
  const Vec3 axis = d.p1 - d.p0;
  const float len2 = glm::dot(axis, axis);
  const Vec3 r = p - d.p0;
  const float t = glm::dot(r, axis) / len2;   // position along the axis, 0..1 inside
  const Vec3 radial = r - axis * t;
  const float q2 = glm::dot(radial, radial);
  return (t >= 0.0f) & (t <= 1.0f) & (q2 <= d.outerRadius * d.outerRadius) &
         (q2 >= d.innerRadius * d.innerRadius) & (d.innerRadius < d.outerRadius);
}

inline bool inside(const ConeDomain& d, Vec3 p) {
  const Vec3 axis = d.base - d.apex;
  const float len2 = glm::dot(axis, axis);
  const Vec3 r = p - d.apex;
  const float t = glm::dot(r, axis) / len2;   // 0 at the apex, 1 at the base
  const Vec3 radial = r - axis * t;
  const float q2 = glm::dot(radial, radial);
  const float ro = d.outerRadius * t, ri = d.innerRadius * t;
  return (t >= 0.0f) & (t <= 1.0f) & (q2 <= ro * ro) & (q2 >= ri * ri) &
         (d.innerRadius < d.outerRadius);
}

inline bool inside(const BlobDomain& d, Vec3 p) {
  const Vec3 r = p - d.center;
  return glm::dot(r, r) <= d.stddev * d.stddev;
}

}  // namespace FLURRY_ISA_NAMESPACE

// Not vectorised, defined once in domain.cpp (baseline): a mesh tests ray-crossing parity
// against its triangles, a union its parts.
bool inside(const MeshDomain& d, Vec3 p);
bool inside(const UnionDomain& d, Vec3 p);

}  // namespace flurry::detail
