// Trilinear lookup in a sampled vector field: the one definition that
// VectorField::sample and the fused pass's SampledField action both use.
#pragma once

#include <algorithm>

#include "flurry/field.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

inline Vec3 sampleTrilinear(const VectorField& f, Vec3 p) {
  const glm::ivec3 dims = f.dims;
  const Vec3 g = (p - f.origin) / f.voxelSize;
  const float fx = std::clamp(g.x, 0.0f, float(dims.x - 1));
  const float fy = std::clamp(g.y, 0.0f, float(dims.y - 1));
  const float fz = std::clamp(g.z, 0.0f, float(dims.z - 1));
  const int x0 = std::min(int(fx), dims.x - 1), y0 = std::min(int(fy), dims.y - 1),
            z0 = std::min(int(fz), dims.z - 1);
  const int x1 = std::min(x0 + 1, dims.x - 1), y1 = std::min(y0 + 1, dims.y - 1),
            z1 = std::min(z0 + 1, dims.z - 1);
  const float tx = fx - float(x0), ty = fy - float(y0), tz = fz - float(z0);
  const Vec3* d = f.data.data();
  auto at = [&](int x, int y, int z) -> const Vec3& {
    return d[std::size_t(x) + std::size_t(dims.x) * (std::size_t(y) + std::size_t(dims.y) * z)];
  };
  const Vec3 c00 = at(x0, y0, z0) * (1 - tx) + at(x1, y0, z0) * tx;
  const Vec3 c10 = at(x0, y1, z0) * (1 - tx) + at(x1, y1, z0) * tx;
  const Vec3 c01 = at(x0, y0, z1) * (1 - tx) + at(x1, y0, z1) * tx;
  const Vec3 c11 = at(x0, y1, z1) * (1 - tx) + at(x1, y1, z1) * tx;
  return (c00 * (1 - ty) + c10 * ty) * (1 - tz) + (c01 * (1 - ty) + c11 * ty) * tz;
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
