// flurry::vdb: every file is read back with OpenVDB itself and checked against the particles
// it came from: grid names, classes, metadata, point counts and values, the density integral
// against the particles' masses, bounds; plus atomic writes, errors, and vector fields.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/IndexFilter.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <random>

#include "builtin.hpp"
#include "flurry/flurry.hpp"
#include "flurry/vdb.hpp"
#include "vdb/detail.hpp"

namespace fs = std::filesystem;
using namespace flurry;

extern char** environ;

namespace {

/// Removes the process's scratch folders after its tests when all of them passed (a failure
/// keeps them to look at): runs of the suite do not fill the temporary folder.
class ScratchFolders : public ::testing::Environment {
 public:
  static ScratchFolders& get() {
    static ScratchFolders* const folders = [] {
      auto* f = new ScratchFolders;  // (gtest owns and deletes it)
      ::testing::AddGlobalTestEnvironment(f);
      return f;
    }();
    return *folders;
  }
  void add(const fs::path& dir) { dirs_.push_back(dir); }
  void TearDown() override {
    if (!::testing::UnitTest::GetInstance()->Passed()) return;
    std::error_code ignored;
    for (const fs::path& dir : dirs_) fs::remove_all(dir, ignored);
  }

 private:
  std::vector<fs::path> dirs_;
};
// Made before the tests run, so that gtest calls its TearDown.
[[maybe_unused]] const ScratchFolders& kScratchFolders = ScratchFolders::get();

/// A fresh, empty folder per test.
fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("flurry_vdb_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  ScratchFolders::get().add(dir);
  return dir;
}

struct VdbFile {
  openvdb::GridPtrVecPtr grids;
  openvdb::MetaMap::Ptr meta;

  explicit VdbFile(const fs::path& path) {
    openvdb::initialize();
    openvdb::io::File f(path.string());
    f.open();
    grids = f.getGrids();
    meta = f.getMetadata();
    f.close();
  }
  /// Sorted: io::File lists grids by name, not in the order written.
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& g : *grids) n.push_back(g->getName());
    std::sort(n.begin(), n.end());
    return n;
  }
  template <typename G>
  typename G::Ptr get(const std::string& name) const {
    for (const auto& g : *grids)
      if (g->getName() == name) return openvdb::gridPtrCast<G>(g);
    return nullptr;
  }
};

double integral(const openvdb::FloatGrid& g) {
  double sum = 0.0;
  for (auto it = g.cbeginValueOn(); it; ++it) sum += double(*it) * double(it.getVoxelCount());
  const double vs = g.voxelSize()[0];
  return sum * vs * vs * vs;
}

double sphereMass(float r, float density = 1.0f) {
  return density * 4.0 / 3.0 * std::numbers::pi * double(r) * r * r;
}

/// Float voxel values, each a float sum of a few dozen deposits, summed here in double: the
/// relative rounding is ~1e-7 per voxel and does not grow with the voxel count. 1e-5 leaves
/// room for that, and is far below what a lost particle or an unnormalised kernel costs
/// (1e-3 and up in these tests).
constexpr double kMassTolerance = 1e-5;

Particle makeParticle(std::mt19937& rng, float rMin, float rMax, float spread = 1.0f) {
  std::uniform_real_distribution<float> u(-spread, spread), r(rMin, rMax), c(0.0f, 1.0f);
  Particle p;
  p.position = Vec3(u(rng), u(rng), u(rng));
  p.velocity = Vec3(u(rng) * 5, u(rng) * 5, u(rng) * 5);
  p.color = Vec4(c(rng), c(rng), c(rng), 1.0f);
  p.size = r(rng);
  p.age = c(rng) * 3;
  return p;
}

Group& makeGroup(Context& ctx, const std::string& name, std::size_t n, float rMin, float rMax,
                 unsigned seed, AttributeSet extra = {}) {
  Group& g = ctx.createGroup(name, n + 16);
  g.require(AttributeSet{Attribute::Velocity, Attribute::Color, Attribute::Size, Attribute::Age} |
            extra);
  std::mt19937 rng(seed);
  for (std::size_t i = 0; i < n; ++i) g.add(makeParticle(rng, rMin, rMax));
  return g;
}

}  // namespace

// ---------------------------------------------------------------------------------- fog --

TEST(VdbFog, GridsClassesAndMetadata) {
  Context ctx;
  Group& g = makeGroup(ctx, "smoke", 300, 0.02f, 0.08f, 1);
  const fs::path path = scratch("fog_meta") / "smoke.0001.vdb";
  vdb::ExportOptions o;
  o.points = false;
  const vdb::FileStats st = vdb::writeFile(path, g, o);
  EXPECT_EQ(st.bytes, fs::file_size(path));
  VdbFile f(path);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"Cd", "density", "vel"}));
  auto density = f.get<openvdb::FloatGrid>("density");
  auto vel = f.get<openvdb::Vec3SGrid>("vel");
  auto cd = f.get<openvdb::Vec3SGrid>("Cd");
  ASSERT_TRUE(density && vel && cd);
  EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
  EXPECT_EQ(vel->getVectorType(), openvdb::VEC_CONTRAVARIANT_RELATIVE);
  EXPECT_EQ(vel->metaValue<std::string>("units"), "world units per second");
  EXPECT_EQ(f.meta->metaValue<std::string>("flurry:velocity_units"), "world units per second");
  EXPECT_EQ(cd->getVectorType(), openvdb::VEC_INVARIANT);
  EXPECT_EQ(f.meta->metaValue<std::string>("flurry:groups"), "smoke");
  EXPECT_EQ(density->activeVoxelCount(), st.fogVoxels);
  EXPECT_EQ(vel->activeVoxelCount(), density->activeVoxelCount());
  EXPECT_EQ(cd->activeVoxelCount(), density->activeVoxelCount());
  // Automatic voxel size: half the median radius.
  std::vector<float> radii(g.lane(Attribute::Size).begin(), g.lane(Attribute::Size).end());
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  EXPECT_FLOAT_EQ(float(density->voxelSize()[0]), 0.5f * radii[radii.size() / 2]);
}

TEST(VdbFog, DensityIntegralEqualsParticleMass) {
  // Radii from a tenth of a voxel to six voxels, at arbitrary offsets against the grid.
  Context ctx;
  Group& g = makeGroup(ctx, "mix", 1000, 0.001f, 0.06f, 2);
  vdb::ExportOptions o;
  o.points = false;
  o.fogVoxelSize = 0.01f;
  o.density = 2.5f;
  const fs::path path = scratch("fog_mass") / "mix.vdb";
  const vdb::FileStats st = vdb::writeFile(path, g, o);
  double expected = 0.0;
  for (float r : g.lane(Attribute::Size)) expected += sphereMass(r, 2.5f);
  VdbFile f(path);
  auto density = f.get<openvdb::FloatGrid>("density");
  ASSERT_TRUE(density);
  EXPECT_NEAR(integral(*density), expected, kMassTolerance * expected);
  EXPECT_NEAR(st.mass, expected, 1e-9 * expected);
  EXPECT_NEAR(f.meta->metaValue<double>("flurry:mass"), expected, 1e-9 * expected);
}

TEST(VdbFog, ParticlesSmallerThanAVoxelKeepTheirMass) {
  Context ctx;
  Group& g = makeGroup(ctx, "dust", 500, 0.002f, 0.01f, 3);  // voxel 0.1: radius 0.02-0.1 voxel
  vdb::ExportOptions o;
  o.points = false;
  o.fogVoxelSize = 0.1f;
  const fs::path path = scratch("fog_small") / "dust.vdb";
  vdb::writeFile(path, g, o);
  double expected = 0.0;
  for (float r : g.lane(Attribute::Size)) expected += sphereMass(r);
  VdbFile f(path);
  EXPECT_NEAR(integral(*f.get<openvdb::FloatGrid>("density")), expected, kMassTolerance * expected);
}

TEST(VdbFog, BoundsVelocityAndColor) {
  Context ctx;
  Group& g = makeGroup(ctx, "few", 40, 0.03f, 0.06f, 4);
  vdb::ExportOptions o;
  o.points = false;
  o.fogVoxelSize = 0.01f;
  const fs::path path = scratch("fog_bounds") / "few.vdb";
  vdb::writeFile(path, g, o);
  VdbFile f(path);
  auto density = f.get<openvdb::FloatGrid>("density");
  // Every active voxel lies inside some particle's kernel (radius max(r, 1.5 voxels)), and
  // every particle's own voxel is active.
  const auto& xf = density->transform();
  std::vector<Particle> ps;
  for (std::size_t i = 0; i < g.size(); ++i) ps.push_back(g.particle(i));
  for (auto it = density->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3d w = xf.indexToWorld(it.getCoord());
    bool inside = false;
    for (const Particle& p : ps) {
      const double h = std::max(double(p.size), 1.5 * 0.01) + 1e-6;
      inside |= (w - openvdb::Vec3d(p.position.x, p.position.y, p.position.z)).length() <= h;
    }
    ASSERT_TRUE(inside) << "voxel " << it.getCoord() << " outside every particle";
    EXPECT_GT(*it, 0.0f);
  }
  for (const Particle& p : ps) {
    const openvdb::Coord c =
        xf.worldToIndexCellCentered(openvdb::Vec3d(p.position.x, p.position.y, p.position.z));
    EXPECT_TRUE(density->tree().isValueOn(c));
  }

  // One lone particle: vel and Cd are its own everywhere it reaches.
  Group& one = ctx.createGroup("one", 1);
  one.require(AttributeSet{Attribute::Velocity, Attribute::Color, Attribute::Size});
  Particle p;
  p.position = Vec3(0.123f, -0.456f, 0.789f);
  p.velocity = Vec3(1.5f, -2.0f, 0.25f);
  p.color = Vec4(0.2f, 0.4f, 0.8f, 1.0f);
  p.size = 0.05f;
  one.add(p);
  vdb::writeFile(path, one, o);
  VdbFile f1(path);
  auto vel = f1.get<openvdb::Vec3SGrid>("vel");
  auto cd = f1.get<openvdb::Vec3SGrid>("Cd");
  ASSERT_GT(vel->activeVoxelCount(), 100u);
  for (auto it = vel->cbeginValueOn(); it; ++it)
    ASSERT_TRUE(it->eq(openvdb::Vec3s(1.5f, -2.0f, 0.25f), 1e-5f)) << *it;
  for (auto it = cd->cbeginValueOn(); it; ++it)
    ASSERT_TRUE(it->eq(openvdb::Vec3s(0.2f, 0.4f, 0.8f), 1e-5f)) << *it;
}

// ------------------------------------------------------------------------------- points --

namespace {

struct ReadPoint {
  openvdb::Vec3d p;
  openvdb::Vec3f v, cd;
  float pscale, age;
};

std::map<std::int64_t, ReadPoint> readPoints(const openvdb::points::PointDataGrid& grid) {
  namespace pts = openvdb::points;
  std::map<std::int64_t, ReadPoint> out;
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
    const auto& desc = leaf->attributeSet().descriptor();
    EXPECT_EQ(desc.valueType(desc.find("id")), "int64");
    pts::AttributeHandle<openvdb::Vec3f> P(leaf->constAttributeArray("P"));
    pts::AttributeHandle<std::int64_t> id(leaf->constAttributeArray("id"));
    pts::AttributeHandle<float> pscale(leaf->constAttributeArray("pscale"));
    const bool full = desc.find("v") != pts::AttributeSet::INVALID_POS;
    std::unique_ptr<pts::AttributeHandle<openvdb::Vec3f>> v, cd;
    std::unique_ptr<pts::AttributeHandle<float>> age;
    if (full) {
      v = std::make_unique<pts::AttributeHandle<openvdb::Vec3f>>(leaf->constAttributeArray("v"));
      cd = std::make_unique<pts::AttributeHandle<openvdb::Vec3f>>(leaf->constAttributeArray("Cd"));
      age = std::make_unique<pts::AttributeHandle<float>>(leaf->constAttributeArray("age"));
    }
    for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
      ReadPoint r{};
      r.p = grid.transform().indexToWorld(idx.getCoord().asVec3d() + P.get(*idx));
      r.pscale = pscale.get(*idx);
      if (full) {
        r.v = v->get(*idx);
        r.cd = cd->get(*idx);
        r.age = age->get(*idx);
      }
      EXPECT_TRUE(out.emplace(id.get(*idx), r).second) << "duplicate id " << id.get(*idx);
    }
  }
  return out;
}

}  // namespace

TEST(VdbPoints, AttributesEqualTheGroups) {
  Context ctx;
  Group& g = makeGroup(ctx, "spray", 5000, 0.01f, 0.05f, 5);
  const fs::path path = scratch("points") / "spray.vdb";
  vdb::ExportOptions o;
  o.fog = false;
  const vdb::FileStats st = vdb::writeFile(path, g, o);
  VdbFile f(path);
  EXPECT_EQ(f.names(), std::vector<std::string>{"points"});
  auto grid = f.get<openvdb::points::PointDataGrid>("points");
  ASSERT_TRUE(grid);
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), g.size());
  EXPECT_EQ(st.points, g.size());
  const auto& desc = grid->tree().cbeginLeaf()->attributeSet().descriptor();
  for (const char* a : {"P", "v", "Cd", "pscale", "id", "age"})
    EXPECT_NE(desc.find(a), openvdb::points::AttributeSet::INVALID_POS) << a;
  // About 8 points per voxel: the mean over occupied voxels of a uniform cloud.
  const double perVoxel = double(g.size()) / double(grid->tree().activeVoxelCount());
  EXPECT_GT(perVoxel, 3.0);
  EXPECT_LT(perVoxel, 16.0);

  const auto read = readPoints(*grid);
  ASSERT_EQ(read.size(), g.size());
  const double vs = grid->voxelSize()[0];
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    const auto it = read.find(p.id);
    ASSERT_NE(it, read.end()) << "id " << p.id;
    const ReadPoint& r = it->second;
    // Stored as a float offset inside its voxel: exact to float rounding of voxel + offset.
    const double tol = 1e-6 * (1.0 + vs);
    EXPECT_NEAR(r.p.x(), p.position.x, tol);
    EXPECT_NEAR(r.p.y(), p.position.y, tol);
    EXPECT_NEAR(r.p.z(), p.position.z, tol);
    EXPECT_EQ(r.v, openvdb::Vec3f(p.velocity.x, p.velocity.y, p.velocity.z));
    EXPECT_EQ(r.cd, openvdb::Vec3f(p.color.x, p.color.y, p.color.z));
    EXPECT_EQ(r.pscale, p.size);
    EXPECT_EQ(r.age, p.age);
  }
}

TEST(VdbPoints, HiddenParticlesAreLeftOutUnlessKept) {
  Context ctx;
  Group& g = ctx.createGroup("blocked", 100);
  g.require(AttributeSet{Attribute::Visible, Attribute::Size});
  std::mt19937 rng(6);
  std::size_t visible = 0;
  for (int i = 0; i < 100; ++i) {
    Particle p = makeParticle(rng, 0.02f, 0.02f);
    p.visible = i % 3 != 0;
    visible += p.visible;
    g.add(p);
  }
  const fs::path dir = scratch("hidden");
  vdb::writeFile(dir / "a.vdb", g);
  VdbFile f(dir / "a.vdb");
  auto grid = f.get<openvdb::points::PointDataGrid>("points");
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), visible);
  for (const auto& [id, r] : readPoints(*grid)) EXPECT_NE(id % 3, 0) << "hidden id exported";
  EXPECT_EQ(f.meta->metaValue<std::int64_t>("flurry:hidden_left_out"), std::int64_t(100 - visible));
  // Only the visible particles' mass is in the fog.
  EXPECT_NEAR(integral(*f.get<openvdb::FloatGrid>("density")), visible * sphereMass(0.02f),
              kMassTolerance * visible * sphereMass(0.02f));

  vdb::ExportOptions keep;
  keep.keepHidden = true;
  vdb::writeFile(dir / "b.vdb", g, keep);
  VdbFile fb(dir / "b.vdb");
  EXPECT_EQ(openvdb::points::pointCount(fb.get<openvdb::points::PointDataGrid>("points")->tree()),
            100u);
}

TEST(VdbPoints, UnstoredAttributesAreLeftOutOrDefaulted) {
  // A group storing only position and id: P, id and pscale (the default radius) are written.
  Context ctx;
  Group& g = ctx.createGroup("bare", 10);
  std::mt19937 rng(7);
  for (int i = 0; i < 10; ++i) g.add(makeParticle(rng, 0.1f, 0.1f));
  ASSERT_FALSE(g.attributes().has(Attribute::Velocity));
  const fs::path path = scratch("bare") / "bare.vdb";
  vdb::ExportOptions o;
  o.defaultRadius = 0.07f;
  vdb::writeFile(path, g, o);
  VdbFile f(path);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"density", "points"}));  // no vel, no Cd
  auto grid = f.get<openvdb::points::PointDataGrid>("points");
  const auto& desc = grid->tree().cbeginLeaf()->attributeSet().descriptor();
  EXPECT_EQ(desc.size(), 3u);  // P, pscale, id
  for (const auto& [id, r] : readPoints(*grid)) EXPECT_EQ(r.pscale, 0.07f);
  EXPECT_NEAR(integral(*f.get<openvdb::FloatGrid>("density")), 10 * sphereMass(0.07f),
              kMassTolerance * 10 * sphereMass(0.07f));
}

TEST(VdbPoints, SeveralGroupsAndEmptyFrames) {
  Context ctx;
  Group& a = makeGroup(ctx, "a", 50, 0.02f, 0.03f, 8);
  Group& b = makeGroup(ctx, "b", 70, 0.02f, 0.03f, 9);
  Group& empty = ctx.createGroup("empty", 4);
  vdb::Frame frame;
  frame.number = 12;
  frame.groups = {vdb::Particles::capture(a), vdb::Particles::capture(b)};
  const fs::path dir = scratch("groups");
  vdb::writeFile(dir / "ab.vdb", frame);
  VdbFile f(dir / "ab.vdb");
  auto grid = f.get<openvdb::points::PointDataGrid>("points");
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), 120u);
  EXPECT_EQ(openvdb::points::pointCount(
                grid->tree(),
                openvdb::points::GroupFilter("b", grid->tree().cbeginLeaf()->attributeSet())),
            70u);
  EXPECT_EQ(f.meta->metaValue<std::int32_t>("flurry:frame"), 12);

  // An empty group still gives a complete file, so a sequence has no holes.
  vdb::writeFile(dir / "empty.vdb", empty);
  VdbFile fe(dir / "empty.vdb");
  EXPECT_EQ(fe.get<openvdb::FloatGrid>("density")->activeVoxelCount(), 0u);
  EXPECT_EQ(openvdb::points::pointCount(fe.get<openvdb::points::PointDataGrid>("points")->tree()),
            0u);
}

// ------------------------------------------------------------------------------- strands --

TEST(VdbStrands, TubeVolumeWithVaryingThickness) {
  Strands s;
  // A straight strand along x, radius 0.1 -> 0.02, red -> blue.
  std::vector<Vec3> p;
  std::vector<Vec4> c;
  std::vector<float> r;
  for (int i = 0; i <= 10; ++i) {
    const float t = float(i) / 10;
    p.push_back(Vec3(t, 0.0f, 0.0f));
    c.push_back(Vec4(1 - t, 0, t, 1));
    r.push_back(0.1f + (0.02f - 0.1f) * t);
  }
  s.add(p, c, r);
  // A helix of constant radius.
  p.clear(), c.clear(), r.clear();
  for (int i = 0; i <= 60; ++i) {
    const float a = float(i) * 0.2f;
    p.push_back(Vec3(std::cos(a) * 0.3f, 1.0f + 0.02f * float(i), std::sin(a) * 0.3f));
    c.push_back(Vec4(1.0f));
    r.push_back(0.015f);
  }
  s.add(p, c, r);

  double expected = 0.0;
  for (std::size_t k = 0; k < s.size(); ++k)
    for (std::uint32_t a = s.start[k]; a + 1 < s.start[k + 1]; ++a) {
      const double len = glm::length(glm::dvec3(s.position[a + 1]) - glm::dvec3(s.position[a]));
      const double r0 = s.radius[a], r1 = s.radius[a + 1];
      expected += std::numbers::pi * len * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
    }
  vdb::ExportOptions o;
  o.fogVoxelSize = 0.01f;
  const fs::path path = scratch("strands") / "hair.vdb";
  const vdb::FileStats st = vdb::writeFog(path, s, o);
  EXPECT_NEAR(st.mass, expected, 1e-9 * expected);
  VdbFile f(path);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"Cd", "density"}));
  auto density = f.get<openvdb::FloatGrid>("density");
  EXPECT_NEAR(integral(*density), expected, kMassTolerance * expected);

  // Along the straight strand: the mass of a slab is π r(x)² per unit length, and the tube
  // reaches about r(x) from the axis.
  auto cd = f.get<openvdb::Vec3SGrid>("Cd");
  auto cda = cd->getConstAccessor();
  for (double x : {0.2, 0.5, 0.8}) {
    const double rx = 0.1 + (0.02 - 0.1) * x;
    const int i0 = int(std::lround(x / 0.01));
    double mass = 0.0, reach = 0.0;
    for (auto it = density->cbeginValueOn(); it; ++it) {
      const openvdb::Coord ijk = it.getCoord();
      if (ijk.y() > 50 || std::abs(ijk.x() - i0) > 5) continue;  // the straight strand only
      mass += double(*it) * 1e-6;
      reach = std::max(reach, 0.01 * std::hypot(double(ijk.y()), double(ijk.z())));
    }
    const double perLength = mass / (11 * 0.01);
    EXPECT_NEAR(perLength, std::numbers::pi * rx * rx, 0.03 * std::numbers::pi * rx * rx)
        << "at x=" << x;
    EXPECT_NEAR(reach, rx, 0.015) << "at x=" << x;
    const openvdb::Vec3s col = cda.getValue(openvdb::Coord(i0, 0, 0));
    EXPECT_NEAR(col.x(), 1 - x, 0.06) << "at x=" << x;
    EXPECT_NEAR(col.z(), x, 0.06) << "at x=" << x;
  }
}

TEST(VdbStrands, PointsRebuildTheCurves) {
  // Two sets of strands (two hair groups): ids run on across them.
  Strands a, b;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), c(0.0f, 1.0f);
  auto strand = [&](Strands& s, int n) {
    std::vector<Vec3> p;
    std::vector<Vec4> col;
    std::vector<float> r;
    Vec3 x(u(rng), u(rng), u(rng));
    for (int i = 0; i < n; ++i) {
      p.push_back(x);
      x += 0.05f * Vec3(u(rng), 1.0f, u(rng));
      col.push_back(Vec4(c(rng), c(rng), c(rng), 1.0f));
      r.push_back(0.001f + 0.01f * c(rng));
    }
    s.add(p, col, r);
  };
  for (int k = 0; k < 40; ++k) strand(a, 2 + k % 17);
  for (int k = 0; k < 25; ++k) strand(b, 5 + k % 9);
  const std::vector<const Strands*> sets{&a, &b};
  vdb::Frame frame;
  frame.strands = {a, b};
  vdb::ExportOptions o;
  o.fogVoxelSize = 0.05f;  // the fog is not what this test checks
  const fs::path path = scratch("strand_points") / "hair.vdb";
  const vdb::FileStats st = vdb::writeFile(path, frame, o);
  EXPECT_EQ(st.strandVertices, a.vertexCount() + b.vertexCount());
  EXPECT_GT(st.strandsVoxelSize, 0.0f);
  VdbFile f(path);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"Cd", "density", "points", "strands"}));
  auto grid = f.get<openvdb::points::PointDataGrid>("strands");
  ASSERT_TRUE(grid);
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), st.strandVertices);
  EXPECT_EQ(grid->metaValue<std::string>("pscale_meaning"), "radius");

  // Read every point back, keyed by (strand, vertex): what a user rebuilds curves from.
  namespace pts = openvdb::points;
  struct V {
    openvdb::Vec3d p;
    openvdb::Vec3f cd;
    float pscale;
  };
  std::map<std::pair<std::int32_t, std::int32_t>, V> read;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const auto& desc = leaf->attributeSet().descriptor();
    ASSERT_EQ(desc.valueType(desc.find("strand_id")), "int32");
    ASSERT_EQ(desc.valueType(desc.find("strand_vertex")), "int32");
    pts::AttributeHandle<openvdb::Vec3f> P(leaf->constAttributeArray("P"));
    pts::AttributeHandle<openvdb::Vec3f> cd(leaf->constAttributeArray("Cd"));
    pts::AttributeHandle<float> pscale(leaf->constAttributeArray("pscale"));
    pts::AttributeHandle<std::int32_t> sid(leaf->constAttributeArray("strand_id"));
    pts::AttributeHandle<std::int32_t> vtx(leaf->constAttributeArray("strand_vertex"));
    for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
      const V v{grid->transform().indexToWorld(idx.getCoord().asVec3d() + P.get(*idx)),
                cd.get(*idx), pscale.get(*idx)};
      EXPECT_TRUE(read.emplace(std::make_pair(sid.get(*idx), vtx.get(*idx)), v).second)
          << "strand " << sid.get(*idx) << " vertex " << vtx.get(*idx) << " twice";
    }
  }
  ASSERT_EQ(read.size(), st.strandVertices);
  std::int32_t id = 0;
  for (const Strands* s : sets)
    for (std::size_t k = 0; k < s->size(); ++k, ++id)
      for (std::uint32_t i = s->start[k]; i < s->start[k + 1]; ++i) {
        const auto it = read.find({id, std::int32_t(i - s->start[k])});
        ASSERT_NE(it, read.end()) << "strand " << id << " vertex " << i - s->start[k];
        const V& v = it->second;
        const double tol = 1e-6 * (1.0 + grid->voxelSize()[0]);
        EXPECT_NEAR(v.p.x(), s->position[i].x, tol);
        EXPECT_NEAR(v.p.y(), s->position[i].y, tol);
        EXPECT_NEAR(v.p.z(), s->position[i].z, tol);
        EXPECT_EQ(v.cd, openvdb::Vec3f(s->color[i].x, s->color[i].y, s->color[i].z));
        EXPECT_EQ(v.pscale, s->radius[i]);
      }

  // writeFog and --vdb-fog write no points of either kind.
  o.points = false;
  EXPECT_EQ(vdb::writeFile(path, frame, o).strandVertices, 0u);
  EXPECT_EQ(VdbFile(path).names(), (std::vector<std::string>{"Cd", "density"}));
}

TEST(VdbStrands, AutomaticVoxelSizeSuitsThinStrands) {
  // Thin strands (radius 0.002) with vertices 0.05 apart: voxels of half a segment, not of
  // half the radius (which would be 25 times finer: millions of voxels for a head of hair).
  auto strands = [](float radius, float segment, float apart = 0.1f) {
    Strands s;
    for (int k = 0; k < 20; ++k) {
      std::vector<Vec3> p;
      for (int i = 0; i < 10; ++i) p.push_back(Vec3(apart * float(k), segment * float(i), 0.0f));
      s.add(p, std::vector<Vec4>(p.size(), Vec4(1.0f)), std::vector<float>(p.size(), radius));
    }
    return s;
  };
  vdb::Frame thin;
  thin.strands.push_back(strands(0.002f, 0.05f));
  EXPECT_FLOAT_EQ(vdb::fogVoxelSize(thin), 0.025f);
  // The strands set it, not how far apart they lie (the scene's extent).
  vdb::Frame spread;
  spread.strands.push_back(strands(0.002f, 0.05f, 10.0f));
  EXPECT_FLOAT_EQ(vdb::fogVoxelSize(spread), 0.025f);
  // A thick strand still gets four voxels across.
  vdb::Frame thick;
  thick.strands.push_back(strands(0.1f, 0.05f));
  EXPECT_FLOAT_EQ(vdb::fogVoxelSize(thick), 0.05f);
  // Particles are unchanged: half the median radius.
  vdb::Frame particles;
  vdb::Particles p;
  for (int i = 0; i < 5; ++i) {
    p.position.push_back(Vec3(float(i), 0.0f, 0.0f));
    p.id.push_back(std::uint32_t(i));
    p.radius.push_back(0.01f * float(i + 1));
  }
  particles.groups.push_back(p);
  EXPECT_FLOAT_EQ(vdb::fogVoxelSize(particles), 0.015f);
  // The thin strands' fog stays small and keeps their whole tube volume.
  const fs::path path = scratch("thin_strands") / "hair.vdb";
  vdb::ExportOptions o;
  o.points = false;
  const vdb::FileStats st = vdb::writeFile(path, thin, o);
  EXPECT_FLOAT_EQ(st.fogVoxelSize, 0.025f);
  const double tube = 20 * 9 * std::numbers::pi * 0.002 * 0.002 * 0.05;
  EXPECT_NEAR(st.mass, tube, 1e-6 * tube);  // float vertices and radii
  EXPECT_NEAR(integral(*VdbFile(path).get<openvdb::FloatGrid>("density")), tube,
              kMassTolerance * tube);
}

TEST(VdbStrands, AutomaticVoxelSizeFitsTheMemoryCap) {
  // Fine strands, n of 500 vertices 0.001 apart on a grid 0.01 apart (no two kernels
  // overlap): half a segment is 0.0005, and each segment then covers ~14 voxels.
  auto strands = [](int n) {
    Strands s;
    for (int k = 0; k < n; ++k) {
      for (int i = 0; i < 500; ++i)
        s.position.push_back(Vec3(0.01f * float(k % 64), 0.001f * float(i), 0.01f * float(k / 64)));
      s.radius.insert(s.radius.end(), 500, 0.0004f);
      s.start.push_back(std::uint32_t(s.position.size()));
    }
    return s;
  };
  // 3000 strands: ~21 million voxels at 0.0005, over the default cap of 2^24: coarser.
  vdb::Frame big;
  big.strands.push_back(strands(3000));
  const float capped = vdb::fogVoxelSize(big);
  EXPECT_GT(capped, 0.0005f * 1.05f);
  // Just coarse enough: a tube at the least kernel width has voxels as 1/size, so ~21/16.8.
  EXPECT_LT(capped, 0.0005f * 1.5f);
  vdb::ExportOptions uncapped;
  uncapped.fogMaxVoxels = 0;
  EXPECT_NEAR(vdb::fogVoxelSize(big, uncapped), 0.0005f, 1e-8f);  // float vertices
  // Under the cap the size is the strands' own.
  vdb::Frame few;
  few.strands.push_back(strands(40));
  EXPECT_NEAR(vdb::fogVoxelSize(few), 0.0005f, 1e-8f);
  // A small cap, written: the active voxels fit it without being far under it (the count is
  // estimated: voxel centres against a tube vary by a few percent), and the strands keep
  // their whole tube volume.
  vdb::ExportOptions o;
  o.points = false;
  o.fogMaxVoxels = 40'000;  // 40 strands ask for ~280k
  const fs::path path = scratch("capped_strands") / "hair.vdb";
  const vdb::FileStats st = vdb::writeFile(path, few, o);
  EXPECT_EQ(st.fogVoxelSize, vdb::fogVoxelSize(few, o));
  EXPECT_GT(st.fogVoxelSize, 0.001f);
  EXPECT_LE(st.fogVoxels, o.fogMaxVoxels * 11 / 10);
  EXPECT_GT(st.fogVoxels, o.fogMaxVoxels / 4);
  const double tube = 40 * 499 * std::numbers::pi * 0.0004 * 0.0004 * 0.001;
  EXPECT_NEAR(integral(*VdbFile(path).get<openvdb::FloatGrid>("density")), tube,
              kMassTolerance * tube);
}

// ------------------------------------------------------------------------------ sequence --

TEST(VdbSequence, OneFilePerFrameMatchingTheLiveGroup) {
  Context ctx({.seed = 3, .dt = 1.0 / 30});
  Group& g = samples::buildFountain(ctx, 20000, 1500.0, 2.0f);
  const fs::path dir = scratch("sequence");
  vdb::SequenceOptions so;
  so.folder = dir / "sub";  // created
  so.name = "fountain";
  vdb::SequenceWriter w(so);
  g.require(AttributeSet{Attribute::Velocity, Attribute::Color, Attribute::Size, Attribute::Age});
  std::map<int, std::size_t> live;
  std::map<int, double> mass;
  for (int frame = 1; frame <= 20; ++frame) {
    ctx.step();
    if (frame % 5) continue;
    live[frame] = g.size();
    double m = 0.0;
    for (float r : g.lane(Attribute::Size)) m += sphereMass(r);
    mass[frame] = m;
    w.write(g, frame, ctx.time());
  }
  const vdb::ExportCost cost = w.finish();
  EXPECT_EQ(cost.files, 4u);
  EXPECT_GT(cost.bytesPerFrame(), 1000.0);
  EXPECT_GT(cost.secondsPerFrame(), 0.0);
  EXPECT_EQ(w.pathFor(5), dir / "sub" / "fountain.0005.vdb");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir / "sub")) {
    ++files;
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
  }
  EXPECT_EQ(files, 4u);
  for (const auto& [frame, n] : live) {
    VdbFile f(w.pathFor(frame));
    EXPECT_EQ(f.meta->metaValue<std::int32_t>("flurry:frame"), frame);
    EXPECT_NEAR(f.meta->metaValue<double>("flurry:time"), frame / 30.0, 1e-9);
    EXPECT_EQ(openvdb::points::pointCount(f.get<openvdb::points::PointDataGrid>("points")->tree()),
              n);
    EXPECT_NEAR(integral(*f.get<openvdb::FloatGrid>("density")), mass[frame],
                kMassTolerance * mass[frame]);
  }
}

// -------------------------------------------------------------------------------- errors --

TEST(VdbErrors, UnwritableFolderNamesThePath) {
  const fs::path dir = scratch("unwritable");
  std::ofstream(dir / "file") << "x";
  // A path under a regular file fails with ENOTDIR even for root.
  const fs::path bad = dir / "file" / "out";
  try {
    vdb::SequenceOptions so;
    so.folder = bad;
    vdb::SequenceWriter w(so);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), bad.string());
  }
  Context ctx;
  Group& g = makeGroup(ctx, "g", 10, 0.02f, 0.03f, 10);
  try {
    vdb::writeFile(bad / "x.vdb", g);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), (bad / "x.vdb").string());
    EXPECT_NE(std::string(e.what()).find("Not a directory"), std::string::npos) << e.what();
  }
}

TEST(VdbErrors, WorkerErrorSurfacesOnTheNextCallAndFinish) {
  const fs::path dir = scratch("worker_error");
  Context ctx;
  Group& g = makeGroup(ctx, "g", 10, 0.02f, 0.03f, 11);
  vdb::SequenceOptions so;
  so.folder = dir / "out";
  so.name = "g";
  vdb::SequenceWriter w(so);
  w.write(g, 1, 0.0);
  EXPECT_EQ(w.finish().files, 1u);
  // The folder disappears under the writer and a file takes its name.
  fs::remove_all(dir / "out");
  std::ofstream(dir / "out") << "x";
  w.write(g, 2, 0.1);
  try {
    w.finish();
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), w.pathFor(2).string());
  }
  EXPECT_THROW(w.write(g, 3, 0.2), IoError);  // the sequence stays failed
}

TEST(VdbErrors, FullDiskLeavesNoFileAndNamesThePath) {
  // A file-size limit makes write() fail part way (EFBIG), as a full disk does (ENOSPC).
  const fs::path dir = scratch("full");
  Context ctx;
  Group& g = makeGroup(ctx, "g", 2000, 0.02f, 0.05f, 12);
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  auto oldHandler = ::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 16 * 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string what, path;
  try {
    vdb::writeFile(dir / "big.vdb", g);
  } catch (const IoError& e) {
    what = e.what();
    path = e.path();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  ::signal(SIGXFSZ, oldHandler);
  EXPECT_EQ(path, (dir / "big.vdb").string());
  EXPECT_NE(what.find("write failed"), std::string::npos) << what;
  EXPECT_TRUE(fs::is_empty(dir)) << "a partial or temporary file was left";
}

TEST(VdbErrors, BadOptionsAndParticles) {
  Context ctx;
  Group& g = makeGroup(ctx, "g", 10, 0.02f, 0.03f, 13);
  const fs::path dir = scratch("bad");
  vdb::ExportOptions o;
  o.fogVoxelSize = -1;
  EXPECT_THROW(vdb::writeFile(dir / "a.vdb", g, o), InvalidArgument);
  o = {};
  o.fogVoxelSize = 1e-6f;  // particles thousands of voxels across
  EXPECT_THROW(vdb::writeFile(dir / "a.vdb", g, o), InvalidArgument);
  g.lane(Attribute::Position, 1)[3] = std::nanf("");
  try {
    vdb::writeFile(dir / "a.vdb", g);
    FAIL() << "no error";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(e.parameter(), "groups[0].position[3]");
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

// A crash between write and rename: the child process is killed in the hook, after the
// temporary of frame 4 is complete and before its rename.
TEST(VdbCrash, Child) {
  const char* dir = std::getenv("FLURRY_VDB_CRASH_DIR");
  if (!dir) GTEST_SKIP() << "run by VdbCrash.KilledBetweenWriteAndRename";
  Context ctx;
  Group& g = makeGroup(ctx, "g", 100, 0.02f, 0.03f, 14);
  vdb::SequenceOptions so;
  so.folder = dir;
  so.name = "crash";
  vdb::SequenceWriter w(so);
  for (int f = 1; f <= 3; ++f) w.write(g, f, f * 0.1);
  w.finish();
  vdb::detail::beforeRename = [](const fs::path&, const fs::path& final) {
    if (final.filename() == "crash.0004.vdb") ::raise(SIGKILL);
  };
  w.write(g, 4, 0.4);
  w.finish();
  FAIL() << "still alive";
}

TEST(VdbCrash, KilledBetweenWriteAndRename) {
  const fs::path dir = scratch("crash");
  const std::string env = "FLURRY_VDB_CRASH_DIR=" + dir.string();
  std::vector<char*> envp;
  for (char** e = environ; *e; ++e) envp.push_back(*e);
  envp.push_back(const_cast<char*>(env.c_str()));
  envp.push_back(nullptr);
  std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::string filter = "--gtest_filter=VdbCrash.Child";
  char* argv[] = {exe.data(), filter.data(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv, envp.data()), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;

  // Frames 1-3 intact, nothing under frame 4's name; its complete temporary is all there is.
  for (int f = 1; f <= 3; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "crash.%04d.vdb", f);
    VdbFile file(dir / name);
    EXPECT_EQ(
        openvdb::points::pointCount(file.get<openvdb::points::PointDataGrid>("points")->tree()),
        100u);
  }
  EXPECT_FALSE(fs::exists(dir / "crash.0004.vdb"));
  const fs::path tmp = dir / ("crash.0004.vdb.tmp." + std::to_string(pid));
  EXPECT_TRUE(fs::exists(tmp));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 4u);

  // The next sequence in the folder removes the temporaries of dead processes that match its
  // own name pattern exactly, and nothing else.
  const std::string dead = std::to_string(pid), live = std::to_string(::getpid());
  const std::vector<std::string> stale = {
      "crash.0004.vdb.tmp." + dead, "crash.-001.vdb.tmp." + dead,
      "crash.17.vdb.tmp.999999999",  // beyond any pid_max: never a running process
  };
  const std::vector<std::string> kept = {
      "crash.0005.vdb.tmp." + live,  // a running process's (this one)
      "crash.0005.vdb.tmp.1",        // init's: running
      "other.0004.vdb.tmp." + dead,  // another sequence's
      "crash.0004.vdb.tmp." + dead + "x",
      "crash.0004.vdb.tmp.0" + dead,
      "crash.0004.vdb.tmp.",
      "crash.x004.vdb.tmp." + dead,
      "crash.0004.vdbx.tmp." + dead,
      "crash.0004.png.tmp." + dead,
      "xcrash.0004.vdb.tmp." + dead,
      "crash.0004.vdb.tmp.99999999999999999999",  // not a pid_t
  };
  for (const std::string& n : stale) std::ofstream(dir / n) << "partial";
  for (const std::string& n : kept) std::ofstream(dir / n) << "partial";
  fs::create_directory(dir / ("crash.0006.vdb.tmp." + dead));  // not a file: kept
  fs::create_symlink(dir / "crash.0001.vdb", dir / ("crash.0007.vdb.tmp." + dead));
  {
    vdb::SequenceOptions so;
    so.folder = dir;
    so.name = "crash";
    vdb::SequenceWriter w(so);
    std::vector<std::string> removed;
    for (const fs::path& p : w.removedTemporaries()) removed.push_back(p.filename().string());
    std::sort(removed.begin(), removed.end());
    std::vector<std::string> expected = stale;
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(removed, expected);
    // The sequence goes on where the killed run stopped.
    Context ctx;
    w.write(makeGroup(ctx, "g", 100, 0.02f, 0.03f, 14), 4, 0.4);
    w.finish();
  }
  for (const std::string& n : stale) EXPECT_FALSE(fs::exists(dir / n)) << n;
  for (const std::string& n : kept) EXPECT_TRUE(fs::exists(dir / n)) << n;
  EXPECT_TRUE(fs::is_directory(dir / ("crash.0006.vdb.tmp." + dead)));
  EXPECT_TRUE(fs::is_symlink(dir / ("crash.0007.vdb.tmp." + dead)));
  for (int f = 1; f <= 4; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "crash.%04d.vdb", f);
    EXPECT_EQ(openvdb::points::pointCount(
                  VdbFile(dir / name).get<openvdb::points::PointDataGrid>("points")->tree()),
              100u);
  }

  // Turned off, nothing is removed.
  std::ofstream(dir / stale[0]) << "partial";
  vdb::SequenceOptions so;
  so.folder = dir;
  so.name = "crash";
  so.cleanStaleTemporaries = false;
  vdb::SequenceWriter w(so);
  EXPECT_TRUE(w.removedTemporaries().empty());
  EXPECT_TRUE(fs::exists(dir / stale[0]));
}

// -------------------------------------------------------------------------- vector fields --

namespace {

template <typename GridT>
fs::path writeGrid(const fs::path& path, typename GridT::Ptr grid) {
  openvdb::initialize();
  openvdb::io::File(path.string()).write(openvdb::GridPtrVec{grid});
  return path;
}

}  // namespace

TEST(VdbField, ReadsVec3GridsOverTheirActiveBox) {
  const fs::path dir = scratch("field");
  auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  auto xf = openvdb::math::Transform::createLinearTransform(0.5);
  xf->postTranslate(openvdb::Vec3d(1, 2, 3));
  grid->setTransform(xf);
  grid->setName("wind");
  auto f = [](int i, int j, int k) { return openvdb::Vec3s(float(i), 2.0f * j, 3.0f * k + 1); };
  for (int k = 0; k <= 5; ++k)
    for (int j = -1; j <= 4; ++j)
      for (int i = -2; i <= 3; ++i) grid->tree().setValueOn(openvdb::Coord(i, j, k), f(i, j, k));
  auto scalar = openvdb::FloatGrid::create();
  scalar->setName("density");
  openvdb::io::File((dir / "wind.vdb").string()).write(openvdb::GridPtrVec{scalar, grid});

  const VectorField field = vdb::readVectorField(dir / "wind.vdb", "wind");
  EXPECT_EQ(field.dims, glm::ivec3(6, 6, 6));
  EXPECT_FLOAT_EQ(field.voxelSize, 0.5f);
  EXPECT_EQ(field.origin, Vec3(0.0f, 1.5f, 3.0f));
  // At a voxel centre and between centres (the field is linear: trilinear is exact).
  EXPECT_EQ(field.sample(Vec3(1.0f, 2.0f, 3.0f)), Vec3(0, 0, 1));
  const Vec3 s = field.sample(Vec3(1.25f, 2.25f, 3.75f));  // index (0.5, 0.5, 1.5)
  EXPECT_NEAR(s.x, 0.5f, 1e-6f);
  EXPECT_NEAR(s.y, 1.0f, 1e-6f);
  EXPECT_NEAR(s.z, 5.5f, 1e-6f);
  // The first Vec3 grid when no name is given; a Vec3d grid too.
  EXPECT_EQ(vdb::readVectorField(dir / "wind.vdb").dims, glm::ivec3(6, 6, 6));
  auto d = openvdb::Vec3DGrid::create();
  d->setName("vd");
  d->tree().setValueOn(openvdb::Coord(0, 0, 0), openvdb::Vec3d(1, 2, 3));
  writeGrid<openvdb::Vec3DGrid>(dir / "d.vdb", d);
  EXPECT_EQ(vdb::readVectorField(dir / "d.vdb", "vd").data, std::vector<Vec3>{Vec3(1, 2, 3)});

  // writeVectorField is its inverse.
  vdb::writeVectorField(dir / "round.vdb", field, "gust");
  const VectorField back = vdb::readVectorField(dir / "round.vdb", "gust");
  EXPECT_EQ(back.dims, field.dims);
  EXPECT_EQ(back.origin, field.origin);
  EXPECT_EQ(back.voxelSize, field.voxelSize);
  EXPECT_EQ(back.data, field.data);
}

TEST(VdbField, RefusesWhatItCannotSample) {
  const fs::path dir = scratch("field_bad");
  auto expectIo = [](const fs::path& p, const std::string& grid, const std::string& needle) {
    try {
      vdb::readVectorField(p, grid);
      ADD_FAILURE() << "no error for " << p;
    } catch (const IoError& e) {
      EXPECT_EQ(e.path(), p.string());
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectIo(dir / "missing.vdb", "vel", "o such file");
  auto scalar = openvdb::FloatGrid::create();
  scalar->setName("density");
  scalar->tree().setValueOn(openvdb::Coord(0), 1.0f);
  writeGrid<openvdb::FloatGrid>(dir / "s.vdb", scalar);
  expectIo(dir / "s.vdb", "vel", "has no grid named 'vel' (it has: density)");
  expectIo(dir / "s.vdb", "density", "not a Vec3");
  expectIo(dir / "s.vdb", "", "no Vec3 grid");

  auto rot = openvdb::Vec3SGrid::create();
  rot->setName("vel");
  rot->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1.0f));
  auto xf = openvdb::math::Transform::createLinearTransform(0.1);
  xf->postRotate(0.3, openvdb::math::Z_AXIS);
  rot->setTransform(xf);
  writeGrid<openvdb::Vec3SGrid>(dir / "rot.vdb", rot);
  expectIo(dir / "rot.vdb", "vel", "uniform scale");

  auto nan = openvdb::Vec3SGrid::create();
  nan->setName("vel");
  nan->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1.0f));
  nan->tree().setValueOn(openvdb::Coord(1, 0, 0), openvdb::Vec3s(0.0f, std::nanf(""), 0.0f));
  writeGrid<openvdb::Vec3SGrid>(dir / "nan.vdb", nan);
  try {
    vdb::readVectorField(dir / "nan.vdb", "vel");
    FAIL() << "NaN accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
    EXPECT_NE(e.parameter().find("nan.vdb:vel"), std::string::npos) << e.parameter();
  }
}
