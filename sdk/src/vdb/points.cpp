// The `points` PointDataGrid: P, v, Cd, pscale, id, age; and the `strands` one: strand
// vertices with P, Cd, pscale, strand_id, strand_vertex.
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "grids.hpp"

namespace flurry::vdb::detail {

namespace {

/// The groups' particles back to back, in OpenVDB's types; an attribute is written if any
/// group stores it, with a default where one does not.
struct Columns {
  std::vector<openvdb::Vec3f> p, v, cd;
  std::vector<float> pscale, age;
  std::vector<std::int64_t> id;  // uint32 ids; int64 keeps every one exact
  bool hasV = false, hasCd = false, hasAge = false;
};

Columns gather(const Frame& frame, const ExportOptions& o) {
  Columns c;
  std::size_t n = 0;
  for (const Particles& g : frame.groups) {
    n += g.size();
    c.hasV |= !g.velocity.empty();
    c.hasCd |= !g.color.empty();
    c.hasAge |= !g.age.empty();
  }
  c.p.reserve(n);
  c.id.reserve(n);
  c.pscale.reserve(n);
  if (c.hasV) c.v.reserve(n);
  if (c.hasCd) c.cd.reserve(n);
  if (c.hasAge) c.age.reserve(n);
  auto vec = [](const Vec3& a) { return openvdb::Vec3f(a.x, a.y, a.z); };
  for (const Particles& g : frame.groups)
    for (std::size_t i = 0; i < g.size(); ++i) {
      c.p.push_back(vec(g.position[i]));
      c.id.push_back(std::int64_t(g.id[i]));
      c.pscale.push_back(g.radius.empty() ? o.defaultRadius : g.radius[i]);
      if (c.hasV) c.v.push_back(g.velocity.empty() ? openvdb::Vec3f(0.0f) : vec(g.velocity[i]));
      if (c.hasCd) c.cd.push_back(g.color.empty() ? openvdb::Vec3f(1.0f) : vec(g.color[i]));
      if (c.hasAge) c.age.push_back(g.age.empty() ? 0.0f : g.age[i]);
    }
  return c;
}

}  // namespace

openvdb::points::PointDataGrid::Ptr buildPoints(const Frame& frame, const ExportOptions& o,
                                                float& voxelSize) {
  namespace pts = openvdb::points;
  const Columns c = gather(frame, o);
  const pts::PointAttributeVector<openvdb::Vec3f> positions(c.p);
  if (!(voxelSize > 0.0f)) voxelSize = pts::computeVoxelSize(positions, o.pointsPerVoxel);
  for (const auto& p : c.p)
    for (int a = 0; a < 3; ++a)
      if (!(std::abs(p[a]) / voxelSize < 1e9))
        throw InvalidArgument("pointsVoxelSize", "a point at " + std::to_string(p[a]) +
                                                     " is too far from the origin for voxels of " +
                                                     std::to_string(voxelSize));
  const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
  const auto index =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);
  // Positions stored as full floats (NullCodec): exact to float rounding, at 12 bytes a point.
  auto grid =
      pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
  auto& tree = grid->tree();
  const auto& indexTree = index->tree();
  auto add = [&](const char* name, const auto& values) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    pts::appendAttribute<T>(tree, name);
    pts::populateAttribute(tree, indexTree, name, pts::PointAttributeVector<T>(values));
  };
  if (c.hasV) add("v", c.v);
  if (c.hasCd) add("Cd", c.cd);
  add("pscale", c.pscale);
  add("id", c.id);
  if (c.hasAge) add("age", c.age);
  // Several groups share one grid; a VDB point group per flurry group tells them apart.
  if (frame.groups.size() > 1) {
    std::size_t start = 0;
    for (const Particles& g : frame.groups) {
      std::vector<short> member(c.p.size(), 0);
      std::fill(member.begin() + std::ptrdiff_t(start),
                member.begin() + std::ptrdiff_t(start + g.size()), short(1));
      pts::appendGroup(tree, g.group);
      pts::setGroup(tree, indexTree, member, g.group);
      start += g.size();
    }
  }
  grid->setName("points");
  if (c.hasV) grid->insertMeta("v_units", openvdb::StringMetadata("world units per second"));
  if (c.hasAge) grid->insertMeta("age_units", openvdb::StringMetadata("seconds"));
  grid->insertMeta("pscale_meaning", openvdb::StringMetadata("radius"));
  return grid;
}

openvdb::points::PointDataGrid::Ptr buildStrandPoints(const Frame& frame, const ExportOptions& o,
                                                      float& voxelSize) {
  namespace pts = openvdb::points;
  // Every vertex a point; `strand_id` and `strand_vertex` say which curve it is on and where,
  // since a PointDataGrid keeps its points in voxel order, not in the order given.
  std::vector<openvdb::Vec3f> p, cd;
  std::vector<float> pscale;
  std::vector<std::int32_t> strand, vertex;
  std::size_t n = 0;
  for (const Strands& s : frame.strands) n += s.vertexCount();
  p.reserve(n), cd.reserve(n), pscale.reserve(n), strand.reserve(n), vertex.reserve(n);
  std::int64_t id = 0;
  for (std::size_t si = 0; si < frame.strands.size(); ++si) {
    const Strands& s = frame.strands[si];
    const std::string name = "strands[" + std::to_string(si) + "]";
    if (s.start.empty() || s.start.back() != s.position.size())
      throw InvalidArgument(name + ".start", "must end at the vertex count");
    for (std::size_t k = 0; k + 1 < s.start.size(); ++k, ++id) {
      if (s.start[k] > s.start[k + 1]) throw InvalidArgument(name + ".start", "must not decrease");
      if (id > std::numeric_limits<std::int32_t>::max() ||
          s.start[k + 1] - s.start[k] > std::uint32_t(std::numeric_limits<std::int32_t>::max()))
        throw InvalidArgument(name, "too many strands or vertices for int32 attributes");
      for (std::uint32_t i = s.start[k]; i < s.start[k + 1]; ++i) {
        const Vec3 x = s.position[i];
        p.emplace_back(x.x, x.y, x.z);
        const Vec4 c = s.color.size() > i ? s.color[i] : Vec4(1.0f);
        cd.emplace_back(c.x, c.y, c.z);
        pscale.push_back(s.radius.size() > i ? s.radius[i] : o.defaultRadius);
        strand.push_back(std::int32_t(id));
        vertex.push_back(std::int32_t(i - s.start[k]));
      }
    }
  }
  const pts::PointAttributeVector<openvdb::Vec3f> positions(p);
  if (!(voxelSize > 0.0f)) voxelSize = pts::computeVoxelSize(positions, o.pointsPerVoxel);
  for (const auto& x : p)
    for (int a = 0; a < 3; ++a)
      if (!(std::abs(x[a]) / voxelSize < 1e9))
        throw InvalidArgument("pointsVoxelSize", "a strand vertex at " + std::to_string(x[a]) +
                                                     " is too far from the origin for voxels of " +
                                                     std::to_string(voxelSize));
  const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
  const auto index =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);
  auto grid =
      pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
  auto& tree = grid->tree();
  const auto& indexTree = index->tree();
  auto add = [&](const char* attr, const auto& values) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    pts::appendAttribute<T>(tree, attr);
    pts::populateAttribute(tree, indexTree, attr, pts::PointAttributeVector<T>(values));
  };
  add("Cd", cd);
  add("pscale", pscale);
  add("strand_id", strand);
  add("strand_vertex", vertex);
  grid->setName("strands");
  grid->insertMeta("pscale_meaning", openvdb::StringMetadata("radius"));
  grid->insertMeta("strand_id_meaning",
                   openvdb::StringMetadata("the strand (curve) a vertex belongs to, from 0"));
  grid->insertMeta("strand_vertex_meaning",
                   openvdb::StringMetadata("the vertex's place along its strand, 0 at the root"));
  return grid;
}

}  // namespace flurry::vdb::detail
