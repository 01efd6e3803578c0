// A vector field sampled on a regular grid (a dense grid, or one read from an OpenVDB Vec3
// grid by flurry::vdb): the sampled-field force reads it trilinearly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <string>

#include <glm/vec3.hpp>

#include "flurry/error.hpp"
#include "flurry/math.hpp"

namespace flurry {

struct VectorField {
  Vec3 origin{0.0f};       ///< world position of sample (0, 0, 0)
  float voxelSize = 1.0f;  ///< spacing of the samples
  glm::ivec3 dims{0};      ///< samples along x, y, z
  std::vector<Vec3> data;  ///< x fastest: index = x + dims.x * (y + dims.y * z)

  /// Throws InvalidArgument if the grid is empty, mis-sized, or holds a NaN or Inf.
  void validate(const char* name = "field") const {
    if (dims.x < 1 || dims.y < 1 || dims.z < 1) throw InvalidArgument(name, "empty grid");
    if (!(voxelSize > 0) || !std::isfinite(voxelSize))
      throw InvalidArgument(std::string(name) + ".voxelSize", "must be finite and > 0");
    if (data.size() != std::size_t(dims.x) * dims.y * dims.z)
      throw InvalidArgument(name, "data size does not match dims");
    for (std::size_t i = 0; i < data.size(); ++i)
      if (!std::isfinite(data[i].x) || !std::isfinite(data[i].y) || !std::isfinite(data[i].z))
        throw InvalidArgument(name, "sample " + std::to_string(i) + " is not finite");
  }

  const Vec3& at(int x, int y, int z) const {
    return data[std::size_t(x) + std::size_t(dims.x) * (std::size_t(y) + std::size_t(dims.y) * z)];
  }

  /// Trilinear interpolation; positions outside the grid take the nearest border value.
  Vec3 sample(Vec3 p) const {
    const Vec3 g = (p - origin) / voxelSize;
    const float fx = std::clamp(g.x, 0.0f, float(dims.x - 1));
    const float fy = std::clamp(g.y, 0.0f, float(dims.y - 1));
    const float fz = std::clamp(g.z, 0.0f, float(dims.z - 1));
    const int x0 = std::min(int(fx), dims.x - 1), y0 = std::min(int(fy), dims.y - 1),
              z0 = std::min(int(fz), dims.z - 1);
    const int x1 = std::min(x0 + 1, dims.x - 1), y1 = std::min(y0 + 1, dims.y - 1),
              z1 = std::min(z0 + 1, dims.z - 1);
    const float tx = fx - float(x0), ty = fy - float(y0), tz = fz - float(z0);
    const Vec3 c00 = at(x0, y0, z0) * (1 - tx) + at(x1, y0, z0) * tx;
    const Vec3 c10 = at(x0, y1, z0) * (1 - tx) + at(x1, y1, z0) * tx;
    const Vec3 c01 = at(x0, y0, z1) * (1 - tx) + at(x1, y0, z1) * tx;
    const Vec3 c11 = at(x0, y1, z1) * (1 - tx) + at(x1, y1, z1) * tx;
    return (c00 * (1 - ty) + c10 * ty) * (1 - tz) + (c01 * (1 - ty) + c11 * ty) * tz;
  }
};

}  // namespace flurry
