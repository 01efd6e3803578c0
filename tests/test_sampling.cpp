// The batch samplers' math, and the documented draw order of a newborn (the OpenCL backend
// draws the same numbers in the same order).
#include <gtest/gtest.h>

#include <cmath>

#include "flurry/flurry.hpp"
#include "sampling.hpp"
#include "shape_math.hpp"

using namespace flurry;

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
