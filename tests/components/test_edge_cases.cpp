// Defects found by testing as a user would (issue #12): each test failed before its fix.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
Context makeContext(double dt = 1.0 / 30.0) {
  ContextOptions o;
  o.dt = dt;
  o.threads = 2;
  return Context(o);
}
bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
}  // namespace

// Item 1: a sphere keeping particles in, hit by a radial burst so fast that every path
// crosses the centre many times a step: nobody is killed as non-finite, everyone stays in.
TEST(EdgeCases, FastRadialBurstInsideASphereStaysFiniteAndInside) {
  Context ctx = makeContext(1.0 / 30.0);
  Group& g = ctx.createGroup("burst", 10000);
  const Vec3 C(0.0f);
  g.setActions({Bounce{Domain::sphere(C, 1.0f), 1.0f, 0.0f, 0.0f, true}, Move{}});
  Random rng(3, 0, 0, 0);
  const Domain directions = Domain::sphere(Vec3(0.0f), 1e5f, 1e5f);
  for (int i = 0; i < 10000; ++i) {
    Particle p;
    p.position = C;
    p.velocity = directions.sample(rng);
    g.add(p);
  }
  for (int s = 0; s < 10; ++s) {
    ctx.step();
    ASSERT_EQ(g.stats().killedNonFinite, 0u) << "step " << s;
    ASSERT_EQ(g.size(), 10000u);
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle q = g.particle(i);
      ASSERT_TRUE(finite(q.position) && finite(q.velocity)) << i;
      ASSERT_LE(glm::length(q.position - C), 1.0f) << i;
    }
  }
}

// Item 2: a two-sided planar deflector treats both sides alike, whichever way its normal
// points. A particle born or placed exactly on the plane belongs to neither side and leaves
// it freely (an emitter on a floor emits through it; before, it bounced or not by the
// normal's orientation); one that arrives exactly at the plane by moving is bounced (before,
// it came to rest on it and then fell through or not, again by the orientation).
TEST(EdgeCases, PlanarDeflectorsTreatBothSidesAlike) {
  struct Piece {
    const char* name;
    Domain shape;
  };
  const Piece pieces[] = {
      {"rectangle normal -y", Domain::rectangle(Vec3(-1, 0, -1), Vec3(2, 0, 0), Vec3(0, 0, 2))},
      {"rectangle normal +y", Domain::rectangle(Vec3(-1, 0, -1), Vec3(0, 0, 2), Vec3(2, 0, 0))},
      {"plane normal -y", Domain::plane(Vec3(0.0f), Vec3(0, -1, 0))},
      {"plane normal +y", Domain::plane(Vec3(0.0f), Vec3(0, 1, 0))},
      {"disc normal -y", Domain::disc(Vec3(0.0f), Vec3(0, -1, 0), 1.0f)},
      {"disc normal +y", Domain::disc(Vec3(0.0f), Vec3(0, 1, 0), 1.0f)},
      {"triangle normal -y", Domain::triangle(Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(0, 0, 1))},
      {"triangle normal +y", Domain::triangle(Vec3(-1, 0, -1), Vec3(0, 0, 1), Vec3(1, 0, -1))},
  };
  for (const Piece& piece : pieces) {
    for (const float vy : {-2.0f, 2.0f}) {
      Context ctx = makeContext(0.5);
      Group& g = ctx.createGroup("on-plane", 16);
      g.setActions({Bounce{piece.shape, 1.0f, 0.0f, 0.0f}, Move{}});
      Particle on;  // on the plane: leaves it freely
      on.position = Vec3(0.1f, 0.0f, 0.1f);
      on.velocity = Vec3(0.0f, vy, 0.0f);
      g.add(on);
      Particle arriving;  // reaches the plane exactly at the end of the step: bounced
      arriving.position = Vec3(0.1f, -vy * 0.5f, 0.1f);
      arriving.velocity = Vec3(0.0f, vy, 0.0f);
      g.add(arriving);
      ctx.step();
      ASSERT_EQ(g.size(), 2u);
      const Particle a = g.particle(0), b = g.particle(1);
      EXPECT_EQ(a.position.y, vy * 0.5f) << piece.name << " vy " << vy;
      EXPECT_EQ(a.velocity.y, vy) << piece.name << " vy " << vy;
      EXPECT_LT(b.position.y * vy, 0.0f)
          << piece.name << " vy " << vy << ": ended on the plane or behind it";
      EXPECT_FLOAT_EQ(b.velocity.y, -vy) << piece.name << " vy " << vy;
    }
  }
}

// Item 3: softened forces with a tiny epsilon leave a particle at the centre untouched
// (the header's promise), instead of 0·inf = NaN.
TEST(EdgeCases, SoftenedForcesWithTinyEpsilonAreFiniteAtTheCentre) {
  for (const float eps : {1e-3f, 1e-26f, 1e-30f, std::numeric_limits<float>::denorm_min()}) {
    Context ctx = makeContext();
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
