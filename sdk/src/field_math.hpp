// Trilinear lookup in a sampled vector field: the one definition that
// VectorField::sample and the fused pass's SampledField action both use. The math is
// kernels/forces.h's (fl_field_axis, fl_field_blend), shared with the device.
#pragma once

#include <cstddef>

#include "flurry/field.hpp"
#include "isa_namespace.hpp"
#include "kernel_compat.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp
namespace kernel {
#include "../../kernels/forces.h"
}  // namespace kernel

inline Vec3 sampleTrilinear(const VectorField& f, Vec3 p) {
  const glm::ivec3 dims = f.dims;
  const Vec3 g = (p - f.origin) / f.voxelSize;
  int x0, x1, y0, y1, z0, z1;
  const float tx = kernel::fl_field_axis(g.x, dims.x, &x0, &x1);
  const float ty = kernel::fl_field_axis(g.y, dims.y, &y0, &y1);
  const float tz = kernel::fl_field_axis(g.z, dims.z, &z0, &z1);
  const Vec3* d = f.data.data();
  auto at = [&](int x, int y, int z) -> const Vec3& {
    return d[std::size_t(x) + std::size_t(dims.x) * (std::size_t(y) + std::size_t(dims.y) * z)];
  };
  const Vec3 &c000 = at(x0, y0, z0), &c100 = at(x1, y0, z0), &c010 = at(x0, y1, z0),
             &c110 = at(x1, y1, z0), &c001 = at(x0, y0, z1), &c101 = at(x1, y0, z1),
             &c011 = at(x0, y1, z1), &c111 = at(x1, y1, z1);
  auto blend = [&](int k) {
    return kernel::fl_field_blend(c000[k], c100[k], c010[k], c110[k], c001[k], c101[k], c011[k],
                                  c111[k], tx, ty, tz);
  };
  return Vec3(blend(0), blend(1), blend(2));
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
