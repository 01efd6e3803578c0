#include "effect/obj_mesh.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>

namespace flurry::detail {

namespace {

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/// The next whitespace-separated token of `line` from `pos` (empty at the end).
std::string_view token(std::string_view line, std::size_t& pos) {
  while (pos < line.size() && isSpace(line[pos])) ++pos;
  const std::size_t start = pos;
  while (pos < line.size() && !isSpace(line[pos])) ++pos;
  return line.substr(start, pos - start);
}

std::string quoted(std::string_view s) {
  constexpr std::size_t kShown = 24;  // a binary file's "token" can be huge
  return "\"" + std::string(s.substr(0, kShown)) + (s.size() > kShown ? "..." : "") + "\"";
}

}  // namespace

ObjMesh parseObj(std::string_view text, std::size_t maxElements) {
  ObjMesh m;
  std::vector<long long> face;
  std::size_t lineNo = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++lineNo;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::size_t at = 0;
    const std::string_view key = token(line, at);
    if (key == "v") {
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        const std::string_view t = token(line, at);
        if (t.empty()) throw ObjError(lineNo, "a vertex needs x y z");
        float x = 0.0f;
        const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), x);
        if (ec != std::errc() || p != t.data() + t.size() || !std::isfinite(x))
          throw ObjError(lineNo, "vertex coordinate " + quoted(t) + " is not a finite number");
        v[k] = x;
      }
      // An optional w (rational curves) is ignored; colours after xyz (a common extension)
      // too.
      if (m.vertices.size() >= maxElements)
        throw ObjError(lineNo, "more than " + std::to_string(maxElements) + " vertices");
      m.vertices.push_back(v);
    } else if (key == "f") {
      face.clear();
      for (std::string_view t = token(line, at); !t.empty(); t = token(line, at)) {
        // v, v/vt, v/vt/vn or v//vn: only the vertex index matters here.
        const std::string_view v = t.substr(0, t.find('/'));
        long long i = 0;
        const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), i);
        if (v.empty() || ec != std::errc() || p != v.data() + v.size() || i == 0)
          throw ObjError(lineNo, "face corner " + quoted(t) +
                                     " is not a vertex index (1-based, or negative from the end)");
        // Negative indices count back from the last vertex read so far.
        if (i < 0) {
          if (-i > (long long)m.vertices.size())
            throw ObjError(lineNo, "face corner " + std::to_string(i) +
                                       " is before the first vertex (" +
                                       std::to_string(m.vertices.size()) + " so far)");
          i = (long long)m.vertices.size() + i + 1;
        }
        face.push_back(i - 1);
      }
      if (face.size() < 3)
        throw ObjError(lineNo,
                       "a face needs at least 3 corners, got " + std::to_string(face.size()));
      for (std::size_t k = 1; k + 1 < face.size(); ++k) {
        if (m.triangles.size() >= maxElements)
          throw ObjError(lineNo, "more than " + std::to_string(maxElements) + " triangles");
        // Indices past the vertices read so far are checked once the file is read (a file
        // may list faces first); out-of-range until then is kept as the largest index.
        auto idx = [](long long x) {
          return std::uint32_t(std::min<long long>(x, std::numeric_limits<std::uint32_t>::max()));
        };
        m.triangles.emplace_back(idx(face[0]), idx(face[k]), idx(face[k + 1]));
        m.triangleLines.push_back(lineNo);
      }
    }
    // Anything else (vn, vt, o, g, s, usemtl, mtllib, l, p, ...) does not shape a surface.
  }
  if (m.triangles.empty()) throw ObjError(lineNo, "no faces ('f' lines) in the file");
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    for (int c = 0; c < 3; ++c)
      if (m.triangles[k][c] >= m.vertices.size())
        throw ObjError(m.triangleLines[k],
                       "face corner " + std::to_string(std::uint64_t(m.triangles[k][c]) + 1) +
                           " is past the last vertex (" + std::to_string(m.vertices.size()) +
                           " in the file)");
  return m;
}

}  // namespace flurry::detail
