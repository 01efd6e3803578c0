// Integrators, sub-steps, the deflector guard of curved steps, and the NaN guard.
#include <gtest/gtest.h>

#include <cmath>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
Context makeContext(double dt) {
  ContextOptions o;
  o.dt = dt;
  o.threads = 2;
  return Context(o);
}
// The analytic projectile with linear drag k and gravity g after time t.
Vec3 projectile(Vec3 p0, Vec3 v0, Vec3 g, float k, double t) {
  const Vec3 term = g / k;
  const float e = float(std::exp(-k * t));
  return p0 + term * float(t) + (v0 - term) * ((1.0f - e) / k);
}
float projectileError(Integrator integ, double dt) {
  Context ctx = makeContext(dt);
  Group& g = ctx.createGroup("g", 1);
  ActionList list{Gravity{Vec3(0, -9.81f, 0)}, Damping{Vec3(0.5f)}, Move{}};
  list.setIntegrator(integ);
  g.setActions(list);
  Particle p;
  p.velocity = Vec3(10, 20, 0);
  g.add(p);
  ctx.run(std::size_t(std::lround(2.0 / dt)));
  return glm::length(g.particle(0).position -
                     projectile(Vec3(0), Vec3(10, 20, 0), Vec3(0, -9.81f, 0), 0.5f, 2.0));
}
float orbitRadiusError(Integrator integ, double dt) {
  Context ctx = makeContext(dt);
  Group& g = ctx.createGroup("g", 1);
  ActionList list{OrbitPoint{Vec3(0), 1.0f, 1e-6f}, Move{}};
  list.setIntegrator(integ);
  g.setActions(list);
  Particle p;
  p.position = Vec3(1, 0, 0);
  p.velocity = Vec3(0, 1, 0);  // circular: v² = M/r
  g.add(p);
  float worst = 0;
  for (int s = 0; s < int(4 * M_PI / dt); ++s) {
    ctx.step();
    worst = std::max(worst, std::abs(glm::length(g.particle(0).position) - 1.0f));
  }
  return worst;
}
}  // namespace

TEST(Integrators, ExactIsExactForGravityWithDrag) {
  // No truncation error at all: what is left is float rounding, about one ulp of the
  // position (~2e-6 at 20 units) per step, so the bound grows with the step count.
  EXPECT_LT(projectileError(Integrator::Exact, 0.5), 2e-5f);   // 4 steps
  EXPECT_LT(projectileError(Integrator::Exact, 0.01), 5e-4f);  // 200 steps
}

TEST(Integrators, OrdersOfAccuracyShowOnAProjectile) {
  // Halving dt divides the error by about 2 (first order) or 16 (fourth order).
  const float e1 = projectileError(Integrator::ExplicitEuler, 0.02);
  const float e2 = projectileError(Integrator::ExplicitEuler, 0.01);
  EXPECT_NEAR(e1 / e2, 2.0f, 0.3f);
  const float r1 = projectileError(Integrator::RK4, 0.5),
              r2 = projectileError(Integrator::RK4, 0.25);
  EXPECT_GT(r1 / r2, 10.0f);
  const float v1 = projectileError(Integrator::VelocityVerlet, 0.02);
  const float v2 = projectileError(Integrator::VelocityVerlet, 0.01);
  EXPECT_NEAR(v1 / v2, 4.0f, 1.0f);
  EXPECT_LT(projectileError(Integrator::RK4, 0.1), e2 / 100);
}

TEST(Integrators, HigherOrderKeepsAnOrbitRound) {
  const float euler = orbitRadiusError(Integrator::ExplicitEuler, 0.01);
  const float verlet = orbitRadiusError(Integrator::VelocityVerlet, 0.01);
  const float rk4 = orbitRadiusError(Integrator::RK4, 0.01);
  EXPECT_GT(euler, 0.05f);  // explicit Euler spirals out
  EXPECT_LT(verlet, 1e-3f);
  EXPECT_LT(rk4, 1e-5f);
}

TEST(Integrators, ExactRefusesForcesWithoutAClosedForm) {
  ActionList list{OrbitPoint{}, Move{}};
  EXPECT_THROW(list.setIntegrator(Integrator::Exact), InvalidArgument);
  ActionList ok{Gravity{}, Move{}};
  ok.setIntegrator(Integrator::Exact);
  EXPECT_THROW(ok.add(Turbulence{}), InvalidArgument);
}

// A curved step (RK4 with gravity) must not carry a resting or fast particle under the floor.
TEST(Integrators, CurvedStepsNeverEndBehindADeflector) {
  for (Integrator integ :
       {Integrator::RK4, Integrator::VelocityVerlet, Integrator::ExplicitEuler}) {
    Context ctx = makeContext(1.0 / 30.0);
    Group& g = ctx.createGroup("g", 1000);
    ActionList list{Gravity{Vec3(0, -30, 0)},
                    Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), 0.3f, 0.2f}, Move{}};
    list.setIntegrator(integ);
    g.setActions(list);
    Random rng(1, 0, 0, 0);
    for (int i = 0; i < 1000; ++i) {
      Particle p;
      p.position = Vec3(0, 10 * rng.uniform(), 0);
      p.velocity = Domain::sphere(Vec3(0), 1e4f * rng.uniform(), 0.0f).sample(rng);
      g.add(p);
    }
    for (int s = 0; s < 90; ++s) {
      ctx.step();
      for (std::size_t i = 0; i < g.size(); ++i)
        ASSERT_GE(g.particle(i).position.y, 0.0f) << integratorName(integ) << " step " << s;
    }
  }
}

// Apex heights of balls dropped from h0 onto a floor with restitution e: the n-th apex is
// e^{2n}·h0. Read where vy turns negative, as y + vy²/2g (exact on a parabola). Returns the
// worst |apex − e^{2n}·h0| / h0 over the first 3 bounces of every ball (1 if one is missed).
static float bounceApexError(Integrator integ, double dt, const Domain& floor) {
  const float g = 9.81f, e = 0.8f;
  const float h0[] = {0.5f, 1.0f, 1.37f};
  Context ctx = makeContext(dt);
  Group& grp = ctx.createGroup("g", 3);
  ActionList list{Gravity{Vec3(0, -g, 0)}, Bounce{floor, e, 0.0f}, Move{}};
  list.setIntegrator(integ);
  grp.setActions(list);
  for (float h : h0) {
    Particle p;
    p.position = Vec3(0.1f * h, h, -0.2f * h);
    p.velocity = Vec3(0.3f, 0.0f, -0.2f);  // along the floor too: no friction, kept
    grp.add(p);
  }
  float worst = 0.0f;
  int seen[3] = {0, 0, 0};
  float prevVy[3] = {0.0f, 0.0f, 0.0f};
  for (int s = 0; s < int(3.0 / dt); ++s) {
    ctx.step();
    for (int i = 0; i < 3; ++i) {
      const Particle p = grp.particle(std::size_t(i));
      if (prevVy[i] >= 0.0f && p.velocity.y < 0.0f && s > 0 && seen[i] < 3) {
        ++seen[i];
        const float apex = p.position.y + p.velocity.y * p.velocity.y / (2.0f * g);
        const float want = h0[i] * std::pow(e, 2.0f * float(seen[i]));
        worst = std::max(worst, std::abs(apex - want) / h0[i]);
      }
      prevVy[i] = p.velocity.y;
    }
  }
  for (int k : seen)
    if (k < 3) worst = 1.0f;
  return worst;
}

// Bounce reflects the velocity the particle has at the moment of impact, found on the
// parabola the integrator moves it on: with constant gravity the bounce is then exact (to
// float rounding) for Exact, Verlet and RK4, at any dt. Reflecting the step's start velocity
// instead is off by g·(dt − tau) at the impact: ~3e-2 of h0 at 24 Hz.
TEST(Integrators, BounceIsExactUnderConstantGravity) {
  const Domain floors[] = {Domain::plane(Vec3(0), Vec3(0, 1, 0)),
                           Domain::rectangle(Vec3(-5, 0, -5), Vec3(10, 0, 0), Vec3(0, 0, 10)),
                           Domain::disc(Vec3(0), Vec3(0, -1, 0), 5.0f)};
  for (const Domain& floor : floors)
    for (Integrator integ : {Integrator::Exact, Integrator::VelocityVerlet, Integrator::RK4})
      for (double dt : {1.0 / 24.0, 1.0 / 240.0}) {
        SCOPED_TRACE(std::string(integratorName(integ)) + " " + floor.name() + " dt " +
                     std::to_string(dt));
        const float err = bounceApexError(integ, dt, floor);
        EXPECT_LT(err, 1e-5f);
      }
}

TEST(Substeps, BoundTheStepAndTheDistance) {
  // One 1 s step with 100 sub-steps of explicit Euler equals 100 steps of 0.01 s.
  auto run = [](double dt, std::size_t steps, Substeps sub) {
    Context ctx = makeContext(dt);
    Group& g = ctx.createGroup("g", 1);
    ActionList list{OrbitPoint{Vec3(0), 1.0f, 1e-6f}, Move{}};
    list.setIntegrator(Integrator::ExplicitEuler);
    list.setSubsteps(sub);
    g.setActions(list);
    Particle p;
    p.position = Vec3(1, 0, 0);
    p.velocity = Vec3(0, 1, 0);
    g.add(p);
    ctx.run(steps);
    return g.particle(0).position;
  };
  const Vec3 a = run(1.0, 1, Substeps{0.01, 0.0f, 256});
  const Vec3 b = run(0.01, 100, Substeps{});
  EXPECT_NEAR(glm::length(a - b), 0.0f, 1e-5f);
  // Speed 1: 100 sub-steps (the bound a hair above 0.01 keeps float rounding from making 101).
  const Vec3 c = run(1.0, 1, Substeps{0.0, 0.0100001f, 256});
  EXPECT_NEAR(glm::length(c - b), 0.0f, 1e-5f);
  EXPECT_THROW(ActionList().setSubsteps(Substeps{-1.0}), InvalidArgument);
}

TEST(NonFinite, AParticleThatTurnsNaNIsKilledAndCounted) {
  Context ctx = makeContext(0.1);
  Group& g = ctx.createGroup("g", 10);
  g.setActions({Callback{[](Particle& p, const CallbackContext&) {
                  if (p.id == 3) p.velocity.x = NAN;
                  if (p.id == 5) p.position.y = INFINITY;
                }},
                Move{}});
  for (int i = 0; i < 10; ++i) g.add(Particle{});
  ctx.step();
  EXPECT_EQ(g.size(), 8u);
  EXPECT_EQ(g.stats().killedNonFinite, 2u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_TRUE(std::isfinite(p.position.x + p.position.y + p.velocity.x));
  }
  const auto& s = g.stats();
  EXPECT_EQ(s.emitted,
            g.size() + s.killedByAge + s.absorbed + s.droppedAtCapacity + s.killedNonFinite);
}
