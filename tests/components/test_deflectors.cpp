// Deflectors (closed shapes, 2-D segments), absorbers by mode, and blockers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
Context makeContext(double dt = 1.0 / 30.0) {
  ContextOptions o;
  o.dt = dt;
  o.threads = 2;
  return Context(o);
}
void fill(Group& g, int n, const Domain& where, const Domain& velocity, std::uint32_t seed = 1) {
  Random rng(seed, 0, 0, 0);
  for (int i = 0; i < n; ++i) {
    Particle p;
    p.position = where.sample(rng);
    p.velocity = velocity.sample(rng);
    g.add(p);
  }
}
}  // namespace

// Issue #12 item 1: a sphere keeping particles in, hit by a radial burst so fast that every path
// crosses the centre many times a step: nobody is killed as non-finite, everyone stays in.
TEST(Bounce, FastRadialBurstInsideASphereStaysFiniteAndInside) {
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
      ASSERT_TRUE(std::isfinite(glm::length(q.position)) && std::isfinite(glm::length(q.velocity)))
          << i;
      ASSERT_LE(glm::length(q.position - C), 1.0f) << i;
    }
  }
}

// A sphere at restitution 1 without friction keeps |v|: mirroring v about the computed
// normal. The hit point is on the sphere only up to rounding, which grows with its distance
// from the origin (ulp(1000) = 6e-5 here, against R = 1), so the normal (h - C)/R was not
// unit and every bounce changed |v|² by 4·cos²·(|n|² - 1): up to ~5e-4 here, a drift of 1e-2
// in 30 steps. Mirrored about h - C by (v·d)/(d·d), the change is rounding only: first order,
// ≤ 34 ulps (2^-24) of |v|² per bounce (the dot product and d·d, 3 ulps each, the quotient,
// times 4·cos² ≤ 4; the three component roundings, ≤ 6), and ≤ 17 bounces a step (one, then
// up to 16 more inside).
TEST(Bounce, SphereAwayFromTheOriginKeepsTheSpeedAtRestitutionOne) {
  const Vec3 C(1000.0f, -1000.0f, 1000.0f);
  const double perBounce = 34.0 * std::ldexp(1.0, -24);
  const int steps = 30;
  for (bool inside : {true, false}) {
    SCOPED_TRACE(inside ? "inside" : "outside");
    Context ctx = makeContext(1.0 / 60.0);
    Group& g = ctx.createGroup("g", 2000);
    g.setActions({Bounce{Domain::sphere(C, 1.0f), 1.0f, 0.0f, 0.0f, inside}, Move{}});
    Random rng(5, 0, 0, 0);
    std::vector<double> speed2;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 dir = Domain::sphere(Vec3(0.0f), 1.0f, 1.0f).sample(rng);
      Particle p;
      // Inside: 1000 units/s, 16 bounces every step. Outside: aimed at the sphere from 1 to 6
      // units away at 60 units/s, each bounces once.
      p.position = inside ? C + Domain::sphere(Vec3(0.0f), 0.9f).sample(rng)
                          : C - dir * (2.0f + 5.0f * rng.uniform());
      p.velocity = inside ? dir * 1000.0f : dir * 60.0f;
      g.add(p);
      speed2.push_back(glm::dot(glm::dvec3(p.velocity), glm::dvec3(p.velocity)));
    }
    double drift = 0.0;
    for (int s = 0; s < steps; ++s) ctx.step();
    ASSERT_EQ(g.size(), 2000u);
    std::size_t bounced = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle q = g.particle(i);
      const glm::dvec3 v(q.velocity);
      drift = std::max(drift, std::abs(glm::dot(v, v) / speed2[i] - 1.0));
      bounced += inside || glm::dot(glm::dvec3(q.position - C), v) > 0.0;
    }
    EXPECT_GT(bounced, 1000u);  // the outside ones came back out
    EXPECT_LE(drift, (inside ? steps * 17 : 1) * perBounce) << "relative change of |v|²";
  }
}

// Issue #12 item 2: a two-sided planar deflector treats both sides alike, whichever way its normal
// points. A particle born or placed exactly on the plane belongs to neither side and leaves
// it freely (an emitter on a floor emits through it; before, it bounced or not by the
// normal's orientation); one that arrives exactly at the plane by moving is bounced (before,
// it came to rest on it and then fell through or not, again by the orientation).
TEST(Bounce, PlanarDeflectorsTreatBothSidesAlike) {
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

// Closed deflectors hold particles in (or out) at any speed, over many steps.
TEST(Bounce, ClosedShapesNeverLeakAtHighSpeed) {
  for (float speed : {1.0f, 1e3f, 1e4f}) {
    const Domain velocities = Domain::sphere(Vec3(0), speed, speed);
    {
      Context ctx = makeContext();
      Group& g = ctx.createGroup("in-sphere", 2000);
      g.setActions(
          {Gravity{}, Bounce{Domain::sphere(Vec3(1, 2, 3), 5.0f), 0.9f, 0.1f, 0.0f, true}, Move{}});
      fill(g, 2000, Domain::sphere(Vec3(1, 2, 3), 4.9f), velocities);
      for (int s = 0; s < 60; ++s) {
        ctx.step();
        for (std::size_t i = 0; i < g.size(); ++i)
          ASSERT_LE(glm::length(g.particle(i).position - Vec3(1, 2, 3)), 5.0f) << speed;
      }
    }
    {
      Context ctx = makeContext();
      Group& g = ctx.createGroup("in-box", 2000);
      const Domain box = Domain::box(Vec3(-1, -2, -3), Vec3(4, 5, 6));
      g.setActions({Gravity{}, Bounce{box, 0.8f, 0.2f, 0.0f, true}, Move{}});
      fill(g, 2000, box, velocities);
      for (int s = 0; s < 60; ++s) {
        ctx.step();
        for (std::size_t i = 0; i < g.size(); ++i)
          ASSERT_TRUE(box.contains(g.particle(i).position)) << speed << " step " << s;
      }
    }
    {
      Context ctx = makeContext();
      Group& g = ctx.createGroup("out-box", 2000);
      const Domain box = Domain::box(Vec3(-1), Vec3(1));
      g.setActions({Bounce{box, 1.0f, 0.0f, 0.0f, false}, Move{}});
      // Aimed at the box from all around.
      Random rng(7, 0, 0, 0);
      for (int i = 0; i < 2000; ++i) {
        Particle p;
        const Vec3 dir = Domain::sphere(Vec3(0), 1.0f, 1.0f).sample(rng);
        p.position = dir * (2.0f + 100.0f * rng.uniform());
        p.velocity = -dir * speed;
        g.add(p);
      }
      for (int s = 0; s < 30; ++s) {
        ctx.step();
        for (std::size_t i = 0; i < g.size(); ++i)
          ASSERT_FALSE(box.contains(g.particle(i).position)) << speed << " step " << s;
      }
    }
  }
}

TEST(Bounce, BoxFromOutsideReflectsOffTheEntryFace) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 1);
  g.setActions({Bounce{Domain::box(Vec3(-1), Vec3(1)), 0.5f, 0.0f, 0.0f}, Move{}});
  Particle p;
  p.position = Vec3(0, 1.1f, 0);
  p.velocity = Vec3(0, -2, 0);
  g.add(p);
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.y, 1.0f, 1e-6f);
  EXPECT_NEAR(g.particle(0).position.y, 1.05f, 1e-5f);
}

TEST(Bounce, SegmentDeflectsIn2D) {
  Context ctx = makeContext(0.05);
  Group& g = ctx.createGroup("g", 200);
  g.setActions({Gravity{}, Bounce{Domain::line(Vec3(-5, 0, 0), Vec3(5, 0, 0)), 0.5f}, Constrain2D{},
                Move{}});
  fill(g, 200, Domain::rectangle(Vec3(-4, 1, 0), Vec3(8, 0, 0), Vec3(0, 3, 0)),
       Domain::disc(Vec3(0), Vec3(0, 0, 1), 20.0f));
  for (int s = 0; s < 100; ++s) {
    ctx.step();
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Vec3 p = g.particle(i).position;
      ASSERT_EQ(p.z, 0.0f);
      // Above the segment unless it flew past its ends.
      if (std::abs(p.x) < 4.9f) ASSERT_GE(p.y, 0.0f) << "step " << s;
    }
  }
}

TEST(Sink, EnterLeaveAndHitModes) {
  const Domain box = Domain::box(Vec3(-1), Vec3(1));
  auto one = [&](Sink sink, Vec3 p, Vec3 v) {
    Context ctx = makeContext(0.1);
    Group& g = ctx.createGroup("g", 1);
    g.setActions({sink, Move{}});
    Particle q;
    q.position = p;
    q.velocity = v;
    g.add(q);
    ctx.step();
    return g.size();
  };
  Sink enter{box, 0.0f, Sink::Mode::Enter};
  EXPECT_EQ(one(enter, Vec3(-1.5f, 0, 0), Vec3(10, 0, 0)), 0u);  // enters
  EXPECT_EQ(one(enter, Vec3(0, 0, 0), Vec3(1, 0, 0)), 1u);       // already in
  Sink leave{box, 0.0f, Sink::Mode::Leave};
  EXPECT_EQ(one(leave, Vec3(0.9f, 0, 0), Vec3(10, 0, 0)), 0u);
  EXPECT_EQ(one(leave, Vec3(0, 0, 0), Vec3(1, 0, 0)), 1u);
  Sink hit{Domain::disc(Vec3(0), Vec3(0, 1, 0), 1.0f), 0.0f, Sink::Mode::Hit};
  EXPECT_EQ(one(hit, Vec3(0, 0.5f, 0), Vec3(0, -10, 0)), 0u);  // crosses the disc
  EXPECT_EQ(one(hit, Vec3(5, 0.5f, 0), Vec3(0, -10, 0)), 1u);  // crosses the plane, not the disc
  Sink outside{box, 0.0f, Sink::Mode::Outside};
  EXPECT_EQ(one(outside, Vec3(5, 0, 0), Vec3(0)), 0u);
  EXPECT_EQ(one(outside, Vec3(0, 0, 0), Vec3(0)), 1u);
}

// passThrough 0.3 lets 30 % of the particles through in every mode: the decision is made once
// per particle and absorber, not drawn again each step the particle is inside.
TEST(Sink, PassThroughIsAFractionOfParticlesInEveryMode) {
  const int n = 10000;
  const double p = 0.3, sigma = std::sqrt(p * (1 - p) / n);
  const Domain slab = Domain::box(Vec3(1, -100, -100), Vec3(2, 100, 100));
  auto passing = [&](std::vector<Action> sinks, Vec3 start, int steps) {
    Context ctx = makeContext(0.05);  // 1 unit/s: 20 steps inside the slab
    Group& g = ctx.createGroup("g", n);
    ActionList list;
    for (const Action& a : sinks) list.add(a);
    list.add(Move{});
    g.setActions(list);
    for (int i = 0; i < n; ++i) {
      Particle q;
      q.position = start + Vec3(0, float(i % 100) * 0.1f, float(i / 100) * 0.1f);
      q.velocity = Vec3(1, 0, 0);
      g.add(q);
    }
    ctx.run(steps);
    return double(g.size()) / n;
  };
  using M = Sink::Mode;
  const Vec3 before(0, 0, 0);
  EXPECT_NEAR(passing({Sink{slab, 0.3f, M::Inside}}, before, 60), p, 3 * sigma);
  EXPECT_NEAR(passing({Sink{slab, 0.3f, M::Enter}}, before, 60), p, 3 * sigma);
  EXPECT_NEAR(passing({Sink{slab, 0.3f, M::Leave}}, before, 60), p, 3 * sigma);
  EXPECT_NEAR(
      passing({Sink{Domain::plane(Vec3(1.5f, 0, 0), Vec3(1, 0, 0)), 0.3f, M::Hit}}, before, 60), p,
      3 * sigma);
  // Outside a region the particles leave and stay out of, for 40 steps.
  EXPECT_NEAR(
      passing({Sink{Domain::box(Vec3(-1, -100, -100), Vec3(1, 100, 100)), 0.3f, M::Outside}},
              before, 60),
      p, 3 * sigma);
  // Two absorbers decide independently: 0.3 · 0.3 pass both.
  const Domain slab2 = Domain::box(Vec3(3, -100, -100), Vec3(4, 100, 100));
  const double p2 = p * p, sigma2 = std::sqrt(p2 * (1 - p2) / n);
  EXPECT_NEAR(passing({Sink{slab, 0.3f, M::Inside}, Sink{slab2, 0.3f, M::Inside}}, before, 100), p2,
              3 * sigma2);
}

TEST(Sink, EachAbsorberCountsWhatItTook) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 100);
  g.setActions(
      {Sink{Domain::sphere(Vec3(-5, 0, 0), 1.0f)}, Sink{Domain::sphere(Vec3(5, 0, 0), 1.0f)}});
  for (int i = 0; i < 30; ++i) {
    Particle p;
    p.position = Vec3(i < 10 ? -5.0f : (i < 30 ? 5.0f : 0.0f), 0, 0);
    g.add(p);
  }
  ctx.step();
  EXPECT_EQ(g.stats().killedByAction[0], 10u);
  EXPECT_EQ(g.stats().killedByAction[1], 20u);
  EXPECT_EQ(g.stats().absorbed, 30u);
}

TEST(SinkVelocity, KillsTheSlow) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 2);
  g.setActions({SinkVelocity{Domain::sphere(Vec3(0), 0.5f)}});
  Particle a, b;
  a.velocity = Vec3(0.1f, 0, 0);
  b.velocity = Vec3(3, 0, 0);
  g.add(a);
  g.add(b);
  ctx.step();
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g.particle(0).velocity.x, 3.0f);
}

// A blocker hides exactly the particles inside it; they reappear when they leave.
TEST(Block, HidesExactlyThoseInside) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 5000);
  const Domain blocker = Domain::box(Vec3(-1, -10, -10), Vec3(1, 10, 10));
  const Domain second = Domain::sphere(Vec3(5, 0, 0), 1.0f);
  g.setActions({Move{}, Block{blocker}, Block{second}});
  fill(g, 5000, Domain::box(Vec3(-10, -1, -1), Vec3(10, 1, 1)), Domain::point(Vec3(1, 0, 0)));
  for (int s = 0; s < 5; ++s) {
    ctx.step();
    const auto vis = g.visible();
    std::size_t hidden = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Vec3 p = g.particle(i).position;
      const bool in = blocker.contains(p) || second.contains(p);
      ASSERT_EQ(vis[i], in ? 0u : 1u);
      hidden += in;
    }
    EXPECT_GT(hidden, 0u);
  }
}
