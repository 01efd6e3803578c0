// Parity on the device: Deflectors, absorbers, blockers, 2-D and neighbour actions
// (kernels/surfaces.cl). Each test runs the same build on the CPU and on the device
// (tests/opencl/parity.hpp) and first checks that the action visibly changes the particles
// (hits, kills), so that a device doing nothing could not pass.
#include <algorithm>
#include <bit>
#include <random>
#include <vector>

#include "../culling_scene.hpp"
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

// The same build without the action under test: parity alone would also pass if the action
// did nothing on either backend.
void expectEffect(const Build& with, const Build& without, int steps = kSteps) {
  FLURRY_REQUIRE_OPENCL();
  const RunResult a = runEffect(Backend::Cpu, with, steps);
  const RunResult b = runEffect(Backend::Cpu, without, steps);
  EXPECT_TRUE(differs(a, b, 0)) << "the action changes nothing: the test could not fail";
}

// Runs parity on `actions` and checks that dropping actions[k] changes the result.
void checkAction(const ActionList& actions, std::size_t k, Emitter e = spray(),
                 AttributeSet require = {}, std::size_t capacity = 20000) {
  auto build = [=](const ActionList& list) -> Build {
    return [=](Context& ctx) -> Group& {
      Group& g = ctx.createGroup("surfaces", capacity);
      g.addEmitter(e);
      g.setActions(list);
      g.require(require);
      return g;
    };
  };
  expectEffect(build(actions), build(withoutAction(actions, k)));
  checkParity(build(actions));
}

const Bounce kFloor{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.6f, 0.1f, 0.0f};

// A few particles that live through the whole run: nothing dies, so both backends keep the
// particles in the same order (neighbour actions read others by index).
Emitter swarm(double rate = 150) {
  Emitter e = spray(Vec3(0.0f, 1.0f, 0.0f), rate);
  e.types[0].lifetime = 1000.0f;
  e.types[0].velocity = Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 2.0f);
  e.types[0].rotVelocity = Domain::box(Vec3(-3.0f), Vec3(3.0f));
  return e;
}

}  // namespace

// ---- Bounce -------------------------------------------------------------------------------

TEST(OpenCLSurfaces, BounceBoxOutside) {
  checkAction(
      {Gravity{kDown},
       Bounce{Domain::box(Vec3(-1.0f, 1.6f, -0.8f), Vec3(0.7f, 2.0f, 1.0f)), 0.7f, 0.2f, 0.1f},
       Bounce{Domain::box(Vec3(-3.0f, -0.5f, -3.0f), Vec3(3.0f, 0.3f, 3.0f)), 0.5f, 0.0f, 0.0f},
       Move{}, KillOld{}},
      1);
}

TEST(OpenCLSurfaces, BounceBoxInside) {
  Bounce b{Domain::box(Vec3(-1.2f, 0.0f, -0.9f), Vec3(1.0f, 2.2f, 1.1f)), 0.8f, 0.15f, 0.2f};
  b.inside = true;
  checkAction({Gravity{kDown}, b, Move{}, KillOld{}}, 1);
}

TEST(OpenCLSurfaces, BounceSphereInside) {
  Bounce b{Domain::sphere(Vec3(0.1f, 1.2f, 0.0f), 1.1f), 0.9f, 0.1f, 0.0f};
  b.inside = true;
  checkAction({Gravity{kDown}, b, Move{}, KillOld{}}, 1);
}

// Fast particles in a small sphere: several crossings in one step (the re-bounce loop).
TEST(OpenCLSurfaces, BounceSphereInsideFast) {
  Bounce b{Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 0.4f), 1.0f, 0.0f, 0.0f};
  b.inside = true;
  Emitter e = spray();
  e.types[0].velocity = Domain::sphere(Vec3(0.0f), 40.0f, 30.0f);
  checkAction({b, Move{}, KillOld{}}, 0, e);
}

TEST(OpenCLSurfaces, BounceSegments2D) {
  Bounce floor{Domain::line(Vec3(-3.0f, -0.2f, 0.0f), Vec3(3.0f, 0.3f, 0.0f)), 0.7f, 0.1f, 0.0f};
  Bounce wall{Domain::line(Vec3(1.0f, -1.0f, 0.0f), Vec3(1.3f, 3.0f, 0.0f)), 0.9f, 0.0f, 0.0f};
  Bounce tilted{Domain::line(Vec3(-1.0f, 2.0f, 0.0f), Vec3(-0.2f, 1.7f, 0.0f)), 0.5f, 0.3f, 0.05f};
  checkAction({Gravity{kDown}, Constrain2D{}, floor, wall, tilted, Move{}, KillOld{}}, 2);
}

// A segment in a tilted plane (planeNormal not z).
TEST(OpenCLSurfaces, BounceSegmentTiltedPlane) {
  Bounce s{Domain::line(Vec3(-3.0f, 0.0f, 0.0f), Vec3(3.0f, 0.2f, 0.5f)), 0.8f, 0.0f, 0.0f};
  s.planeNormal = Vec3(0.0f, 0.3f, 1.0f);
  checkAction({Gravity{kDown}, s, Move{}, KillOld{}}, 1);
}

// ---- Sink ---------------------------------------------------------------------------------

TEST(OpenCLSurfaces, SinkEnter) {
  const Domain regions[] = {
      Domain::sphere(Vec3(0.3f, 1.8f, 0.0f), 0.6f),
      Domain::box(Vec3(-2.0f, -1.0f, -2.0f), Vec3(2.0f, 0.5f, 0.0f)),
      Domain::cylinder(Vec3(0.0f, 1.5f, -1.0f), Vec3(0.0f, 1.5f, 1.0f), 0.5f),
      Domain::plane(Vec3(0.0f, 0.2f, 0.0f), Vec3(0.3f, -1.0f, 0.0f)),
  };
  for (const Domain& r : regions) {
    SCOPED_TRACE(r.name());
    Sink k{r, 0.0f, Sink::Mode::Enter};
    checkAction({Gravity{kDown}, k, Move{}, KillOld{}}, 1);
  }
}

TEST(OpenCLSurfaces, SinkLeaveWithPassThrough) {
  Sink k{Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 1.2f), 0.4f, Sink::Mode::Leave};
  checkAction({Gravity{kDown}, k, Move{}, KillOld{}}, 1);
}

// Inside a region the spray crosses for many steps: the once-per-particle decision (the same
// hash of seed, id, group and index on both backends), also across sub-steps.
TEST(OpenCLSurfaces, SinkInsideWithPassThrough) {
  ActionList list{
      Gravity{kDown},
      Sink{Domain::box(Vec3(-3.0f, 0.8f, -3.0f), Vec3(3.0f, 1.4f, 3.0f)), 0.3f, Sink::Mode::Inside},
      Sink{Domain::sphere(Vec3(0.0f, 0.5f, 0.0f), 0.8f), 0.6f, Sink::Mode::Enter}, Move{},
      KillOld{}};
  checkAction(list, 1);
  list.setSubsteps(Substeps{1.0 / 90.0});
  checkAction(list, 1);
}

TEST(OpenCLSurfaces, SinkHitEveryPiece) {
  const Domain pieces[] = {
      Domain::plane(Vec3(0.0f, 0.5f, 0.0f), Vec3(0.1f, 1.0f, 0.0f)),
      Domain::rectangle(Vec3(-1.0f, 1.8f, -1.0f), Vec3(1.5f, 0.0f, 0.2f), Vec3(0.3f, 0.2f, 1.6f)),
      Domain::disc(Vec3(0.0f, 0.4f, 0.0f), Vec3(0.2f, 1.0f, 0.1f), 1.5f, 0.3f),
      Domain::triangle(Vec3(-2.0f, 0.3f, -2.0f), Vec3(2.0f, 0.6f, -1.0f), Vec3(0.0f, 0.2f, 2.0f)),
  };
  for (const Domain& r : pieces) {
    SCOPED_TRACE(r.name());
    Sink k{r, 0.0f, Sink::Mode::Hit};
    checkAction({Gravity{kDown}, k, Move{}, KillOld{}}, 1);
  }
}

TEST(OpenCLSurfaces, SinkHitWithPassThroughAndSubsteps) {
  ActionList list{Gravity{kDown},
                  Sink{Domain::disc(Vec3(0.0f, 1.5f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 1.0f), 0.5f,
                       Sink::Mode::Hit},
                  kFloor, Move{}, KillOld{}};
  list.setSubsteps(Substeps{1.0 / 90.0});
  checkAction(list, 1);
}

TEST(OpenCLSurfaces, SinkVelocity) {
  checkAction({Gravity{kDown}, SinkVelocity{Domain::sphere(Vec3(0.0f, -4.0f, 0.0f), 2.0f), true},
               Move{}, KillOld{}},
              1);
  checkAction({Gravity{kDown},
               SinkVelocity{Domain::box(Vec3(-2.0f, -5.0f, -2.0f), Vec3(2.0f, 5.0f, 2.0f)), false},
               Move{}, KillOld{}},
              1);
}

// ---- Block --------------------------------------------------------------------------------

TEST(OpenCLSurfaces, BlockSeveral) {
  checkAction({Gravity{kDown}, Block{Domain::box(Vec3(-0.5f, 1.0f, -2.0f), Vec3(0.5f, 2.0f, 2.0f))},
               Move{}, Block{Domain::sphere(Vec3(1.0f, 1.0f, 0.0f), 0.8f)}, KillOld{}},
              1, spray(), {Attribute::Visible});
  checkAction({Gravity{kDown}, Block{Domain::box(Vec3(-0.5f, 1.0f, -2.0f), Vec3(0.5f, 2.0f, 2.0f))},
               Move{}, Block{Domain::sphere(Vec3(1.0f, 1.0f, 0.0f), 0.8f)}, KillOld{}},
              3, spray(), {Attribute::Visible});
}

// ---- Avoid, Constrain2D -------------------------------------------------------------------

TEST(OpenCLSurfaces, AvoidEveryObstacle) {
  const Domain obstacles[] = {
      Domain::sphere(Vec3(0.2f, 2.2f, 0.0f), 0.6f),
      Domain::sphere(Vec3(0.2f, 2.0f, 0.0f), 0.8f, 0.4f),
      Domain::box(Vec3(-1.0f, 1.8f, -0.5f), Vec3(0.5f, 2.3f, 1.0f)),
      Domain::blob(Vec3(0.0f, 2.0f, 0.3f), 0.5f),
      Domain::cylinder(Vec3(-1.0f, 2.0f, 0.0f), Vec3(1.0f, 2.2f, 0.0f), 0.4f, 0.1f),
      Domain::cylinder(Vec3(0.0f, 1.6f, -1.0f), Vec3(0.0f, 1.9f, 1.0f), 0.5f, 0.25f),
      Domain::cone(Vec3(0.0f, 2.8f, 0.0f), Vec3(0.2f, 1.7f, 0.0f), 0.9f, 0.3f),
      Domain::cone(Vec3(0.0f, 2.8f, 0.0f), Vec3(0.0f, 1.7f, 0.1f), 0.9f),
      Domain::plane(Vec3(0.0f, 2.0f, 0.0f), Vec3(0.2f, 1.0f, 0.0f)),
      Domain::rectangle(Vec3(-1.0f, 1.8f, -1.0f), Vec3(1.5f, 0.0f, 0.2f), Vec3(0.3f, 0.2f, 1.6f)),
      Domain::disc(Vec3(0.0f, 2.0f, 0.0f), Vec3(0.2f, 1.0f, 0.1f), 1.2f, 0.3f),
      Domain::triangle(Vec3(-2.0f, 1.9f, -2.0f), Vec3(2.0f, 2.1f, -1.0f), Vec3(0.0f, 1.8f, 2.0f)),
  };
  for (const Domain& o : obstacles) {
    SCOPED_TRACE(o.name());
    checkAction({Gravity{kDown}, Avoid{o, 2.0f, 1e-2f, 0.3f}, kFloor, Move{}, KillOld{}}, 1);
  }
}

TEST(OpenCLSurfaces, Constrain2D) {
  checkAction({Gravity{kDown}, Constrain2D{Vec3(0.1f, 0.2f, 0.3f), Vec3(0.3f, 0.2f, 1.0f)}, kFloor,
               Move{}, KillOld{}},
              1);
}

// ---- Neighbours ---------------------------------------------------------------------------

TEST(OpenCLSurfaces, Gravitate) {
  checkAction({Gravitate{0.05f, 1e-2f, 1.5f}, kFloor, Move{}}, 0, swarm());
}

TEST(OpenCLSurfaces, GravitateIntegrators) {
  for (Integrator in : {Integrator::ExplicitEuler, Integrator::VelocityVerlet, Integrator::RK4}) {
    SCOPED_TRACE(integratorName(in));
    ActionList list{Gravitate{0.05f, 1e-2f}, Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Move{}};
    list.setIntegrator(in);
    checkAction(list, 0, swarm(60));
  }
}

TEST(OpenCLSurfaces, Follow) {
  checkAction({Follow{3.0f, 1e-2f}, kFloor, Move{}}, 0, swarm());
  checkAction({Follow{3.0f, 1e-2f, 0.5f}, Damping{Vec3(0.3f)}, Move{}}, 0, swarm());
}

TEST(OpenCLSurfaces, FollowIntegrators) {
  for (Integrator in : {Integrator::ExplicitEuler, Integrator::VelocityVerlet, Integrator::RK4}) {
    SCOPED_TRACE(integratorName(in));
    ActionList list{Follow{3.0f, 1e-2f}, Damping{Vec3(0.2f)}, Move{}};
    list.setIntegrator(in);
    checkAction(list, 0, swarm());
  }
}

TEST(OpenCLSurfaces, MatchVelocity) {
  checkAction({MatchVelocity{2.0f, 1e-3f, 0.6f}, kFloor, Move{}}, 0, swarm());
}

// Sub-steps: the approach fraction for the sub-step's dt, computed on the device.
TEST(OpenCLSurfaces, MatchVelocitySubsteps) {
  ActionList list{MatchVelocity{2.0f, 1e-3f, 0.6f}, kFloor, Move{}};
  list.setSubsteps(Substeps{1.0 / 70.0});
  checkAction(list, 0, swarm(80));
}

TEST(OpenCLSurfaces, MatchRotVelocity) {
  checkAction({MatchRotVelocity{1.5f, 1e-3f, 0.7f}, kFloor, Move{}}, 0, swarm(),
              {Attribute::RotVelocity, Attribute::Up});
}

// ---- Disabled until codegen.cpp and kernels/tail.cl catch up -----------------------------
// Both pass with the two changes described in each comment (checked on a patched copy).

// The integrators' curved-step guard after Move (fused_pass.cpp guard): codegen.cpp refuses
// a Bounce before an integrating Move; it is to keep the step's start position and call
// surfaces.cl fl_bounce_guard for each such Bounce after the integrator.
TEST(OpenCLSurfaces, BounceUnderIntegrators) {
  Bounce sphere{Domain::sphere(Vec3(0.1f, 1.2f, 0.0f), 1.1f), 0.9f, 0.1f, 0.0f};
  sphere.inside = true;
  Bounce box{Domain::box(Vec3(-1.2f, 1.6f, -0.9f), Vec3(1.0f, 2.2f, 1.1f)), 0.8f, 0.15f, 0.2f};
  Bounce seg{Domain::line(Vec3(-3.0f, -0.2f, 0.0f), Vec3(3.0f, 0.3f, 0.0f)), 0.7f, 0.1f, 0.0f};
  // Planar pieces bounce on the parabola of the integrator's acceleration (Verlet, RK4, Exact).
  Bounce disc{Domain::disc(Vec3(0.0f, 0.2f, 0.0f), Vec3(0.1f, 1.0f, 0.0f), 1.5f, 0.3f), 0.7f, 0.2f,
              0.05f};
  const Bounce bounces[] = {kFloor, sphere, box, seg, disc};
  for (Integrator in : {Integrator::ExplicitEuler, Integrator::VelocityVerlet, Integrator::RK4,
                        Integrator::Exact}) {
    for (const Bounce& b : bounces) {
      SCOPED_TRACE(std::string(integratorName(in)) + " " + b.surface.name());
      ActionList list{Gravity{kDown}, Damping{Vec3(0.3f)}, b, Move{}, KillOld{}};
      list.setIntegrator(in);
      checkAction(list, 2);
    }
  }
}

// Particles die and the holes are closed from the tail: the neighbour actions read others
// by index, so the order must be the CPU's, whose first hole takes the last survivor
// (emission.cpp); tail.cl's fl_tail gives it the first (it is to read tail[moves - 1 - j]).
TEST(OpenCLSurfaces, NeighboursWhileParticlesDie) {
  checkAction({Gravitate{0.05f, 1e-2f, 1.5f}, Gravity{kDown}, kFloor, Move{}, KillOld{}}, 0,
              spray(Vec3(0.0f, 1.0f, 0.0f), 150));
  checkAction({Follow{3.0f, 1e-2f}, Gravity{kDown}, kFloor, Move{}, KillOld{}}, 0,
              spray(Vec3(0.0f, 1.0f, 0.0f), 150));
  checkAction({MatchVelocity{2.0f, 1e-3f, 0.6f}, Gravity{kDown}, kFloor, Move{}, KillOld{}}, 0,
              spray(Vec3(0.0f, 1.0f, 0.0f), 150));
}

// ---- Spatial culling per work-group (issue #17) ---------------------------------------------

namespace {

// The CPU culling tests' scene (tests/culling_scene.hpp) with three sets of deflectors;
// the run adds an emitter, so that newborns (each with its own step length) share
// work-groups with the others.
ActionList cullingScene(std::uint32_t seed) {
  return flurry::test::cullingScene(seed, 3);
}

struct CullRun {
  std::vector<std::uint32_t> bits;  // every particle's position, velocity, age, visibility, id
  GroupStats stats;
};

CullRun runCullingScene(std::uint32_t seed, bool cull, const Substeps* substeps,
                        std::size_t count) {
  ContextOptions o;
  o.backend = Backend::OpenCL;
  o.dt = 1.0 / 30.0;
  o.seed = seed;
  o.cull = cull;
  Context ctx(o);
  Group& g = ctx.createGroup("scene", count + 2000);
  ActionList list = cullingScene(seed);
  if (substeps) list.setSubsteps(*substeps);
  g.setActions(list);
  Emitter e = spray(Vec3(-20.0f, 0.0f, 10.0f), 600);
  g.addEmitter(e);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f);
  std::normal_distribution<float> speed(0.0f, 3.0f);
  // In x order, as particles near one another mostly are in a group (their emitter's).
  std::vector<Particle> ps(count);
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
  CullRun r;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    auto put = [&](float x) { r.bits.push_back(std::bit_cast<std::uint32_t>(x)); };
    for (int c = 0; c < 3; ++c) put(p.position[c]), put(p.velocity[c]);
    put(p.age);
    r.bits.push_back(p.visible ? 1u : 0u);
    r.bits.push_back(p.id);
  }
  r.stats = g.stats();
  return r;
}

// Each configuration is two programs (with and without culling) of a long list: a few
// seconds each on PoCL.
void expectCullingExact(std::size_t count, const Substeps* substeps) {
  FLURRY_REQUIRE_OPENCL();
  for (std::uint32_t seed : {1u, 2u}) {
    const CullRun on = runCullingScene(seed, true, substeps, count);
    const CullRun off = runCullingScene(seed, false, substeps, count);
    EXPECT_EQ(on.bits.size(), off.bits.size()) << "seed " << seed;
    EXPECT_TRUE(on.bits == off.bits) << "seed " << seed;
    EXPECT_EQ(on.stats.killedByAction, off.stats.killedByAction);
    EXPECT_GT(on.stats.blockActionsCulled, 0u);  // culling did skip work
    EXPECT_EQ(off.stats.blockActionsCulled, 0u);
  }
}

}  // namespace

// fl_act: many work-groups.
TEST(OpenCLCulling, RandomScenesAreBitwiseTheSameWithAndWithout) {
  expectCullingExact(20000, nullptr);
}

// fl_small (up to 4096 particles): the group's whole step in one work-group, in passes of it;
// sub-steps.
TEST(OpenCLCulling, SmallGroupIsBitwiseTheSameWithAndWithout) {
  const Substeps three{1.0 / 90.0, 0.0f, 8};  // its barriers in the sub-step loop
  expectCullingExact(1500, &three);
}

// A fast particle among slow ones reaches a deflector far from its work-group's other
// particles in one step: the swept bounds reach it, so it is bounced; a second, unreachable
// deflector is skipped (by every work-group of fl_act).
TEST(OpenCLCulling, AFarDeflectorReachedInOneStepStillBounces) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.backend = Backend::OpenCL;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 8192);
  flurry::test::farDeflectorScene(g, 8192);
  ctx.step();
  EXPECT_TRUE(flurry::test::fastParticleBounced(g));
  // 32 work-groups of 256: each skips the far sphere; the disc only where it is out of reach.
  EXPECT_GE(g.stats().blockActionsCulled, 32u);
}

// A deflector turns a work-group's paths towards a second one that their bounds, gathered
// before the first, did not reach: the bounds follow the bounce (codegen.cpp followCode),
// so the second still deflects them.
TEST(OpenCLCulling, ABouncedPathIsFollowedToTheNextDeflector) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.backend = Backend::OpenCL;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 256);
  // A wall at 45° through x = 1 sends +x into +y; a ceiling at y = 0.3 above it.
  g.setActions({Bounce{Domain::rectangle(Vec3(0.5f, -0.5f, -1.0f), Vec3(1.0f, 1.0f, 0.0f),
                                         Vec3(0.0f, 0.0f, 2.0f))},
                Bounce{Domain::rectangle(Vec3(0.0f, 0.3f, -1.0f), Vec3(2.0f, 0.0f, 0.0f),
                                         Vec3(0.0f, 0.0f, 2.0f))},
                Bounce{Domain::sphere(Vec3(0.0f, -500.0f, 0.0f), 1.0f)}, Move{}});
  for (int i = 0; i < 256; ++i) {
    Particle p;
    p.position = Vec3(0.9f, 0.0f, float(i) / 256.0f * 0.2f - 0.1f);
    p.velocity = Vec3(6.0f, 0.0f, 0.0f);
    g.add(p);
  }
  ctx.step();
  ASSERT_EQ(g.size(), 256u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_LT(p.velocity.y, -5.9f) << p.id;  // turned up by the wall, down by the ceiling
    EXPECT_LT(p.position.y, 0.3f) << p.id;   // under the ceiling
  }
  EXPECT_GE(g.stats().blockActionsCulled, 1u);  // the far sphere
}
