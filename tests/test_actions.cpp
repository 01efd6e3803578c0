// Every action against its closed-form expectation.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include "culling_scene.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;
using flurry::test::cullingScene;

// The CPU backend runs the widest build the CPU has (run natively, and under qemu as a CPU
// without AVX and one without AVX-512: tests/isa); FLURRY_ISA may pick a narrower one.
TEST(Dispatch, PicksTheWidestInstructionSetTheCpuHas) {
  const std::string isa = cpuInstructionSet();
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  const bool has512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512vl");
  const bool has2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (std::getenv("FLURRY_ISA") == nullptr) {
    EXPECT_EQ(isa, has512 ? "avx512" : has2 ? "avx2" : "baseline");
  }
  if (isa == "avx512") {
    EXPECT_TRUE(has512);
  }
  if (isa == "avx2") {
    EXPECT_TRUE(has2);
  }
#endif
  EXPECT_TRUE(isa == "avx512" || isa == "avx2" || isa == "baseline") << isa;
}

namespace {
ContextOptions opts(double dt = 0.01, unsigned threads = 1) {
  ContextOptions o;
  o.dt = dt;
  o.threads = threads;
  return o;
}
}  // namespace

TEST(Gravity, ProjectileMatchesTheDiscreteAndAnalyticSolutions) {
  Context ctx(opts(0.01));
  Group& g = ctx.createGroup("p", 4);
  g.setActions({Gravity{Vec3(0, -9.81f, 0)}, Move{}});
  Particle p;
  p.position = Vec3(1, 2, 3);
  p.velocity = Vec3(3, 10, -1);
  g.add(p);
  const int N = 100;
  ctx.run(N);
  const double dt = 0.01, T = N * dt, gy = -9.81;
  const Particle q = g.particle(0);
  // Semi-implicit Euler: p_N = p0 + v0 T + g dt^2 N(N+1)/2 exactly (up to float rounding).
  EXPECT_NEAR(q.position.x, 1 + 3 * T, 1e-4);
  EXPECT_NEAR(q.position.y, 2 + 10 * T + gy * dt * dt * N * (N + 1) / 2, 1e-4);
  EXPECT_NEAR(q.position.z, 3 - T, 1e-4);
  EXPECT_NEAR(q.velocity.y, 10 + gy * T, 1e-4);
  // ...which is the parabola p0 + v0 T + g T^2 / 2 to first order in dt.
  EXPECT_NEAR(q.position.y, 2 + 10 * T + 0.5 * gy * T * T, std::abs(gy) * T * dt);
}

// Move turns the up vector with the angular velocity, exactly (kernels/forces.h fl_turn_up): a
// spin of w about z for T seconds turns it by w T, whatever the steps, and keeps it unit.
TEST(Move, TurnsTheUpVectorByTheAngularVelocityExactly) {
  const float w = 2.5f;
  for (const double dt : {0.001, 0.05, 0.7}) {
    Context ctx(opts(dt));
    Group& g = ctx.createGroup("p", 2);
    g.require({Attribute::Up, Attribute::RotVelocity});
    g.setActions({Move{}});
    Particle spun, still;
    spun.up = Vec3(1.0f, 0.0f, 0.0f);
    spun.rotVelocity = Vec3(0.0f, 0.0f, w);
    still.up = Vec3(0.6f, 0.8f, 0.0f);  // no angular velocity: left as it is, to the bit
    g.add(spun);
    g.add(still);
    const int N = int(std::lround(7.0 / dt));
    ctx.run(N);
    const double angle = double(w) * dt * N;
    const Vec3 up = g.particle(0).up;
    EXPECT_NEAR(up.x, std::cos(angle), 1e-4) << dt;
    EXPECT_NEAR(up.y, std::sin(angle), 1e-4) << dt;
    EXPECT_EQ(up.z, 0.0f);
    EXPECT_NEAR(glm::length(up), 1.0f, 1e-5f) << dt;
    EXPECT_EQ(g.particle(1).up, still.up);
  }
}

TEST(Damping, DecaysExponentiallyAtAnyStepSize) {
  for (double dt : {0.1, 1.0}) {
    Context ctx(opts(dt));
    Group& g = ctx.createGroup("p", 1);
    g.setActions({Damping{Vec3(0.6931472f)}, Move{}});  // rate ln 2: halves each second
    Particle p;
    p.velocity = Vec3(8, -4, 2);
    g.add(p);
    ctx.run(std::size_t(std::lround(1.0 / dt)));
    const Vec3 v = g.particle(0).velocity;
    EXPECT_NEAR(v.x, 4.0, 1e-5) << "dt " << dt;
    EXPECT_NEAR(v.y, -2.0, 1e-5);
    EXPECT_NEAR(v.z, 1.0, 1e-5);
  }
}

TEST(Bounce, ReflectsWithRestitutionAndFriction) {
  Context ctx(opts(0.1));
  Group& g = ctx.createGroup("p", 1);
  const float e = 0.5f, mu = 0.25f;
  g.setActions({Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), e, mu, 0.0f}, Move{}});
  Particle p;
  p.position = Vec3(0, 0.1f, 0);  // hits the plane after 0.05 s of the 0.1 s step
  p.velocity = Vec3(2, -2, 0);
  g.add(p);
  ctx.step();
  const Particle q = g.particle(0);
  EXPECT_NEAR(q.velocity.x, 2 * (1 - mu), 1e-6);
  EXPECT_NEAR(q.velocity.y, 2 * e, 1e-6);
  // Impact at t = 0.05 at x = 0.1, then 0.05 s of the reflected motion.
  EXPECT_NEAR(q.position.x, 0.1 + 0.05 * 2 * (1 - mu), 1e-5);
  EXPECT_NEAR(q.position.y, 0.05 * 2 * e, 1e-5);
}

TEST(Bounce, CutoffSparesSlowSlidingFromFriction) {
  Context ctx(opts(0.1));
  Group& g = ctx.createGroup("p", 1);
  g.setActions({Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), 1.0f, 0.5f, 1.0f}, Move{}});
  Particle p;
  p.position = Vec3(0, 0.1f, 0);
  p.velocity = Vec3(0.5f, -2, 0);  // tangential speed 0.5 < cutoff 1
  g.add(p);
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.x, 0.5, 1e-6);
}

TEST(Bounce, MissesOutsideAFinitePieceAndHitsInside) {
  for (const Domain& d : {Domain::rectangle(Vec3(-1, 0, -1), Vec3(2, 0, 0), Vec3(0, 0, 2)),
                          Domain::disc(Vec3(0), Vec3(0, 1, 0), 1.0f),
                          Domain::triangle(Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(0, 0, 1))}) {
    Context ctx(opts(0.1));
    Group& g = ctx.createGroup("p", 2);
    g.setActions({Bounce{d, 1.0f, 0.0f, 0.0f}, Move{}});
    Particle in, out;
    in.position = Vec3(0, 0.1f, 0);
    in.velocity = Vec3(0, -2, 0);
    out.position = Vec3(5, 0.1f, 5);
    out.velocity = Vec3(0, -2, 0);
    g.add(in);
    g.add(out);
    ctx.step();
    EXPECT_GT(g.particle(0).position.y, 0.0f) << d.name();
    EXPECT_NEAR(g.particle(0).velocity.y, 2.0f, 1e-6) << d.name();
    EXPECT_LT(g.particle(1).position.y, 0.0f) << d.name();
  }
}

TEST(Bounce, SphereFromOutside) {
  Context ctx(opts(0.1));
  Group& g = ctx.createGroup("p", 1);
  g.setActions({Bounce{Domain::sphere(Vec3(0), 1.0f), 1.0f, 0.0f, 0.0f}, Move{}});
  Particle p;
  p.position = Vec3(0, 1.1f, 0);
  p.velocity = Vec3(0, -2, 0);
  g.add(p);
  ctx.step();
  EXPECT_NEAR(g.particle(0).velocity.y, 2.0f, 1e-5);
  EXPECT_NEAR(g.particle(0).position.y, 1.1f, 1e-5);
}

// No tunnelling: at speeds up to 1e4 units/s with dt = 1/30 no particle ends a step behind
// a deflector, from any direction, over many steps.
TEST(Bounce, NoTunnellingAtHighSpeed) {
  for (float speed : {10.0f, 1e3f, 1e4f}) {
    for (const Domain& d :
         {Domain::plane(Vec3(0, 0.5f, 0), Vec3(0, 1, 0)),
          Domain::rectangle(Vec3(-1e5f, 0.5f, -1e5f), Vec3(2e5f, 0, 0), Vec3(0, 0, 2e5f)),
          Domain::sphere(Vec3(0), 50.0f)}) {
      Context ctx(opts(1.0 / 30.0, 2));
      Group& g = ctx.createGroup("p", 4096);
      g.setActions({Gravity{Vec3(0, -9.81f, 0)}, Bounce{d, 0.7f, 0.1f, 0.0f}, Move{}});
      Random rng(5, 0, 0, 0);
      const bool sphere = std::holds_alternative<SphereDomain>(d.shape());
      for (int i = 0; i < 4096; ++i) {
        Particle p;
        Vec3 dir = Domain::sphere(Vec3(0), 1.0f, 1.0f).sample(rng);
        p.position = sphere ? dir * (50.0f + 200.0f * rng.uniform())
                            : Vec3(0, 0.5f + 1e3f * rng.uniform(), 0);
        p.velocity = sphere ? -dir * speed + Vec3(rng.uniform(), 0, 0) : dir * speed;
        g.add(p);
      }
      for (int s = 0; s < 60; ++s) {
        ctx.step();
        const auto px = g.lane(Attribute::Position, 0), py = g.lane(Attribute::Position, 1),
                   pz = g.lane(Attribute::Position, 2);
        for (std::size_t i = 0; i < g.size(); ++i) {
          if (sphere)
            ASSERT_GE(px[i] * px[i] + py[i] * py[i] + pz[i] * pz[i], 50.0f * 50.0f * (1 - 1e-6f))
                << "speed " << speed << " step " << s;
          else
            ASSERT_GE(py[i], 0.5f) << d.name() << " speed " << speed << " step " << s;
        }
      }
    }
  }
}

TEST(Sink, KillsInsideOrOutsideAndCountsIt) {
  Context ctx(opts());
  Group& g = ctx.createGroup("p", 100);
  g.setActions({Sink{Domain::box(Vec3(-1), Vec3(1)), 0.0f}});
  for (int i = 0; i < 10; ++i) {
    Particle p;
    p.position = Vec3(i < 4 ? 0.0f : 5.0f, 0, 0);
    g.add(p);
  }
  ctx.step();
  EXPECT_EQ(g.size(), 6u);
  EXPECT_EQ(g.stats().absorbed, 4u);
  EXPECT_EQ(g.stats().killedByAction[0], 4u);
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_EQ(g.particle(i).position.x, 5.0f);

  Group& h = ctx.createGroup("q", 100);
  h.setActions({Sink{Domain::sphere(Vec3(0), 1.0f), 0.0f, Sink::Mode::Outside}});
  Particle a, b;
  b.position = Vec3(3, 0, 0);
  h.add(a);
  h.add(b);
  ctx.step();
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h.particle(0).position.x, 0.0f);
}

// One way to say inside or outside: `mode` (the classic API's `killInside` switch is gone
// from Sink, where it doubled and could contradict the mode); SinkVelocity, which has no
// mode, keeps it.
template <class A>
constexpr bool kHasKillInside = requires(A a) {
  a.killInside;
};
TEST(Sink, ModeAloneSaysInsideOrOutside) {
  EXPECT_FALSE(kHasKillInside<Sink>);
  EXPECT_TRUE(kHasKillInside<SinkVelocity>);
}

TEST(Sink, PassThroughFractionIsRespected) {
  Context ctx(opts());
  const int n = 20000;
  Group& g = ctx.createGroup("p", n);
  g.setActions({Sink{Domain::box(Vec3(-1), Vec3(1)), 0.3f}});
  for (int i = 0; i < n; ++i) g.add(Particle{});
  ctx.step();
  const double passed = double(g.size()) / n;
  const double sigma = std::sqrt(0.3 * 0.7 / n);
  EXPECT_NEAR(passed, 0.3, 2 * sigma);
}

TEST(KillOld, KillsPastLifetimeAndCountsByAge) {
  Context ctx(opts(0.1));
  Group& g = ctx.createGroup("p", 10);
  g.setActions({Move{}, KillOld{}});
  for (int i = 0; i < 5; ++i) {
    Particle p;
    p.lifetime = 0.25f + 0.1f * i;  // 0.25 .. 0.65
    g.add(p);
  }
  ctx.run(3);  // age 0.3
  EXPECT_EQ(g.size(), 4u);
  ctx.run(2);  // age 0.5
  EXPECT_EQ(g.size(), 2u);
  EXPECT_EQ(g.stats().killedByAge, 3u);
}

TEST(Actions, InvalidParametersNameTheField) {
  auto expectParam = [](auto&& f, const std::string& param) {
    try {
      f();
      FAIL() << "no exception for " << param;
    } catch (const InvalidArgument& e) {
      EXPECT_EQ(e.parameter(), param) << e.what();
    }
  };
  expectParam([] { ActionList{Gravity{Vec3(0, NAN, 0)}}; }, "actions[0].Gravity.acceleration");
  expectParam([] { ActionList{Move{}, Damping{Vec3(-1)}}; }, "actions[1].Damping.rate");
  expectParam(
      [] {
        ActionList{Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), -1.0f}};
      },
      "actions[0].Bounce.restitution");
  expectParam(
      [] {
        ActionList{Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), 1.0f, 2.0f}};
      },
      "actions[0].Bounce.friction");
  expectParam([] { ActionList{Bounce{Domain::cylinder(Vec3(0), Vec3(1), 1.0f)}}; },
              "actions[0].Bounce.surface");
  expectParam(
      [] {
        ActionList{Sink{Domain::box(Vec3(0), Vec3(1)), 1.5f}};
      },
      "actions[0].Sink.passThrough");
  expectParam([] { Domain::sphere(Vec3(0), 0.0f); }, "sphere.outerRadius");
  expectParam(
      [] {
        Context c(opts());
        c.createGroup("g", 0);
      },
      "capacity");
  expectParam([] { Context c(opts(std::nan(""))); }, "dt");
}

// ---- Spatial culling (ContextOptions::cull): exact, bitwise ------------------------------

namespace {
std::vector<std::uint32_t> particleBits(const Group& g) {
  std::vector<std::uint32_t> out;
  auto put = [&](float x) { out.push_back(std::bit_cast<std::uint32_t>(x)); };
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    for (int c = 0; c < 3; ++c) put(p.position[c]), put(p.velocity[c]);
    put(p.age);
    out.push_back(p.visible ? 1u : 0u);
    out.push_back(p.id);
  }
  return out;
}

struct CullRun {
  std::vector<std::uint32_t> bits;
  GroupStats stats;
};

CullRun runCullingScene(std::uint32_t seed, bool cull, bool substeps) {
  ContextOptions o = opts(1.0 / 30.0, 2);
  o.cull = cull;
  o.seed = seed;
  Context ctx(o);
  Group& g = ctx.createGroup("scene", 20000);
  ActionList list = cullingScene(seed);
  if (substeps) list.setSubsteps({0.0, 2.0f, 8});
  g.setActions(list);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f);
  std::normal_distribution<float> speed(0.0f, 3.0f);
  // In x order, as particles near one another mostly are in a group (their emitter's).
  std::vector<Particle> ps(20000);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    Particle& p = ps[i];
    p.position = Vec3(pos(rng), pos(rng), pos(rng));
    p.velocity = Vec3(speed(rng), speed(rng), speed(rng)) * (i % 50 == 0 ? 20.0f : 1.0f);
    if (i % 97 == 0) p.velocity.y = -0.0f;  // a -0 the falloff gravity must keep as it does
  }
  std::sort(ps.begin(), ps.end(),
            [](const Particle& a, const Particle& b) { return a.position.x < b.position.x; });
  for (const Particle& p : ps) g.add(p);
  ctx.run(10);
  return {particleBits(g), g.stats()};
}
}  // namespace

TEST(Culling, RandomScenesAreBitwiseTheSameWithAndWithout) {
  for (std::uint32_t seed : {1u, 2u, 3u, 4u}) {
    for (bool substeps : {false, true}) {
      const CullRun on = runCullingScene(seed, true, substeps);
      const CullRun off = runCullingScene(seed, false, substeps);
      EXPECT_EQ(on.bits.size(), off.bits.size()) << seed << " " << substeps;
      EXPECT_TRUE(on.bits == off.bits) << "seed " << seed << " substeps " << substeps;
      EXPECT_EQ(on.stats.killedByAction, off.stats.killedByAction);
      EXPECT_GT(on.stats.blockActionsCulled, 0u);  // culling did skip work
      EXPECT_EQ(off.stats.blockActionsCulled, 0u);
    }
  }
}

// A fast particle among slow ones reaches a deflector far from the block's particles in one
// step: its block's swept bounds reach it, so it is bounced; a second, unreachable deflector
// is skipped.
TEST(Culling, AFarDeflectorReachedInOneStepStillBounces) {
  Context ctx(opts(0.1));
  Group& g = ctx.createGroup("g", 4096);
  flurry::test::farDeflectorScene(g, 2048);
  ctx.step();
  EXPECT_TRUE(flurry::test::fastParticleBounced(g));
  EXPECT_GE(g.stats().blockActionsCulled, 2u);  // the far sphere, for both blocks
}
