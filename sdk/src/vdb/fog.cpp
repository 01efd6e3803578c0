// Splatting particles and strands into the fog volume: `density`, `vel`, `Cd`.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <openvdb/tools/Composite.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "grids.hpp"

namespace flurry::vdb::detail {

namespace {

/// One spherical deposit: a particle, or a bead of a strand.
struct Blob {
  Vec3 p;
  float r;
  double mass;
  Vec3 v;
  Vec3 c;
};

/// Flat to q = 1/2, smoothstep down to 0 at q = 1 (q: distance over kernel radius). Flat in
/// the middle so a lone particle reads as a soft-edged ball of about its radius.
inline double kernel(double q) {
  if (q <= 0.5) return 1.0;
  if (q >= 1.0) return 0.0;
  const double t = (q - 0.5) * 2.0;
  return 1.0 - t * t * (3.0 - 2.0 * t);
}

struct Accum {
  openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
  openvdb::Vec3SGrid::Ptr mv = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  openvdb::Vec3SGrid::Ptr mc = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
};

/// Largest kernel, in voxels across one axis, before we refuse (a particle that big against
/// the voxel means a wrong voxel size, and would take minutes and gigabytes).
constexpr double kMaxKernelVoxels = 1024.0;

void splat(const Blob& b, float voxelSize, float minKernel, bool vel, bool color,
           openvdb::FloatGrid::Accessor& da, openvdb::Vec3SGrid::Accessor& va,
           openvdb::Vec3SGrid::Accessor& ca) {
  if (!(b.mass > 0.0)) return;
  const double inv = 1.0 / double(voxelSize);
  const double x[3] = {b.p.x * inv, b.p.y * inv, b.p.z * inv};
  const double h = std::max(double(b.r) * inv, double(minKernel));
  if (2.0 * h > kMaxKernelVoxels)
    throw InvalidArgument("fogVoxelSize", "a particle of radius " + std::to_string(b.r) +
                                              " spans " + std::to_string(int(2 * h)) +
                                              " voxels of " + std::to_string(voxelSize) +
                                              ": choose a larger voxel size");
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    // Voxel coordinates are 32-bit; stay well inside them.
    if (!(std::abs(x[a]) + h < 1e9))
      throw InvalidArgument("fogVoxelSize", "a particle at " + std::to_string(b.p[a]) +
                                                " is too far from the origin for voxels of " +
                                                std::to_string(voxelSize));
    lo[a] = int(std::ceil(x[a] - h));
    hi[a] = int(std::floor(x[a] + h));
  }
  const double invH = 1.0 / h;
  auto weight = [&](int i, double dyz2) {
    const double dx = i - x[0];
    return kernel(std::sqrt(dx * dx + dyz2) * invH);
  };
  // The voxels of row (j, k) that may lie inside the kernel's sphere: [i0, i1], a voxel wider
  // than the sphere's chord on each side (the weight decides; a voxel outside it weighs 0,
  // and adding 0 changes no sum), empty where the row misses the sphere. Half of the box's
  // voxels are outside, and each would cost a square root.
  auto row = [&](int j, int k, int& i0, int& i1, double& dyz2) {
    const double dy = j - x[1], dz = k - x[2];
    dyz2 = dy * dy + dz * dz;
    const double c2 = h * h - dyz2;
    if (c2 < 0.0) return false;
    const double c = std::sqrt(c2);
    i0 = std::max(lo[0], int(std::ceil(x[0] - c)) - 1);
    i1 = std::min(hi[0], int(std::floor(x[0] + c)) + 1);
    return i0 <= i1;
  };
  // Normalise over the voxel centres actually covered, so the deposit sums to the mass
  // exactly wherever the particle sits against the grid.
  double sum = 0.0;
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j) {
      int i0, i1;
      double dyz2;
      if (!row(j, k, i0, i1, dyz2)) continue;
      for (int i = i0; i <= i1; ++i) sum += weight(i, dyz2);
    }
  const double perVoxel = b.mass / (double(voxelSize) * voxelSize * voxelSize);
  const openvdb::Vec3s v(b.v.x, b.v.y, b.v.z), c(b.c.x, b.c.y, b.c.z);
  if (!(sum > 0.0)) {  // a kernel narrower than the voxel spacing: all to the nearest voxel
    const openvdb::Coord ijk(int(std::lround(x[0])), int(std::lround(x[1])),
                             int(std::lround(x[2])));
    const float d = float(perVoxel);
    da.setValue(ijk, da.getValue(ijk) + d);
    if (vel) va.setValue(ijk, va.getValue(ijk) + v * d);
    if (color) ca.setValue(ijk, ca.getValue(ijk) + c * d);
    return;
  }
  // Deposits straight into the leaves (8 voxels along x each), found once per leaf a row
  // crosses rather than through the accessors per voxel and grid.
  using DensityLeaf = openvdb::FloatGrid::TreeType::LeafNodeType;
  using VectorLeaf = openvdb::Vec3SGrid::TreeType::LeafNodeType;
  const double norm = 1.0 / sum;
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j) {
      int i0, i1;
      double dyz2;
      if (!row(j, k, i0, i1, dyz2)) continue;
      DensityLeaf* dl = nullptr;
      VectorLeaf *vl = nullptr, *cl = nullptr;
      int leafX = 0;
      for (int i = i0; i <= i1; ++i) {
        const double w = weight(i, dyz2);
        if (!(w > 0.0)) continue;
        const openvdb::Coord ijk(i, j, k);
        if (!dl || (i & ~7) != leafX) {
          leafX = i & ~7;
          dl = da.touchLeaf(ijk);
          if (vel) vl = va.touchLeaf(ijk);
          if (color) cl = ca.touchLeaf(ijk);
        }
        const openvdb::Index n = DensityLeaf::coordToOffset(ijk);
        const float d = float(perVoxel * (w * norm));
        dl->setValueOn(n, dl->getValue(n) + d);
        if (vel) vl->setValueOn(n, vl->getValue(n) + v * d);
        if (color) cl->setValueOn(n, cl->getValue(n) + c * d);
      }
    }
}

/// Strands as beads: each segment cut into pieces no longer than half the thinner kernel
/// radius, each piece a blob at its middle carrying the exact tube volume of the piece.
void strandBlobs(const Strands& s, const ExportOptions& o, float voxelSize, std::size_t index,
                 std::vector<Blob>& out) {
  const std::string name = "strands[" + std::to_string(index) + "]";
  if (s.start.empty() || s.start.back() != s.position.size())
    throw InvalidArgument(name + ".start", "must end at the vertex count");
  if (!s.radius.empty() && s.radius.size() != s.position.size())
    throw InvalidArgument(name + ".radius", "needs one value per vertex");
  if (!s.color.empty() && s.color.size() != s.position.size())
    throw InvalidArgument(name + ".color", "needs one value per vertex");
  const double minR = double(o.fogMinKernelVoxels) * voxelSize;
  for (std::size_t k = 0; k + 1 < s.start.size(); ++k) {
    if (s.start[k] > s.start[k + 1]) throw InvalidArgument(name + ".start", "must not decrease");
    for (std::uint32_t a = s.start[k]; a + 1 < s.start[k + 1]; ++a) {
      const Vec3 p0 = s.position[a], p1 = s.position[a + 1];
      const double r0 = s.radius.empty() ? o.defaultRadius : s.radius[a];
      const double r1 = s.radius.empty() ? o.defaultRadius : s.radius[a + 1];
      const Vec4 c0 = s.color.empty() ? Vec4(1.0f) : s.color[a];
      const Vec4 c1 = s.color.empty() ? Vec4(1.0f) : s.color[a + 1];
      if (!std::isfinite(r0) || !std::isfinite(r1) || r0 < 0 || r1 < 0)
        throw InvalidArgument(name + ".radius", "must be finite and >= 0");
      const double len = glm::length(glm::dvec3(p1) - glm::dvec3(p0));
      if (!std::isfinite(len)) throw InvalidArgument(name + ".position", "is not finite");
      if (len == 0.0) continue;  // a tube of no length holds no volume
      const double step = 0.5 * std::max(std::min(r0, r1), minR);
      const double pieces = std::ceil(len / step);
      if (pieces > 1e7)
        throw InvalidArgument(name, "a segment needs " + std::to_string(pieces) +
                                        " beads: choose a larger voxel size");
      const int n = std::max(1, int(pieces));
      for (int i = 0; i < n; ++i) {
        const double t0 = double(i) / n, t1 = double(i + 1) / n, tm = 0.5 * (t0 + t1);
        const double ra = r0 + (r1 - r0) * t0, rb = r0 + (r1 - r0) * t1;
        // ∫ π r² ds over the piece, exact for r linear in s.
        const double vol = std::numbers::pi * len * (t1 - t0) * (ra * ra + ra * rb + rb * rb) / 3.0;
        const Vec4 c = c0 + (c1 - c0) * float(tm);
        out.push_back(Blob{p0 + (p1 - p0) * float(tm), float(r0 + (r1 - r0) * tm),
                           double(o.density) * vol, Vec3(0.0f), Vec3(c)});
      }
    }
  }
}

}  // namespace

FogGrids buildFog(const Frame& frame, const ExportOptions& o, float voxelSize) {
  bool vel = false, color = !frame.strands.empty();
  std::size_t count = 0;
  for (const Particles& g : frame.groups) {
    vel |= !g.velocity.empty();
    color |= !g.color.empty();
    count += g.size();
  }
  std::vector<Blob> blobs;
  blobs.reserve(count);
  for (const Particles& g : frame.groups)
    for (std::size_t i = 0; i < g.size(); ++i) {
      const float r = g.radius.empty() ? o.defaultRadius : g.radius[i];
      blobs.push_back(Blob{g.position[i], r, particleMass(r, o.density),
                           g.velocity.empty() ? Vec3(0.0f) : g.velocity[i],
                           g.color.empty() ? Vec3(1.0f) : g.color[i]});
    }
  for (std::size_t s = 0; s < frame.strands.size(); ++s)
    strandBlobs(frame.strands[s], o, voxelSize, s, blobs);

  // Fixed chunks, each splatted into grids of its own in parallel, then summed in a fixed
  // order: the result does not depend on the number of threads.
  constexpr std::size_t kChunk = 8192;
  const std::size_t chunks = std::max<std::size_t>(1, (blobs.size() + kChunk - 1) / kChunk);
  std::vector<Accum> acc(chunks);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const auto& range) {
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      Accum& a = acc[c];
      auto da = a.density->getAccessor();
      auto va = a.mv->getAccessor();
      auto ca = a.mc->getAccessor();
      const std::size_t end = std::min(blobs.size(), (c + 1) * kChunk);
      for (std::size_t i = c * kChunk; i < end; ++i)
        splat(blobs[i], voxelSize, o.fogMinKernelVoxels, vel, color, da, va, ca);
    }
  });
  for (std::size_t width = 1; width < chunks; width *= 2) {
    tbb::parallel_for(std::size_t(0), (chunks + 2 * width - 1) / (2 * width), [&](std::size_t p) {
      const std::size_t a = 2 * width * p, b = a + width;
      if (b >= chunks) return;
      openvdb::tools::compSum(*acc[a].density, *acc[b].density);
      if (vel) openvdb::tools::compSum(*acc[a].mv, *acc[b].mv);
      if (color) openvdb::tools::compSum(*acc[a].mc, *acc[b].mc);
    });
  }

  FogGrids out;
  for (const Blob& b : blobs) out.mass += b.mass;
  const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
  out.density = acc[0].density;
  out.density->setName("density");
  out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
  out.density->setTransform(xform);
  out.density->insertMeta("flurry:mass", openvdb::DoubleMetadata(out.mass));
  out.density->insertMeta("flurry:density", openvdb::FloatMetadata(o.density));
  // Average velocity and color: the mass-weighted sums over the voxel's density.
  auto averaged = [&](openvdb::Vec3SGrid::Ptr g, const char* name) {
    auto da = out.density->getConstAccessor();
    for (auto it = g->beginValueOn(); it; ++it) {
      const float d = da.getValue(it.getCoord());
      it.setValue(d > 0.0f ? it.getValue() / d : openvdb::Vec3s(0.0f));
    }
    g->setName(name);
    g->setTransform(xform);
    return g;
  };
  if (vel) {
    out.vel = averaged(acc[0].mv, "vel");
    out.vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    out.vel->insertMeta("units", openvdb::StringMetadata("world units per second"));
  }
  if (color) {
    out.color = averaged(acc[0].mc, "Cd");
    out.color->setVectorType(openvdb::VEC_INVARIANT);
  }
  return out;
}

}  // namespace flurry::vdb::detail
