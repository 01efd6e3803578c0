// Hair (static) mode output: a particle's whole life as a strand of vertices, each with a
// position, a color and a thickness (radius). Renderers and exporters read this.
#pragma once

#include <cstdint>
#include <vector>

#include "flurry/math.hpp"

namespace flurry {

/// Strands stored back to back: strand k has the vertices [start[k], start[k + 1]).
struct Strands {
  std::vector<Vec3> position;
  std::vector<Vec4> color;
  std::vector<float> radius;
  std::vector<std::uint32_t> start{0};  ///< size() + 1 entries

  std::size_t size() const { return start.size() - 1; }
  std::size_t vertexCount() const { return position.size(); }
  void clear() {
    position.clear();
    color.clear();
    radius.clear();
    start.assign(1, 0);
  }
  /// Appends one strand from parallel arrays of equal length.
  void add(const std::vector<Vec3>& p, const std::vector<Vec4>& c, const std::vector<float>& r) {
    position.insert(position.end(), p.begin(), p.end());
    color.insert(color.end(), c.begin(), c.end());
    radius.insert(radius.end(), r.begin(), r.end());
    start.push_back(std::uint32_t(position.size()));
  }
};

}  // namespace flurry
