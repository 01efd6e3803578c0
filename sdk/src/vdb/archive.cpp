// Serialising grids to a .vdb image in memory, and reading vector grids back.
#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <system_error>

#include "flurry/version.hpp"
#include "grids.hpp"

namespace flurry::vdb::detail {

namespace {

/// openvdb::io::File writes straight to the file and never checks the stream afterwards, so
/// a full disk leaves a short file behind silently. Writing the image to memory first lets
/// writeAtomic check every byte onto the disk; the bytes are the same as File's (a seekable
/// stream: grid offsets included, so readers can load one grid without the others).
class MemoryArchive final : public openvdb::io::Archive {
 public:
  std::string image(const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
    std::ostringstream os(std::ios_base::out | std::ios_base::binary);
    openvdb::io::Archive::write(os, grids, /*seekable=*/true, meta);
    if (!os) throw Error("serialising the grids failed");
    return std::move(os).str();
  }
};

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

std::string encode(const Frame& frame, const ExportOptions& o, FileStats& st) {
  openvdb::initialize();
  const auto start = std::chrono::steady_clock::now();
  openvdb::GridCPtrVec grids;
  openvdb::MetaMap meta;
  st.mass = 0.0;
  std::size_t hidden = 0;
  std::string names;
  for (const Particles& g : frame.groups) {
    hidden += g.hidden;
    names += (names.empty() ? "" : ",") + g.group;
  }
  if (o.fog) {
    st.fogVoxelSize = fogVoxelSize(frame, o);
    FogGrids fog = buildFog(frame, o, st.fogVoxelSize);
    st.mass = fog.mass;
    st.fogVoxels = fog.density->activeVoxelCount();
    grids.push_back(fog.density);
    if (fog.vel) grids.push_back(fog.vel);
    if (fog.color) grids.push_back(fog.color);
    meta.insertMeta("flurry:mass", openvdb::DoubleMetadata(fog.mass));
  }
  if (o.points) {
    st.pointsVoxelSize = o.pointsVoxelSize;
    auto points = buildPoints(frame, o, st.pointsVoxelSize);
    st.points = 0;
    for (const Particles& g : frame.groups) st.points += g.size();
    grids.push_back(points);
  }
  std::size_t vertices = 0;
  for (const Strands& s : frame.strands) vertices += s.vertexCount();
  if (o.points && vertices > 0) {
    st.strandsVoxelSize = o.pointsVoxelSize;
    grids.push_back(buildStrandPoints(frame, o, st.strandsVoxelSize));
    st.strandVertices = vertices;
  }
  meta.insertMeta("creator", openvdb::StringMetadata(std::string("Flurry ") + versionString()));
  meta.insertMeta("flurry:frame", openvdb::Int32Metadata(frame.number));
  meta.insertMeta("flurry:time", openvdb::DoubleMetadata(frame.time));
  meta.insertMeta("flurry:time_units", openvdb::StringMetadata("seconds"));
  meta.insertMeta("flurry:velocity_units", openvdb::StringMetadata("world units per second"));
  meta.insertMeta("flurry:groups", openvdb::StringMetadata(names));
  meta.insertMeta("flurry:strands", openvdb::Int64Metadata(std::int64_t(frame.strands.size())));
  meta.insertMeta("flurry:hidden_left_out",
                  openvdb::Int64Metadata(o.keepHidden ? 0 : std::int64_t(hidden)));
  st.buildSeconds = seconds(start);
  return MemoryArchive().image(grids, meta);
}

namespace {

template <typename GridT>
VectorField denseField(const GridT& grid, const std::string& path, std::size_t maxSamples) {
  const std::string grid_ = "grid '" + grid.getName() + "' ";
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  if (box.empty()) throw IoError(path, grid_ + "has no active voxels");
  const openvdb::math::Transform& xf = grid.transform();
  const openvdb::Vec3d vs = xf.voxelSize();
  // The field is axis-aligned with one spacing: refuse a rotation, shear or uneven scale
  // rather than sample it wrongly.
  const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0.0));
  const openvdb::Vec3d ex = xf.indexToWorld(openvdb::Vec3d(1, 0, 0)) - o;
  const openvdb::Vec3d ey = xf.indexToWorld(openvdb::Vec3d(0, 1, 0)) - o;
  const openvdb::Vec3d ez = xf.indexToWorld(openvdb::Vec3d(0, 0, 1)) - o;
  const double tol = 1e-6 * vs[0];
  if (!xf.isLinear() || std::abs(vs[0] - vs[1]) > tol || std::abs(vs[0] - vs[2]) > tol ||
      std::abs(ex[1]) + std::abs(ex[2]) + std::abs(ey[0]) + std::abs(ey[2]) + std::abs(ez[0]) +
              std::abs(ez[1]) >
          tol ||
      ex[0] <= 0 || ey[1] <= 0 || ez[2] <= 0)
    throw IoError(path, grid_ + "has a transform that is not a uniform scale and translation");
  const openvdb::Coord dim = box.dim();
  const double samples = double(dim.x()) * dim.y() * dim.z();
  if (samples > double(maxSamples))
    throw IoError(path, grid_ + "has " + std::to_string(std::uint64_t(samples)) +
                            " voxels in its active bounding box, more than the limit of " +
                            std::to_string(maxSamples));
  VectorField f;
  f.voxelSize = float(vs[0]);
  const openvdb::Vec3d origin = xf.indexToWorld(box.min());
  f.origin = Vec3(float(origin[0]), float(origin[1]), float(origin[2]));
  f.dims = glm::ivec3(dim.x(), dim.y(), dim.z());
  f.data.resize(std::size_t(samples));
  auto acc = grid.getConstAccessor();
  std::size_t n = 0;
  // Inactive voxels inside the box read as the grid's value there (the background).
  for (int z = box.min().z(); z <= box.max().z(); ++z)
    for (int y = box.min().y(); y <= box.max().y(); ++y)
      for (int x = box.min().x(); x <= box.max().x(); ++x) {
        const auto v = acc.getValue(openvdb::Coord(x, y, z));
        f.data[n++] = Vec3(float(v[0]), float(v[1]), float(v[2]));
      }
  // The parameter named in the error is file:grid.
  f.validate((path + ":" + grid.getName()).c_str());
  return f;
}

}  // namespace

}  // namespace flurry::vdb::detail

namespace flurry::vdb {

VectorField readVectorField(const std::filesystem::path& path, const std::string& gridName,
                            std::size_t maxSamples) {
  openvdb::initialize();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw IoError(path.string(), ec ? ec.message() : "no such file or not a regular file");
  openvdb::GridBase::Ptr base;
  std::string name = gridName;
  try {
    openvdb::io::File file(path.string());
    file.open();
    if (name.empty()) {
      // The first Vec3 grid, found from the descriptors without reading any tree.
      const openvdb::GridPtrVecPtr all = file.readAllGridMetadata();  // keep it alive
      for (const auto& g : *all)
        if (g->valueType() == "vec3s" || g->valueType() == "vec3d") {
          name = g->getName();
          break;
        }
      if (name.empty()) throw IoError(path.string(), "holds no Vec3 grid");
    } else if (!file.hasGrid(name)) {
      std::string have;
      for (auto it = file.beginName(); it != file.endName(); ++it)
        have += (have.empty() ? "" : ", ") + it.gridName();
      throw IoError(path.string(), "has no grid named '" + name + "' (it has: " + have + ")");
    }
    base = file.readGrid(name);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw IoError(path.string(), std::string("cannot read: ") + e.what());
  }
  if (auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base))
    return detail::denseField(*g, path.string(), maxSamples);
  if (auto g = openvdb::gridPtrCast<openvdb::Vec3DGrid>(base))
    return detail::denseField(*g, path.string(), maxSamples);
  throw IoError(path.string(), "grid '" + name + "' is a " + base->valueType() +
                                   " grid, not a Vec3 (vec3s or vec3d) grid");
}

void writeVectorField(const std::filesystem::path& path, const VectorField& field,
                      const std::string& gridName) {
  field.validate(gridName.c_str());
  openvdb::initialize();
  auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  auto xf = openvdb::math::Transform::createLinearTransform(field.voxelSize);
  xf->postTranslate(openvdb::Vec3d(field.origin.x, field.origin.y, field.origin.z));
  grid->setTransform(xf);
  grid->setName(gridName);
  grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  auto acc = grid->getAccessor();
  for (int z = 0; z < field.dims.z; ++z)
    for (int y = 0; y < field.dims.y; ++y)
      for (int x = 0; x < field.dims.x; ++x) {
        const Vec3 v = field.at(x, y, z);
        acc.setValueOn(openvdb::Coord(x, y, z), openvdb::Vec3s(v.x, v.y, v.z));
      }
  openvdb::GridCPtrVec grids{grid};
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata(std::string("Flurry ") + versionString()));
  detail::writeAtomic(path, detail::MemoryArchive().image(grids, meta));
}

}  // namespace flurry::vdb
