// A Wavefront OBJ reader for mesh domains in effect files: 'v' and 'f' lines only (normals,
// texture coordinates, groups and materials are skipped), polygons fanned into triangles.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "flurry/error.hpp"
#include "flurry/math.hpp"

namespace flurry::detail {

/// What is wrong with an OBJ text, and on which line (1-based).
class ObjError : public Error {
 public:
  ObjError(std::size_t line, const std::string& why)
      : Error("line " + std::to_string(line) + ": " + why), line_(line), why_(why) {}
  std::size_t line() const { return line_; }
  const std::string& why() const { return why_; }

 private:
  std::size_t line_;
  std::string why_;
};

struct ObjMesh {
  std::vector<Vec3> vertices;
  std::vector<glm::uvec3> triangles;
  std::vector<std::size_t> triangleLines;  ///< the 'f' line each triangle came from
};

/// Parses OBJ text. Throws ObjError naming the line: a 'v' without three finite numbers, an
/// 'f' with fewer than three corners or a corner that is not a vertex index (1-based,
/// negative counts back from the last vertex so far), an index past the file's vertices,
/// more than `maxElements` vertices or triangles, a file with no faces.
ObjMesh parseObj(std::string_view text, std::size_t maxElements);

}  // namespace flurry::detail
