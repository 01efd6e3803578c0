// The batch samplers' math, and the documented draw order of a newborn (the OpenCL backend
// draws the same numbers in the same order).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "flurry/flurry.hpp"
#include "leaf_shapes.hpp"
#include "sampling.hpp"
#include "shape_math.hpp"

using namespace flurry;

// Every instruction set's build of the batch draws (sdk/src/sampling.cpp), called directly so
// that each is checked on a CPU that has it, whichever the dispatcher would pick.
#define FLURRY_TEST_DECLARE_BATCH(isa)                                                         \
  namespace flurry::detail::isa {                                                              \
  void uniformBatch(std::uint64_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, \
                    std::size_t, float*, float*, float*, float*);                              \
  void uniformBatchOfIds(std::uint64_t, const std::uint32_t*, std::uint32_t, std::uint32_t,    \
                         std::uint32_t, std::size_t, float*, float*, float*, float*);          \
  }
#ifdef FLURRY_HAS_ISA_VARIANTS
FLURRY_TEST_DECLARE_BATCH(isa_avx2)
FLURRY_TEST_DECLARE_BATCH(isa_avx512)
#endif
#undef FLURRY_TEST_DECLARE_BATCH

TEST(Sampling, SinCos2PiMatchesLibm) {
  double worst = 0;
  for (int i = 0; i < 100000; ++i) {
    const float u = float(i) / 100000.0f;
    float s, c;
    detail::kernel::fl_sincos_2pi(u, &s, &c);
    worst = std::max(
        {worst, std::abs(s - std::sin(2 * M_PI * u)), std::abs(c - std::cos(2 * M_PI * u))});
  }
  EXPECT_LT(worst, 5e-7);
}

TEST(Sampling, CubeRootIsAccurate) {
  double worst = 0;
  for (int i = 0; i <= 100000; ++i) {
    const float x = std::pow(float(i) / 100000.0f, 3.0f) * 1000.0f;
    const double exact = std::cbrt(double(x));
    worst = std::max(worst,
                     std::abs(detail::kernel::fl_cbrt_nonneg(x) - exact) / std::max(exact, 1e-30));
  }
  EXPECT_LT(worst, 5e-7);
  EXPECT_EQ(detail::kernel::fl_cbrt_nonneg(0.0f), 0.0f);
}

// A newborn of a one-type emitter equals the one-by-one recipe: Random(seed, id, group index,
// stream::kEmission), velocity, then position, then lifetime, color, alpha, size.
TEST(Sampling, NewbornsFollowTheDocumentedDrawOrder) {
  ContextOptions o;
  o.seed = 1234;
  o.dt = 0.1;
  Context ctx(o);
  ctx.createGroup("other", 1);  // group index 0; ours is 1
  Group& g = ctx.createGroup("g", 1000);
  g.require({Attribute::Velocity, Attribute::Lifetime, Attribute::Color, Attribute::Size});
  Emitter e;
  e.shape = Domain::sphere(Vec3(1, 2, 3), 2.0f, 0.5f);
  e.bursts = {{0.0, 600, 0, 1}};  // > one batch of 256, born at t = 0: moved by v·dt
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0), Vec3(0, 3, 0), 1.0f);
  t.lifetime = Fuzzy(2.0f, 0.5f);
  t.color = Domain::box(Vec3(0), Vec3(1));
  t.alpha = Fuzzy(0.5f, 0.25f);
  t.size = Fuzzy(0.1f, 0.05f, Fuzzy::Distribution::Normal);
  e.types = {t};
  g.addEmitter(e);
  g.setActions({Move{}});
  ctx.step();
  ASSERT_EQ(g.size(), 600u);
  for (std::size_t i = 0; i < g.size(); i += 37) {
    const Particle p = g.particle(i);
    Random rng(1234, p.id, 1, stream::kEmission);
    const Vec3 vel = t.velocity.sample(rng);
    const Vec3 pos = e.shape.sample(rng) + vel * 0.1f;
    EXPECT_EQ(p.velocity, vel);
    EXPECT_NEAR(glm::length(p.position - pos), 0.0f, 1e-5f);
    EXPECT_EQ(p.lifetime, t.lifetime.sample(rng));
    const Vec3 rgb = t.color.sample(rng);
    EXPECT_EQ(Vec3(p.color), rgb);
    EXPECT_EQ(p.color.a, t.alpha.sample(rng));
    EXPECT_FLOAT_EQ(p.size, std::max(0.0f, t.size.sample(rng)));
  }
}

namespace {
struct BatchVariant {
  const char* name;
  bool supported;
  decltype(&detail::uniformBatch) consecutive;
  decltype(&detail::uniformBatchOfIds) listed;
};
std::vector<BatchVariant> batchVariants() {
  std::vector<BatchVariant> v = {
      {"this build", true, &detail::uniformBatch, &detail::uniformBatchOfIds}};
#ifdef FLURRY_HAS_ISA_VARIANTS
  __builtin_cpu_init();
  v.push_back({"avx2", __builtin_cpu_supports("avx2") != 0, &detail::isa_avx2::uniformBatch,
               &detail::isa_avx2::uniformBatchOfIds});
  v.push_back({"avx512",
               __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                   __builtin_cpu_supports("avx512vl"),
               &detail::isa_avx512::uniformBatch, &detail::isa_avx512::uniformBatchOfIds});
#endif
  return v;
}
std::uint32_t floatBits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}
}  // namespace

// The vectorised Philox draws are Philox4x32::generate + uniformFloat bit for bit, in every
// lane and in the partial last vector, and write nothing past n (the OpenCL backend and the
// one-by-one path draw the scalar function).
TEST(Sampling, UniformBatchIsScalarPhiloxBitForBit) {
  const std::uint64_t seeds[] = {0u, 1234u, 0xDEADBEEFCAFEF00Dull, ~0ull};
  std::vector<std::size_t> counts;
  for (std::size_t n = 0; n <= 40; ++n) counts.push_back(n);
  counts.push_back(1000);
  const std::uint32_t firsts[] = {0u, 7u, 0xFFFFFFF3u};  // the last wraps around
  constexpr std::size_t kGuard = 3;
  constexpr float kUntouched = -1.0f;
  std::vector<std::uint32_t> idStore(1000 + 5);
  for (std::size_t i = 0; i < idStore.size(); ++i)
    idStore[i] = std::uint32_t(i * 2654435761u) ^ 0x5A5A1234u;
  const std::uint32_t* ids = idStore.data() + 3;  // not vector-aligned
  std::size_t checked = 0;
  for (const BatchVariant& var : batchVariants()) {
    if (!var.supported) continue;
    for (std::uint64_t seed : seeds)
      for (std::size_t n : counts)
        for (int listed = 0; listed < 2; ++listed)
          for (std::uint32_t first : firsts) {
            if (listed && first != firsts[0]) continue;
            const std::uint32_t c1 = std::uint32_t(n) * 3u + 1u,
                                c2 = 0xFFFF0000u + std::uint32_t(n);
            const std::uint32_t block = std::uint32_t(seed) & 3u;
            std::vector<float> out[4];
            for (auto& o : out) o.assign(1 + n + kGuard, kUntouched);
            float* u[4];
            for (int w = 0; w < 4; ++w) u[w] = out[w].data() + 1;  // odd offsets
            if (listed)
              var.listed(seed, ids, c1, c2, block, n, u[0], u[1], u[2], u[3]);
            else
              var.consecutive(seed, first, c1, c2, block, n, u[0], u[1], u[2], u[3]);
            for (std::size_t i = 0; i < n; ++i) {
              const std::uint32_t c0 = listed ? ids[i] : first + std::uint32_t(i);
              const Philox4x32::Block b = Philox4x32::generate(
                  c0, c1, c2, block, std::uint32_t(seed), std::uint32_t(seed >> 32));
              for (int w = 0; w < 4; ++w)
                ASSERT_EQ(floatBits(u[w][i]), floatBits(uniformFloat(b.v[w])))
                    << var.name << (listed ? " listed ids" : " consecutive ids") << ", seed "
                    << seed << ", first " << first << ", n " << n << ", i " << i << ", word " << w;
            }
            for (int w = 0; w < 4; ++w) {
              EXPECT_EQ(out[w][0], kUntouched) << var.name << ", n " << n;
              for (std::size_t g = 0; g < kGuard; ++g)
                EXPECT_EQ(u[w][n + g], kUntouched) << var.name << ", n " << n;
            }
            ++checked;
          }
  }
  EXPECT_GT(checked, 0u);
}

// Every draw a domain may take, for n samples: rows of uniforms from the emission's stream
// (detail::uniformBatch, ids 0 ..), and pointers to them as the samplers take them.
struct Draws {
  std::vector<float> rows[detail::kMaxDomainDraws];
  const float* u[detail::kMaxDomainDraws];
  Draws(const Draws&) = delete;  // (u points into rows)
  Draws& operator=(const Draws&) = delete;
  Draws(std::size_t n, std::uint64_t seed, std::uint32_t c1, std::uint32_t c2) {
    for (int d = 0; d < detail::kMaxDomainDraws; ++d) {
      rows[d].resize(n);
      u[d] = rows[d].data();
    }
    for (int blk = 0; blk * 4 < detail::kMaxDomainDraws; ++blk)
      detail::uniformBatch(seed, 0, c1, c2, std::uint32_t(blk), n, rows[4 * blk].data(),
                           rows[4 * blk + 1].data(), rows[4 * blk + 2].data(),
                           rows[4 * blk + 3].data());
  }
};

// A union of many parts (past 256 its samples are sorted by part a byte of the part's index at
// a time): each sample is the sample its own draws give on the part it lies in, bit for bit.
TEST(Sampling, AUnionOfManyPartsSamplesEachOnItsPart) {
  for (const int count : {600, 70000}) {
    std::vector<Domain> parts;
    for (int k = 0; k < count; ++k)  // apart: a sample names its sphere by the nearest centre
      parts.push_back(Domain::sphere(Vec3(10.0f * float(k % 300), 10.0f * float(k / 300), 0.0f),
                                     1.0f + 0.5f * float(k % 3)));
    const Domain un = Domain::unite(parts);
    constexpr std::size_t n = 1000;  // four chunks, the last a part of one
    const Draws draws(n, 7, 3, 4);
    const float* const* u = draws.u;
    std::vector<float> x(n), y(n), z(n);
    detail::sampleBatch(un, u, n, x.data(), y.data(), z.data());
    std::vector<int> seen(std::size_t(count), 0);
    for (std::size_t i = 0; i < n; ++i) {
      const int col = int(std::lround(x[i] / 10.0f)), row = int(std::lround(y[i] / 10.0f));
      const int k = row * 300 + col;
      ASSERT_TRUE(k >= 0 && k < count) << count << " parts, sample " << i;
      ++seen[std::size_t(k)];
      // The part's own sample from draws 1.. of sample i (draw 0 picked the part).
      const float* own[detail::kMaxDomainDraws - 1];
      for (int d = 0; d + 1 < detail::kMaxDomainDraws; ++d) own[d] = u[d + 1] + i;
      float wx, wy, wz;
      detail::sampleBatch(parts[std::size_t(k)], own, 1, &wx, &wy, &wz);
      ASSERT_EQ(floatBits(x[i]), floatBits(wx)) << count << " parts, sample " << i;
      ASSERT_EQ(floatBits(y[i]), floatBits(wy)) << count << " parts, sample " << i;
      ASSERT_EQ(floatBits(z[i]), floatBits(wz)) << count << " parts, sample " << i;
    }
    // Several samples share a part (the grouping has runs to make), and many parts are hit.
    EXPECT_GT(*std::max_element(seen.begin(), seen.end()), 1) << count;
    EXPECT_GT(std::count_if(seen.begin(), seen.end(), [](int c) { return c > 0; }), 100) << count;
  }
}

// The normals of a batch's newborns along Emitter::normalSpeed: on every shape but a mesh
// and a union, Domain::normal's at the sampled point, bit for bit; on a mesh, the normal of a
// face the point lies on (the face its draw picked), and on a union the picked part's.
TEST(Sampling, SampledNormalsAreTheShapesNormalsWhereTheSamplesLanded) {
  const std::vector<Vec3> tv = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<glm::uvec3> tt = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const Domain tetra = Domain::mesh(tv, tt);
  std::vector<Domain> shapes = leafShapes();
  shapes.push_back(tetra);
  shapes.push_back(Domain::unite({Domain::sphere(Vec3(5.0f, 0.0f, 0.0f), 1.0f, 1.0f), tetra}));
  constexpr std::size_t n = 301;  // not whole vectors
  const Draws draws(n, 99, 5, 6);
  const float* const* u = draws.u;
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const Domain& d = shapes[s];
    std::vector<float> x(n), y(n), z(n), nx(n), ny(n), nz(n);
    detail::sampleBatch(d, u, n, x.data(), y.data(), z.data());
    detail::sampledNormals(d, u, n, x.data(), y.data(), z.data(), nx.data(), ny.data(), nz.data());
    const bool faces = s + 2 >= shapes.size();  // the tetrahedron, the union holding it
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 p(x[i], y[i], z[i]), nrm(nx[i], ny[i], nz[i]);
      if (!faces) {
        const Vec3 want = d.normal(p);
        ASSERT_EQ(floatBits(nrm.x), floatBits(want.x)) << d.name() << " " << i;
        ASSERT_EQ(floatBits(nrm.y), floatBits(want.y)) << d.name() << " " << i;
        ASSERT_EQ(floatBits(nrm.z), floatBits(want.z)) << d.name() << " " << i;
        continue;
      }
      if (p.x > 3.0f) {  // the union's sphere
        ASSERT_NEAR(glm::length(nrm - (p - Vec3(5.0f, 0.0f, 0.0f))), 0.0f, 1e-5f) << i;
        continue;
      }
      // One of the faces' outward normals, and the point on that face's plane.
      bool onItsFace = false;
      for (const glm::uvec3& f : tt) {
        const Vec3 a = tv[f.x], want = glm::normalize(glm::cross(tv[f.y] - a, tv[f.z] - a));
        if (glm::length(nrm - want) < 1e-6f) onItsFace = std::abs(glm::dot(p - a, want)) < 1e-6f;
      }
      ASSERT_TRUE(onItsFace) << d.name() << " " << i;
    }
  }
}
