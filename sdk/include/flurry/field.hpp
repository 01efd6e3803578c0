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
  Vec3 sample(Vec3 p) const;
};

}  // namespace flurry
