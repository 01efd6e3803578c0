// The domains' shared math (kernels/domain.h, also the OpenCL backend's) on the CPU, and the
// per-shape containment tests built on it: inline and branch-free so that the backends' loops
// over whole particle arrays vectorise. Domain::contains() and the CPU kernels share these.
#pragma once

#include <type_traits>

#include "../../kernels/params.h"  // FL_DOMAIN_*: the kinds, in Domain::Shape's order
#include "flurry/domain.hpp"
#include "isa_namespace.hpp"
#include "kernel_compat.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp
namespace kernel {
#include "../../kernels/domain.h"
}  // namespace kernel

inline bool inside(const PointDomain&, Vec3) {
  return false;
}
inline bool inside(const LineDomain&, Vec3) {
  return false;
}
inline bool inside(const TriangleDomain&, Vec3) {
  return false;
}
inline bool inside(const RectangleDomain&, Vec3) {
  return false;
}
inline bool inside(const DiscDomain&, Vec3) {
  return false;
}

inline bool inside(const PlaneDomain& d, Vec3 p) {
  return kernel::fl_inside_plane(d.point, d.normal, p);
}
inline bool inside(const BoxDomain& d, Vec3 p) {
  return kernel::fl_inside_box(d.min, d.max, p);
}
inline bool inside(const SphereDomain& d, Vec3 p) {
  return kernel::fl_inside_sphere(d.center, d.outerRadius, d.innerRadius, p);
}
inline bool inside(const CylinderDomain& d, Vec3 p) {
  return kernel::fl_inside_axial(d.p0, d.p1 - d.p0, d.outerRadius, d.innerRadius, 0, p);
}
inline bool inside(const ConeDomain& d, Vec3 p) {
  return kernel::fl_inside_axial(d.apex, d.base - d.apex, d.outerRadius, d.innerRadius, 1, p);
}
inline bool inside(const BlobDomain& d, Vec3 p) {
  return kernel::fl_inside_blob(d.center, d.stddev, p);
}

// The nearest point of a planar piece (Domain::closestPoint); its normal is the shape's.
inline Vec3 closest(const PlaneDomain& d, Vec3 p) {
  return kernel::fl_closest_plane(d.point, d.normal, p);
}
inline Vec3 closest(const RectangleDomain& d, Vec3 p) {
  return kernel::fl_closest_rectangle(d.origin, d.u, d.v, p);
}
inline Vec3 closest(const TriangleDomain& d, Vec3 p) {
  return kernel::fl_closest_triangle(d.p0, d.p1, d.p2, p);
}
inline Vec3 closest(const DiscDomain& d, Vec3 p) {
  return kernel::fl_closest_disc(d.center, d.normal, kernel::fl_any_perpendicular(d.normal),
                                 d.outerRadius, d.innerRadius, p);
}
/// The same point without a branch (kernels/domain.h fl_closest_triangle_chosen,
/// fl_closest_rectangle_chosen), for loops over many points that vectorise; a plane's and a
/// disc's are branch-free already.
inline Vec3 closestChosen(const TriangleDomain& d, Vec3 p) {
  return kernel::fl_closest_triangle_chosen(d.p0, d.p1, d.p2, p);
}
inline Vec3 closestChosen(const RectangleDomain& d, Vec3 p) {
  return kernel::fl_closest_rectangle_chosen(d.origin, d.u, d.v, p);
}
template <class Shape>
inline Vec3 closestChosen(const Shape& d, Vec3 p) {
  return closest(d, p);
}
// The normal at p of every shape but a mesh and a union (Domain::normal; also a newborn's
// along Emitter::normalSpeed, sampling.cpp sampledNormals): a planar piece's is its own.
inline Vec3 normal(const PointDomain& d, Vec3 p) {
  return kernel::fl_point_normal(d.p, p);
}
inline Vec3 normal(const LineDomain& d, Vec3 p) {
  return kernel::fl_line_normal(d.p0, d.p1, p);
}
inline Vec3 normal(const TriangleDomain& d, Vec3) {
  return d.normal;
}
inline Vec3 normal(const PlaneDomain& d, Vec3) {
  return d.normal;
}
inline Vec3 normal(const RectangleDomain& d, Vec3) {
  return d.normal;
}
inline Vec3 normal(const DiscDomain& d, Vec3) {
  return d.normal;
}
inline Vec3 normal(const BoxDomain& d, Vec3 p) {
  return kernel::fl_box_normal(d.min, d.max, p);
}
inline Vec3 normal(const SphereDomain& d, Vec3 p) {
  Vec3 n;
  kernel::fl_closest_ball(d.center, d.outerRadius, d.innerRadius, p, &n);
  return n;
}
inline Vec3 normal(const BlobDomain& d, Vec3 p) {
  Vec3 n;
  kernel::fl_closest_ball(d.center, d.stddev, 0.0f, p, &n);
  return n;
}
inline Vec3 normal(const CylinderDomain& d, Vec3 p) {
  return kernel::fl_axial_normal(d.p0, d.p1 - d.p0, d.outerRadius, d.innerRadius, 0, p);
}
inline Vec3 normal(const ConeDomain& d, Vec3 p) {
  return kernel::fl_axial_normal(d.apex, d.base - d.apex, d.outerRadius, d.innerRadius, 1, p);
}

template <class Shape>
constexpr bool kPlanarShape =
    std::is_same_v<Shape, PlaneDomain> || std::is_same_v<Shape, RectangleDomain> ||
    std::is_same_v<Shape, TriangleDomain> || std::is_same_v<Shape, DiscDomain>;

}  // namespace FLURRY_ISA_NAMESPACE

// Not vectorised, defined once in domain.cpp (baseline): a mesh tests ray-crossing parity
// against its triangles, a union its parts.
bool inside(const MeshDomain& d, Vec3 p);
bool inside(const UnionDomain& d, Vec3 p);

}  // namespace flurry::detail
