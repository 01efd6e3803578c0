// Force fields and the other per-particle actions against their expected behaviour.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "flurry/flurry.hpp"
#include "forces_kernel.hpp"  // fl_curve_lookup: the device's walk, on the CPU
#include "noise.hpp"

using namespace flurry;

namespace {
Context makeContext(double dt = 0.01) {
  ContextOptions o;
  o.dt = dt;
  o.threads = 2;
  return Context(o);
}
Particle at(Vec3 p, Vec3 v = Vec3(0)) {
  Particle q;
  q.position = p;
  q.velocity = v;
  return q;
}
}  // namespace

// Issue #12 item 3: softened forces with a tiny epsilon leave a particle at the centre untouched
// (the header's promise), instead of 0·inf = NaN.
TEST(SoftenedForces, TinyEpsilonIsFiniteAtTheCentre) {
  for (const float eps : {1e-3f, 1e-26f, 1e-30f, std::numeric_limits<float>::denorm_min()}) {
    Context ctx = makeContext(1.0 / 30.0);
    Group& g = ctx.createGroup("centre", 16);
    OrbitPoint point;
    point.center = Vec3(1, 2, 3);
    point.epsilon = eps;
    OrbitLine line;
    line.point = Vec3(1, 2, 3);
    line.epsilon = eps;
    Explosion blast;
    blast.center = Vec3(1, 2, 3);
    blast.epsilon = eps;
    blast.speed = 0.0f;
    g.setActions({point, line, blast, Move{}});
    Particle p;
    p.position = Vec3(1, 2, 3);
    g.add(p);
    Particle on;  // on OrbitLine's axis, off the point: the line pulls with d = 0
    on.position = Vec3(1, 2.5f, 3);
    g.add(on);
    for (int s = 0; s < 3; ++s) ctx.step();
    ASSERT_EQ(g.stats().killedNonFinite, 0u) << "epsilon " << eps;
    ASSERT_EQ(g.size(), 2u);
    const Particle q = g.particle(0);
    EXPECT_EQ(q.position, Vec3(1, 2, 3)) << "epsilon " << eps;
    EXPECT_EQ(q.velocity, Vec3(0.0f)) << "epsilon " << eps;
  }
}

TEST(OrbitPoint, KeepsACircularOrbitsRadius) {
  Context ctx = makeContext(0.001);
  Group& g = ctx.createGroup("g", 1);
  const float M = 10.0f, eps = 1e-4f, r = 2.0f;
  g.setActions({OrbitPoint{Vec3(0), M, eps}, Move{}});
  // Circular speed for the softened pull: v² = M r² / (r² + eps)^(3/2).
  const float v = std::sqrt(M * r * r / std::pow(r * r + eps, 1.5f));
  g.add(at(Vec3(r, 0, 0), Vec3(0, v, 0)));
  const double period = 2 * M_PI * r / v;
  float lo = r, hi = r;
  for (int s = 0; s < int(5 * period / 0.001); ++s) {
    ctx.step();
    const float rad = glm::length(g.particle(0).position);
    lo = std::min(lo, rad);
    hi = std::max(hi, rad);
  }
  EXPECT_GT(lo, r * 0.995f);
  EXPECT_LT(hi, r * 1.005f);
}

TEST(OrbitPoint, IsFiniteAtTheCenter) {
  Context ctx = makeContext();
  Group& g = ctx.createGroup("g", 1);
  g.setActions({OrbitPoint{Vec3(1, 2, 3), 100.0f, 1e-3f}, Move{}});
  g.add(at(Vec3(1, 2, 3)));
  ctx.run(10);
  const Particle p = g.particle(0);
  EXPECT_TRUE(std::isfinite(p.position.x) && std::isfinite(p.velocity.x));
  EXPECT_EQ(p.velocity, Vec3(0));  // d = 0: no pull at all
}

TEST(OrbitLine, PullsTowardsTheLineOnly) {
  Context ctx = makeContext();
  Group& g = ctx.createGroup("g", 1);
  g.setActions({OrbitLine{Vec3(0), Vec3(0, 1, 0), 1.0f, 1e-3f}});
  g.add(at(Vec3(2, 5, 0)));
  ctx.step();
  const Vec3 v = g.particle(0).velocity;
  EXPECT_LT(v.x, 0.0f);
  EXPECT_NEAR(v.y, 0.0f, 1e-7);
  EXPECT_NEAR(v.z, 0.0f, 1e-7);
}

TEST(Gravitate, ConservesMomentum) {
  Context ctx = makeContext();
  Group& g = ctx.createGroup("g", 50);
  g.setActions({Gravitate{1.0f, 0.01f}, Move{}});
  Random rng(3, 0, 0, 0);
  for (int i = 0; i < 50; ++i) g.add(at(Domain::box(Vec3(-1), Vec3(1)).sample(rng)));
  ctx.run(20);
  Vec3 momentum(0);
  for (std::size_t i = 0; i < g.size(); ++i) momentum += g.particle(i).velocity;
  EXPECT_LT(glm::length(momentum), 1e-3f);
  EXPECT_GT(glm::length(g.particle(0).velocity), 0.0f);
}

TEST(Vortex, SwirlsAroundTheAxisAndIsFiniteOnIt) {
  Context ctx = makeContext(0.01);
  Group& g = ctx.createGroup("g", 2);
  Vortex vx;
  vx.aroundSpeed = 2.0f;
  vx.responsiveness = 1000.0f;  // the velocity reaches the field's at once
  g.setActions({vx, Move{}});
  g.add(at(Vec3(1, 0, 0)));
  g.add(at(Vec3(0, 3, 0)));  // on the axis
  ctx.step();
  const Vec3 v = g.particle(0).velocity;
  EXPECT_NEAR(v.z, -1.0f, 1e-3f);  // axis × x̂ = -ẑ; outside the core: 2·(0.5/1)^1
  EXPECT_TRUE(std::isfinite(g.particle(1).velocity.x));
  EXPECT_EQ(g.particle(1).velocity, Vec3(0));
}

TEST(Turbulence, CurlNoiseIsDivergenceFree) {
  const float h = 1e-3f;
  Random rng(9, 0, 0, 0);
  double worstDiv = 0, typicalGrad = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 p = Domain::box(Vec3(-10), Vec3(10)).sample(rng);
    const Vec3 dx =
        (detail::curlNoise(p + Vec3(h, 0, 0), 2) - detail::curlNoise(p - Vec3(h, 0, 0), 2)) /
        (2 * h);
    const Vec3 dy =
        (detail::curlNoise(p + Vec3(0, h, 0), 2) - detail::curlNoise(p - Vec3(0, h, 0), 2)) /
        (2 * h);
    const Vec3 dz =
        (detail::curlNoise(p + Vec3(0, 0, h), 2) - detail::curlNoise(p - Vec3(0, 0, h), 2)) /
        (2 * h);
    worstDiv = std::max(worstDiv, double(std::abs(dx.x + dy.y + dz.z)));
    typicalGrad += std::abs(dx.y) + std::abs(dy.z) + std::abs(dz.x);
  }
  typicalGrad /= 600;
  EXPECT_GT(typicalGrad, 0.1);              // the field does vary...
  EXPECT_LT(worstDiv, 0.01 * typicalGrad);  // ...with no divergence beyond the differences' error
}

// A particle flung far beyond int's range still reads the noise: its lattice cell is held in
// range, not converted as it is (undefined: UBSan reported it at 3.6e32, found by
// RandomEffects), and the field stays finite there; nearer, the cells are unchanged.
TEST(Turbulence, IsDefinedAndFiniteFarAway) {
  Context ctx = makeContext(0.05);
  Group& g = ctx.createGroup("g", 8);
  g.setActions({Turbulence{3.0f, 10.0f, 3, Vec3(0.0f)}});
  for (const float x : {3.6e32f, -3.6e32f, 3e9f, -2.2e9f, 1.5e5f})
    ASSERT_TRUE(g.add(at(Vec3(x, -x, 0.5f * x))));
  ctx.step();
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Vec3 v = g.particle(i).velocity;
    EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) << i;
  }
  EXPECT_NE(detail::curlNoise(Vec3(1.5e5f, -1.5e5f, 7.5e4f), 3), Vec3(0.0f));
}

TEST(MagneticField, DoesNoWorkAndGyratesAtTheLarmorRadius) {
  Context ctx = makeContext(0.001);
  Group& g = ctx.createGroup("g", 1);
  const float q = 2.0f, m = 0.5f, B = 4.0f, speed = 3.0f;
  g.setActions({MagneticField{Vec3(0, 0, B)}, Move{}});
  Particle p = at(Vec3(0), Vec3(speed, 0, 0));
  p.charge = q;
  p.mass = m;
  g.add(p);
  const float radius = m * speed / (q * B);  // 0.1875
  float xmin = 1e9f, xmax = -1e9f, ymin = 1e9f, ymax = -1e9f;
  for (int s = 0; s < 10000; ++s) {
    ctx.step();
    const Particle c = g.particle(0);
    ASSERT_NEAR(glm::length(c.velocity), speed, 1e-5f * speed);
    xmin = std::min(xmin, c.position.x);
    xmax = std::max(xmax, c.position.x);
    ymin = std::min(ymin, c.position.y);
    ymax = std::max(ymax, c.position.y);
  }
  EXPECT_NEAR(xmax - xmin, 2 * radius, 0.01f);
  EXPECT_NEAR(ymax - ymin, 2 * radius, 0.01f);
}

// A field past ~1.8e19, whose square overflows a float: its strength was infinite, and an
// uncharged particle turned by 0 * inf (a NaN: killed).
TEST(MagneticField, AFieldWhoseSquareOverflowsTurnsAsItsDirectionSays) {
  Context ctx = makeContext(0.001);
  Group& g = ctx.createGroup("g", 2);
  const Vec3 field(3e19f, 4e19f, 0.0f), axis(0.6f, 0.8f, 0.0f);  // |B| = 5e19
  g.setActions({MagneticField{field}, Move{}});
  Particle charged = at(Vec3(0), Vec3(1, 2, 3)), uncharged = charged;
  charged.charge = 2e-20f;  // q/m |B| = 1 radian a second
  uncharged.charge = 0.0f;
  g.add(charged);
  g.add(uncharged);
  ctx.run(500);
  ASSERT_EQ(g.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Particle p = g.particle(i);
    if (p.charge == 0.0f) {
      EXPECT_EQ(p.velocity, Vec3(1, 2, 3));
      continue;
    }
    // Half a radian about the field: the speed and the part along the field stay.
    EXPECT_NEAR(glm::length(p.velocity), std::sqrt(14.0f), 1e-5f);
    EXPECT_NEAR(glm::dot(p.velocity, axis), glm::dot(Vec3(1, 2, 3), axis), 1e-5f);
    const Vec3 across = Vec3(1, 2, 3) - glm::dot(Vec3(1, 2, 3), axis) * axis;
    const Vec3 now = p.velocity - glm::dot(p.velocity, axis) * axis;
    EXPECT_NEAR(glm::dot(glm::normalize(across), glm::normalize(now)), std::cos(0.5f), 1e-4f);
  }
}

TEST(ElectricField, AcceleratesByChargeOverMassAndIgnoresZeroMass) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({ElectricField{Vec3(1, 0, 0)}});
  Particle a = at(Vec3(0));
  a.charge = 3.0f;
  a.mass = 2.0f;
  Particle b = a;
  b.mass = 0.0f;
  g.add(a);
  g.add(b);
  ctx.run(10);
  EXPECT_NEAR(g.particle(0).velocity.x, 1.5f, 1e-5f);
  EXPECT_EQ(g.particle(1).velocity, Vec3(0));
}

TEST(Targets, ApproachWithoutOvershootAtAnyStep) {
  for (double dt : {0.01, 1.0, 10.0}) {
    Context ctx = makeContext(dt);
    Group& g = ctx.createGroup("g", 1);
    g.setActions({TargetVelocity{Vec3(5, 0, 0), 2.0f}, TargetColor{Vec3(1, 0, 0), 0.5f, 2.0f},
                  TargetSize{2.0f, 2.0f}});
    g.add(at(Vec3(0)));
    ctx.run(5);
    const Particle p = g.particle(0);
    EXPECT_LE(p.velocity.x, 5.0f);
    EXPECT_GT(p.velocity.x, 0.0f);
    EXPECT_LE(p.size, 2.0f + 1e-6f);
    EXPECT_GE(p.color.g, 0.0f);
  }
  // Exact exponential: one step of 1 s equals ten of 0.1 s.
  float v[2];
  int k = 0;
  for (double dt : {1.0, 0.1}) {
    Context ctx = makeContext(dt);
    Group& g = ctx.createGroup("g", 1);
    g.setActions({TargetVelocity{Vec3(1, 0, 0), 0.7f}});
    g.add(at(Vec3(0)));
    ctx.run(std::size_t(std::lround(1.0 / dt)));
    v[k++] = g.particle(0).velocity.x;
  }
  EXPECT_NEAR(v[0], v[1], 1e-5f);
  EXPECT_NEAR(v[0], 1.0f - std::exp(-0.7f), 1e-6f);
}

TEST(SpeedClamp, KeepsSpeedInRange) {
  Context ctx = makeContext();
  Group& g = ctx.createGroup("g", 2);
  g.setActions({SpeedClamp{1.0f, 2.0f}});
  g.add(at(Vec3(0), Vec3(10, 0, 0)));
  g.add(at(Vec3(0), Vec3(0, 0.1f, 0)));
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.x, 2.0f, 1e-6f);
  EXPECT_NEAR(g.particle(1).velocity.y, 1.0f, 1e-6f);
}

TEST(OverLife, ColorAndSizeFollowTheirCurvesInReplaceMode) {
  Context ctx = makeContext(0.25);
  Group& g = ctx.createGroup("g", 1);
  g.setActions(
      {Move{},
       ColorOverLife{{{0.0f, Vec4(1, 0, 0, 1)}, {1.0f, Vec4(0, 0, 1, 0)}}, OverLifeMode::Replace},
       SizeOverLife{{{0.0f, 1.0f}, {0.5f, 3.0f}, {1.0f, 0.0f}}, OverLifeMode::Replace}});
  // Replace needs no birth values.
  EXPECT_FALSE(g.attributes().has(Attribute::BirthColor));
  EXPECT_FALSE(g.attributes().has(Attribute::BirthSize));
  Particle p = at(Vec3(0));
  p.lifetime = 1.0f;
  p.color = Vec4(0.2f, 0.4f, 0.6f, 1.0f);
  g.add(p);
  ctx.run(2);  // age 0.5
  const Particle q = g.particle(0);
  EXPECT_NEAR(q.color.r, 0.5f, 1e-6f);
  EXPECT_NEAR(q.color.b, 0.5f, 1e-6f);
  EXPECT_NEAR(q.size, 3.0f, 1e-6f);
}

// By default the curves scale what the particle was born with: two particle types of an
// emitter keep their own colours and sizes under one curve.
TEST(OverLife, CurvesMultiplyTheBirthColorAndSizeByDefault) {
  Context ctx = makeContext(0.25);
  Group& g = ctx.createGroup("g", 100);
  Emitter e;
  e.bursts = {{0.0, 100, 0.0, 1}};
  e.types.resize(2);
  e.types[0].color = Domain::point(Vec3(1.0f, 0.5f, 0.1f));  // orange
  e.types[0].size = 0.04f;
  e.types[1].color = Domain::point(Vec3(0.2f, 0.6f, 1.0f));  // blue
  e.types[1].size = 0.08f;
  for (auto& t : e.types) t.lifetime = 1.0f;
  g.addEmitter(e);
  g.setActions({Move{}, ColorOverLife{{{0.0f, Vec4(1.0f)}, {1.0f, Vec4(0.5f, 0.5f, 0.5f, 0.0f)}}},
                SizeOverLife{{{0.0f, 1.0f}, {1.0f, 3.0f}}}, KillOld{}});
  EXPECT_TRUE(g.attributes().has(Attribute::BirthColor));
  EXPECT_TRUE(g.attributes().has(Attribute::BirthSize));
  ctx.run(2);
  ASSERT_EQ(g.size(), 100u);
  int blue = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle q = g.particle(i);
    const bool isBlue = q.color.b > q.color.r;
    blue += isBlue;
    const Vec3 birth = isBlue ? Vec3(0.2f, 0.6f, 1.0f) : Vec3(1.0f, 0.5f, 0.1f);
    const float t = q.age / q.lifetime;  // the curves ran after Move, at this age
    ASSERT_GT(t, 0.2f);
    ASSERT_LT(t, 0.8f);
    const float f = 1.0f - 0.5f * t;
    EXPECT_NEAR(q.color.r, birth.r * f, 1e-5f);
    EXPECT_NEAR(q.color.g, birth.g * f, 1e-5f);
    EXPECT_NEAR(q.color.b, birth.b * f, 1e-5f);
    EXPECT_NEAR(q.color.a, 1.0f - t, 1e-5f);
    EXPECT_NEAR(q.size, (isBlue ? 0.08f : 0.04f) * (1.0f + 2.0f * t), 1e-5f);
  }
  EXPECT_GT(blue, 20);
  EXPECT_LT(blue, 80);

  // A particle added by hand: its colour and size as added are its birth values.
  Particle p = at(Vec3(0));
  p.lifetime = 1.0f;
  p.color = Vec4(0.0f, 1.0f, 0.0f, 1.0f);
  p.size = 2.0f;
  Context ctx2 = makeContext(0.25);
  Group& h = ctx2.createGroup("h", 1);
  h.setActions({Move{}, ColorOverLife{{{0.0f, Vec4(1.0f)}, {1.0f, Vec4(0.0f)}}},
                SizeOverLife{{{0.0f, 1.0f}, {1.0f, 0.0f}}}});
  h.add(p);
  ctx2.run(2);  // age 0.5
  EXPECT_NEAR(h.particle(0).color.g, 0.5f, 1e-6f);
  EXPECT_NEAR(h.particle(0).color.r, 0.0f, 1e-6f);
  EXPECT_NEAR(h.particle(0).size, 1.0f, 1e-6f);
}

// The CPU evaluates a curve of a few keys a segment at a time over many particles; the device
// walks the keys per particle (kernels/forces.h fl_curve_lookup). Both give the same bits: at
// the keys, between them, before the first and past the last, on two keys at one time, for a
// particle without a lifetime, with one key, and for curves long enough to be searched.
TEST(OverLife, CurvesGiveTheKernelsValuesBitForBit) {
  using ColorKeys = std::vector<ColorOverLife::Key>;
  using SizeKeys = std::vector<SizeOverLife::Key>;
  std::vector<std::pair<ColorKeys, SizeKeys>> curves = {
      {{{0.1f, Vec4(1, 0, 0, 1)},
        {0.3f, Vec4(0, 1, 0, 0.5f)},
        {0.3f, Vec4(0, 0, 1, 0.25f)},  // a jump: two keys at one time
        {0.65f, Vec4(0.2f, 0.7f, 0.1f, 0.9f)},
        {0.9f, Vec4(0.5f, 0.5f, 0.5f, 0.0f)}},
       {{0.1f, 1.0f}, {0.3f, 3.0f}, {0.3f, 0.5f}, {0.9f, 2.0f}}},
      {{{0.4f, Vec4(0.3f, 0.6f, 0.9f, 1.0f)}}, {{0.4f, 7.0f}}},  // one key
  };
  // Longer curves: 9 and 12 keys (still a segment at a time), and past kMostSegmentedKeys
  // (16; searched per particle) 33 in threes at one time (jumps) and 200 spaced unevenly.
  for (const int keys : {9, 12, 33, 200}) {
    ColorKeys longColor;
    SizeKeys longSize;
    for (int k = 0; k < keys; ++k) {
      float t = float(k) / float(keys - 1);
      if (keys == 33) t = float(k - k % 3) / 32.0f;  // three keys at each time
      if (keys == 200) t = t * t;                    // spaced unevenly
      const float w = float(k % 3) / 2.0f;
      longColor.push_back({t, Vec4(w, 1.0f - w, t, 1.0f - t)});
      longSize.push_back({t, 1.0f + w});
    }
    curves.push_back({longColor, longSize});
  }
  for (const OverLifeMode mode : {OverLifeMode::Replace, OverLifeMode::Multiply}) {
    for (const auto& [colorKeys, sizeKeys] : curves) {
      Context ctx = makeContext(0.25);
      Group& g = ctx.createGroup("g", 2000);
      g.setActions({ColorOverLife{colorKeys, mode}, SizeOverLife{sizeKeys, mode}});
      // Ages that land on every key, between them, outside them; some without a lifetime.
      std::vector<Particle> added;
      for (int i = 0; i < 1500; ++i) {
        Particle p = at(Vec3(0));
        p.lifetime = i % 97 == 0 ? 0.0f : 2.0f;
        p.age =
            i < 1200 ? 2.0f * float(i) / 1100.0f - 0.1f : 2.0f * colorKeys[i % colorKeys.size()].t;
        p.color = Vec4(0.5f + 0.001f * float(i % 200), 0.25f, 1.0f, 0.75f);
        p.size = 1.0f + 0.01f * float(i % 50);
        g.add(p);
        added.push_back(p);
      }
      ctx.step();  // (no Move: the ages stay as added)
      ASSERT_EQ(g.size(), added.size());
      for (std::size_t i = 0; i < added.size(); ++i) {
        const Particle& p = added[i];
        const Particle q = g.particle(i);
        ASSERT_EQ(q.age, p.age);
        const float t = detail::kernel::fl_life_fraction(p.age, p.lifetime);
        float col[4], size[1];
        detail::kernel::fl_curve_lookup(reinterpret_cast<const float*>(colorKeys.data()),
                                        unsigned(colorKeys.size()), 5u, t, col);
        detail::kernel::fl_curve_lookup(reinterpret_cast<const float*>(sizeKeys.data()),
                                        unsigned(sizeKeys.size()), 2u, t, size);
        const bool multiply = mode == OverLifeMode::Multiply;
        for (int d = 0; d < 4; ++d) {
          const float want = multiply ? p.color[d] * col[d] : col[d];
          ASSERT_EQ(std::bit_cast<std::uint32_t>(q.color[d]), std::bit_cast<std::uint32_t>(want))
              << "particle " << i << " channel " << d << " t " << t << " keys " << colorKeys.size();
        }
        const float want = multiply ? p.size * size[0] : size[0];
        ASSERT_EQ(std::bit_cast<std::uint32_t>(q.size), std::bit_cast<std::uint32_t>(want))
            << "particle " << i << " t " << t << " keys " << sizeKeys.size();
      }
    }
  }
}

TEST(RandomActions, DrawFromTheirDomainsReproducibly) {
  auto run = [] {
    Context ctx = makeContext();
    Group& g = ctx.createGroup("g", 100);
    g.setActions({RandomVelocity{Domain::box(Vec3(1, 2, 3), Vec3(2, 3, 4))}});
    for (int i = 0; i < 100; ++i) g.add(at(Vec3(0)));
    ctx.step();
    std::vector<Vec3> v;
    for (std::size_t i = 0; i < g.size(); ++i) v.push_back(g.particle(i).velocity);
    return v;
  };
  const auto a = run(), b = run();
  EXPECT_EQ(a, b);
  for (const Vec3& v : a) EXPECT_TRUE(Domain::box(Vec3(1, 2, 3), Vec3(2, 3, 4)).contains(v));
  EXPECT_NE(a[0], a[1]);
}

TEST(Jet, AcceleratesOnlyWithinItsRadius) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({Jet{Vec3(0), 1.0f, Domain::point(Vec3(0, 10, 0))}});
  g.add(at(Vec3(0.5f, 0, 0)));
  g.add(at(Vec3(5, 0, 0)));
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.y, 1.0f, 1e-6f);
  EXPECT_EQ(g.particle(1).velocity.y, 0.0f);
}

TEST(Explosion, PushesOutwardNearTheFront) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({Explosion{Vec3(0), 10.0f, 100.0f, 0.5f, 1e-3f, 0.0f}});
  g.add(at(Vec3(0.5f, 0, 0)));  // the front is at 0.5 at mid-step
  g.add(at(Vec3(0, -20, 0)));   // far from it
  ctx.step();
  EXPECT_GT(g.particle(0).velocity.x, 1.0f);
  EXPECT_NEAR(g.particle(1).velocity.y, 0.0f, 1e-6f);
}

TEST(SampledField, AcceleratesAlongTheGrid) {
  auto field = std::make_shared<VectorField>();
  field->dims = glm::ivec3(2, 2, 2);
  field->data.assign(8, Vec3(0, 0, 1));
  field->data[1] = Vec3(0, 0, 3);  // x = 1, y = 0, z = 0
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 1);
  g.setActions({SampledField{field}});
  g.add(at(Vec3(0.5f, 0, 0)));  // halfway: 2
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.z, 0.2f, 1e-6f);
  auto bad = std::make_shared<VectorField>(*field);
  bad->data[3] = Vec3(NAN);
  EXPECT_THROW(ActionList{SampledField{bad}}, InvalidArgument);
}

TEST(Avoid, SteersAwayFromAnObstacleAhead) {
  Context ctx = makeContext(0.01);
  Group& g = ctx.createGroup("g", 1);
  g.setActions({Avoid{Domain::sphere(Vec3(0), 1.0f), 50.0f, 0.1f, 1.0f}, Move{}});
  g.add(at(Vec3(-3, 0.2f, 0), Vec3(2, 0, 0)));
  bool entered = false;
  for (int s = 0; s < 300; ++s) {
    ctx.step();
    entered |= glm::length(g.particle(0).position) < 1.0f;
  }
  EXPECT_FALSE(entered);
}

TEST(Follow, TrailsTheNextParticle) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({Follow{1.0f, 0.01f}});
  g.add(at(Vec3(0)));
  g.add(at(Vec3(1, 0, 0)));
  ctx.step();
  EXPECT_GT(g.particle(0).velocity.x, 0.0f);
  EXPECT_EQ(g.particle(1).velocity, Vec3(0));  // the leader
}

TEST(MatchVelocity, NeighboursConverge) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({MatchVelocity{5.0f, 0.01f, 10.0f}});
  g.add(at(Vec3(0), Vec3(1, 0, 0)));
  g.add(at(Vec3(1, 0, 0), Vec3(-1, 0, 0)));
  ctx.run(20);
  EXPECT_NEAR(g.particle(0).velocity.x, g.particle(1).velocity.x, 1e-3f);
}

TEST(RestoreAndCopyVertexB, ReturnToTheRestPoseOnTime) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 1);
  g.setActions({CopyVertexB{}});
  g.add(at(Vec3(1, 2, 3)));
  ctx.step();
  g.setActions({Gravity{}, Move{}});
  ctx.run(10);  // falls away
  EXPECT_GT(glm::length(g.particle(0).position - Vec3(1, 2, 3)), 1.0f);
  g.setActions({Restore{float(ctx.time()), 1.0f}, Move{}});
  ctx.run(10);
  EXPECT_LT(glm::length(g.particle(0).position - Vec3(1, 2, 3)), 1e-4f);
  ctx.run(5);
  EXPECT_LT(glm::length(g.particle(0).position - Vec3(1, 2, 3)), 1e-4f);
}

TEST(Callback, RunsAUserFunctionPerParticle) {
  Context ctx = makeContext(0.5);
  Group& g = ctx.createGroup("g", 10);
  g.setActions({Callback{[](Particle& p, const CallbackContext& c) { p.userData += c.dt; },
                         {Attribute::UserData}}});
  for (int i = 0; i < 10; ++i) g.add(at(Vec3(0)));
  ctx.run(4);
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_FLOAT_EQ(g.particle(i).userData, 2.0f);
}

TEST(Constrain2D, KeepsTheGroupInItsPlane) {
  Context ctx = makeContext(0.05);
  Group& g = ctx.createGroup("g", 1);
  g.setActions({Gravity{Vec3(0, -9.81f, 3)}, Constrain2D{}, Move{}});
  g.add(at(Vec3(0, 5, 0), Vec3(1, 0, 2)));
  ctx.run(20);
  EXPECT_EQ(g.particle(0).position.z, 0.0f);
  EXPECT_EQ(g.particle(0).velocity.z, 0.0f);
}

// A falloff radius scales a field down to nothing at its edge, for every field kind.
TEST(Falloff, FadesFieldsToZeroAtTheRadius) {
  const Falloff f{Vec3(0), 2.0f, 1.0f};
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 3);
  MagneticField m{Vec3(0, 0, 5)};
  m.falloff = f;
  g.setActions({Gravity{Vec3(0, -10, 0), f}, m});
  for (float x : {0.0f, 1.0f, 3.0f}) {
    Particle p = at(Vec3(x, 0, 0), Vec3(1, 0, 0));
    p.charge = 1.0f;
    g.add(p);
  }
  ctx.step();
  // Gravity scaled by w, then v turned about z by -(q/m)|B|dt·w = -0.5·w radians.
  auto expect = [](float w) {
    const Vec3 v(1.0f, -1.0f * w, 0.0f);
    const float a = -0.5f * w;
    return Vec3(v.x * std::cos(a) - v.y * std::sin(a), v.x * std::sin(a) + v.y * std::cos(a), 0.0f);
  };
  EXPECT_LT(glm::length(g.particle(0).velocity - expect(1.0f)), 1e-5f);  // full strength
  EXPECT_LT(glm::length(g.particle(1).velocity - expect(0.5f)), 1e-5f);  // halfway out
  EXPECT_EQ(g.particle(2).velocity, Vec3(1, 0, 0));                      // outside: untouched
}

// RandomAccel draws for a block of particles at once: each particle still gets the numbers
// of its own stream (seed, id, step, group << 16 | action), in Random's order, as
// Domain::sample draws them (the OpenCL backend draws the same). Blob takes two Philox
// blocks per sample; 1000 particles are several batches and a partial one.
TEST(RandomAccel, EachParticleDrawsItsOwnStream) {
  for (const Domain& d : {Domain::sphere(Vec3(0, 1, 0), 6.0f), Domain::blob(Vec3(1, 0, 0), 8.0f),
                          Domain::box(Vec3(-1), Vec3(2))}) {
    ContextOptions o;
    o.dt = 0.5;
    o.threads = 2;
    o.seed = 0x1234'5678'9ABCull;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 1000);
    g.setActions({Gravity{Vec3(0.0f)}, RandomAccel{d}});  // RandomAccel is action 1
    for (int i = 0; i < 1000; ++i) g.add(at(Vec3(float(i), 0, 0)));
    ctx.run(2);
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle p = g.particle(i);
      Vec3 v(0.0f);
      for (std::uint32_t step = 0; step < 2; ++step) {
        Random rng(o.seed, p.id, step, 1);
        v += d.sample(rng) * 0.5f;
      }
      ASSERT_EQ(p.velocity, v) << d.name() << " particle " << i;
    }
  }
}

// RandomVelocity, RandomRotVelocity and RandomDisplace draw in batches too: the same numbers
// as one Random per particle and action.
TEST(RandomActions, BatchesDrawEachParticlesOwnStream) {
  const Domain d = Domain::cylinder(Vec3(0, -1, 0), Vec3(0, 2, 1), 3.0f, 1.0f);
  ContextOptions o;
  o.dt = 0.25;
  o.threads = 2;
  o.seed = 0xABCD'1234ull;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  g.setActions({RandomVelocity{d}, RandomRotVelocity{d}, RandomDisplace{d}});
  for (int i = 0; i < 1000; ++i) g.add(at(Vec3(float(i), 0, 0)));
  ctx.step();
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    auto draw = [&](std::uint32_t action) {
      Random rng(o.seed, p.id, 0, action);
      return d.sample(rng);
    };
    ASSERT_EQ(p.velocity, draw(0)) << "particle " << i;
    ASSERT_EQ(p.rotVelocity, draw(1)) << "particle " << i;
    ASSERT_EQ(p.position, Vec3(float(p.id), 0, 0) + draw(2) * 0.25f) << "particle " << i;
  }
}
