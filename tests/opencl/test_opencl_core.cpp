// Parity on the device: Core actions, integrators, sub-steps and the NaN guard on the device.
// Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp).
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

Build spraying(ActionList actions, AttributeSet require = {}) {
  return [=](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("core", 20000);
    g.addEmitter(spray());
    g.setActions(actions);
    if (!(require == AttributeSet{})) g.require(require);
    return g;
  };
}

}  // namespace

TEST(OpenCLCore, CopyVertexBAndRestore) {
  // Particles with a rest position fall, then from t = 1 s are steered home, arriving at 2.5 s.
  auto rest = [](ActionList list) {
    return [list](Context& ctx) -> Group& {
      Group& g = ctx.createGroup("restore", 2000);
      g.require({Attribute::PositionB, Attribute::VelocityB});
      for (int k = 0; k < 1000; ++k) {
        Particle p;
        p.position = Vec3(0.01f * float(k % 37), 0.02f * float(k % 53), 0.003f * float(k));
        p.positionB = Vec3(float(k % 10), 1.0f + 0.1f * float(k % 7), -0.5f * float(k % 3));
        p.velocity = Vec3(0.1f * float(k % 5), 2.0f, 0.0f);
        g.add(p);
      }
      g.setActions(list);
      return g;
    };
  };
  FLURRY_REQUIRE_OPENCL();
  auto check = [&](ActionList list) {
    const RunResult cpu = runEffect(Backend::Cpu, rest(list), 90);
    const RunResult cl = runEffect(Backend::OpenCL, rest(list), 90);
    expectSame(cpu, cl);
    return cpu;
  };
  // 90 steps of 1/30 s: home at 2.5 s, standing still.
  const RunResult home = check({Gravity{kDown}, Restore{1.0f, 1.5f}, Move{}});
  const Particle& p = home.byId.begin()->second;
  EXPECT_NEAR(glm::length(p.position - p.positionB), 0.0f, 1e-4f);
  // CopyVertexB after Move: the rest position and velocity follow the particle.
  const RunResult copied = check({Gravity{kDown}, Move{}, CopyVertexB{true, true}});
  const Particle& q = copied.byId.begin()->second;
  EXPECT_EQ(q.positionB, q.position);
  EXPECT_EQ(q.velocityB, q.velocity);
}

TEST(OpenCLCore, CallbackWithAnOpenCLBody) {
  // The same callback as C++ (CPU) and as OpenCL C statements (device).
  auto build = [](bool device) {
    return [device](Context& ctx) -> Group& {
      Group& g = ctx.createGroup("callback", 20000);
      g.addEmitter(spray());
      Callback cb;
      cb.attributes = {Attribute::Position, Attribute::Velocity, Attribute::UserData};
      cb.function = [](Particle& p, const CallbackContext& c) {
        p.userData += c.dt;
        if (p.position.y > 2.0f) p.velocity.x += 0.5f;
      };
      if (device) cb.opencl = "user += dt;\nif (py > 2.0f) vx += 0.5f;";
      // The far sink makes the device's program one that culls (its work-items past the
      // live particles run the list on zeros): the callback runs for live particles only.
      g.setActions({Gravity{kDown}, cb, Move{}, KillOld{},
                    Sink{.region = Domain::sphere(Vec3(100.0f, 0.0f, 0.0f), 1.0f)}});
      return g;
    };
  };
  FLURRY_REQUIRE_OPENCL();
  const RunResult cpu = runEffect(Backend::Cpu, build(false), kSteps);
  const RunResult cl = runEffect(Backend::OpenCL, build(true), kSteps);
  EXPECT_GT(cpu.stats.emitted, 0u);
  expectSame(cpu, cl);
}

TEST(OpenCLCore, ACallbackWrittenOnceRunsOnBoth) {
  // One FLURRY_CALLBACK body: C++ on the CPU, OpenCL C on the device, the same particles.
  // Builtins with OpenCL's definitions (clamp, mix, step, min, max), <cmath>'s correctly
  // rounded ones (sqrt, fmax), a comma in a declaration and a break.
  const Callback cb = FLURRY_CALLBACK(
      const float speed = sqrt(vx * vx + vy * vy + vz * vz), cap = 2.5f;
      user += dt;
      if (speed > cap) {
        vx = vx * (cap / speed);
        vz = vz * (cap / speed);
      }
      if (id % 3u == 1u) break;
      vy += clamp(mix(0.0f, 1.0f, 0.5f), 0.0f, 0.25f) * step(2.0f, py) + fmax(min(py, 0.0f), -1.0f);
      size = max(size, 0.02f););
  checkParity(spraying({Gravity{kDown}, cb, Move{}, KillOld{}}));
}

TEST(OpenCLCore, ClocksSeedsAndUpdateIntervalsAsOnTheCpu) {
  // A group with its own clock (half speed), its own seed (random actions keyed by its own
  // steps) and an update interval (a step of three steps' time every third step): the device
  // takes each step's dt, time, seed and step key from the host as the CPU does.
  auto build = [](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("lod", 20000);
    g.addEmitter(spray());
    g.setActions(
        {Gravity{kDown}, RandomAccel{Domain::sphere(Vec3(0.0f), 2.0f)}, Move{}, KillOld{}});
    g.setTimeScale(0.5).setSeed(9, 1).setUpdateInterval(3);
    return g;
  };
  checkParity(build);
}

// Groups of one context spread over the device's queues (as many as it has compute units,
// up to four) and run side by side: each is still what the CPU makes of it, and one read
// back while the others' steps are queued sees its own.
TEST(OpenCLCore, ManyGroupsOnSeveralQueuesAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend backend) {
    Context ctx(parityOptions(backend));
    std::vector<Group*> groups;
    for (int k = 0; k < 8; ++k) {
      Group& g = ctx.createGroup("g" + std::to_string(k), 3000);
      g.addEmitter(spray(Vec3(float(k), 1.0f, 0.0f), 300.0 + 100.0 * k));
      g.setActions({Gravity{kDown},
                    Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f, 0.1f, 0.0f},
                    Move{}, KillOld{}});
      groups.push_back(&g);
    }
    std::vector<std::size_t> midway;
    for (int s = 0; s < 60; ++s) {
      ctx.step();
      if (s % 20 == 19) midway.push_back(groups[std::size_t(s / 20)]->size());
    }
    std::vector<RunResult> results;
    for (Group* g : groups) results.push_back(resultOf(*g));
    return std::pair{results, midway};
  };
  const auto [cpu, cpuMidway] = run(Backend::Cpu);
  const auto [cl, clMidway] = run(Backend::OpenCL);
  EXPECT_EQ(cpuMidway, clMidway);
  ASSERT_EQ(cpu.size(), cl.size());
  for (std::size_t k = 0; k < cpu.size(); ++k) {
    SCOPED_TRACE("group " + std::to_string(k));
    EXPECT_GT(cpu[k].size, 0u);
    expectSame(cpu[k], cl[k]);
  }
}

TEST(OpenCLCore, ACallbackWithoutAnOpenCLBodyIsRefusedByName) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.backend = Backend::OpenCL;
  Context ctx(o);
  Group& g = ctx.createGroup("cb", 100);
  g.addEmitter(spray());
  g.setActions({Callback{[](Particle&, const CallbackContext&) {}}, Move{}});
  try {
    ctx.step();
    FAIL() << "a C++-only callback ran on the device";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("Callback"), std::string::npos) << e.what();
  }
}

class OpenCLIntegrators : public ::testing::TestWithParam<Integrator> {};

TEST_P(OpenCLIntegrators, GravityAndDrag) {
  ActionList list{Gravity{kDown}, Damping{Vec3(0.3f, 0.1f, 0.6f)}, Move{}, KillOld{}};
  list.setIntegrator(GetParam());
  checkParity(spraying(list, {Attribute::PrevPosition}));
}

// A force after the last Move, or in a list without one, is its own update under every
// integrator (only a Move that follows it evaluates it): the device once dropped it.
TEST_P(OpenCLIntegrators, ForcesAfterTheLastMoveAreTheirOwnUpdate) {
  ActionList after{Gravity{kDown}, Move{}, Damping{Vec3(0.3f, 0.1f, 0.6f)},
                   Gravity{Vec3(2.0f, 0.0f, 0.0f)}, KillOld{}};
  after.setIntegrator(GetParam());
  checkParity(spraying(after), 60);
  ActionList none{Gravity{kDown}, Damping{Vec3(0.5f)}, KillOld{}};
  none.setIntegrator(GetParam());
  checkParity(spraying(none), 60);
}

INSTANTIATE_TEST_SUITE_P(OpenCLCore, OpenCLIntegrators,
                         ::testing::Values(Integrator::ExplicitEuler, Integrator::VelocityVerlet,
                                           Integrator::RK4, Integrator::Exact));

TEST(OpenCLCore, SubstepsByTimeAndByDistance) {
  ActionList byTime{Gravity{kDown}, Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.7f},
                    Move{}, KillOld{}};
  byTime.setSubsteps({1.0 / 100.0, 0.0f, 16});
  checkParity(spraying(byTime));
  ActionList byDistance = byTime;
  byDistance.setSubsteps({0.0, 0.05f, 16});
  checkParity(spraying(byDistance));
}

// A whole number as the distance: the program spelled it "1f", which is no OpenCL literal.
TEST(OpenCLCore, SubstepsByAWholeDistance) {
  ActionList list{Gravity{kDown}, Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.7f},
                  Move{}, KillOld{}};
  list.setSubsteps({0.0, 1.0f, 16});
  checkParity(spraying(list));
}

TEST(OpenCLCore, NonFiniteParticlesAreKilledAndCounted) {
  // A callback that poisons some particles: both backends kill and count the same ones.
  auto build = [](bool device) {
    return [device](Context& ctx) -> Group& {
      Group& g = ctx.createGroup("nan", 20000);
      g.addEmitter(spray());
      Callback cb;
      cb.attributes = {Attribute::Position, Attribute::Id};
      cb.function = [](Particle& p, const CallbackContext&) {
        if (p.id % 7 == 3 && p.position.y > 1.5f) p.position.x = std::nanf("");
      };
      if (device) cb.opencl = "if (id % 7u == 3u && py > 1.5f) px = NAN;";
      g.setActions({Gravity{kDown}, Move{}, cb, KillOld{}});
      return g;
    };
  };
  FLURRY_REQUIRE_OPENCL();
  const RunResult cpu = runEffect(Backend::Cpu, build(false), kSteps);
  const RunResult cl = runEffect(Backend::OpenCL, build(true), kSteps);
  EXPECT_GT(cpu.stats.killedNonFinite, 0u);
  expectSame(cpu, cl);
}

TEST(OpenCLCore, HairStrandsMatchTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  struct Out {
    Strands strands;
    GroupStats stats;
  };
  auto run = [](Backend backend) {
    ContextOptions o;
    o.seed = 11;
    o.backend = backend;
    Context ctx(o);
    Group& g = ctx.createGroup("fur", 4000);
    Emitter e = spray(Vec3(0.0f), 300);
    e.types[0].lifetime = Fuzzy(1.5f, 0.5f);
    g.addEmitter(e);
    g.require({Attribute::Color, Attribute::Size});
    g.setActions({Gravity{kDown}, Damping{Vec3(0.2f)},
                  Bounce{Domain::plane(Vec3(0.0f, -0.5f, 0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f},
                  Sink{Domain::sphere(Vec3(1.0f, 0.0f, 0.0f), 0.5f), 0.0f}, Move{}, KillOld{}});
    g.setHair({true, 2, 24});
    ctx.run(30);
    return Out{g.strands(), g.stats()};
  };
  const Out cpu = run(Backend::Cpu), cl = run(Backend::OpenCL);
  ASSERT_GT(cpu.strands.size(), 100u);
  EXPECT_EQ(cpu.stats.emitted, cl.stats.emitted);
  EXPECT_EQ(cpu.stats.killedByAge, cl.stats.killedByAge);
  EXPECT_EQ(cpu.stats.absorbed, cl.stats.absorbed);
  EXPECT_EQ(cpu.stats.killedByAction, cl.stats.killedByAction);
  ASSERT_EQ(cpu.strands.start, cl.strands.start);
  float worst = 0;
  for (std::size_t v = 0; v < cpu.strands.vertexCount(); ++v)
    for (int c = 0; c < 3; ++c) {
      const float a = cpu.strands.position[v][c], b = cl.strands.position[v][c];
      worst = std::max(worst, std::abs(a - b));
      ASSERT_LE(std::abs(a - b), kAbs + kRel * std::abs(a)) << "vertex " << v;
      ASSERT_EQ(cpu.strands.color[v][c], cl.strands.color[v][c]);
    }
  EXPECT_EQ(cpu.strands.radius, cl.strands.radius);
  std::printf("[ hair     ] %zu strands, %zu vertices; largest |cpu - opencl| %g\n",
              cpu.strands.size(), cpu.strands.vertexCount(), worst);
}

// A hair group fed by a sub-emitter: the newborns the host appends after a step are made
// strands in the next, with that step's own newborns, in id order, as on the CPU.
TEST(OpenCLCore, HairFedByASubEmitterAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend backend) {
    Context ctx(parityOptions(backend));
    Group& sparks = ctx.createGroup("sparks", 4000);
    sparks.addEmitter(spray(Vec3(0.0f, 1.0f, 0.0f), 600));
    sparks.setActions({Gravity{kDown}, Move{}, KillOld{}});
    Group& fur = ctx.createGroup("fur", 6000);
    Emitter own = spray(Vec3(2.0f, 0.0f, 0.0f), 150);
    own.types[0].lifetime = 0.6f;
    fur.addEmitter(own);
    DeathEmitter de;
    de.source = "sparks";
    de.count = 0.5f;
    de.types[0].velocity = Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 0.5f);
    de.types[0].lifetime = 0.5f;
    fur.addDeathEmitter(de);
    fur.setActions({Gravity{kDown}, Move{}, KillOld{}});
    fur.setHair({true, 2, 16});
    ctx.run(120);
    return std::pair(fur.strands(), fur.stats());
  };
  const auto [cpu, cpuStats] = run(Backend::Cpu);
  const auto [cl, clStats] = run(Backend::OpenCL);
  EXPECT_EQ(cpuStats.emitted, clStats.emitted);
  EXPECT_GT(cpuStats.emitted, 900u);  // its own 600 and the sub-emitter's
  ASSERT_EQ(cpu.start, cl.start);
  for (std::size_t v = 0; v < cpu.vertexCount(); ++v)
    for (int c = 0; c < 3; ++c)
      ASSERT_LE(std::abs(cpu.position[v][c] - cl.position[v][c]),
                kAbs + kRel * std::abs(cpu.position[v][c]))
          << "vertex " << v;
}

TEST(OpenCLCore, ACallbackMayNotReturn) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.backend = Backend::OpenCL;
  Context ctx(o);
  Group& g = ctx.createGroup("cb", 100);
  g.addEmitter(spray());
  Callback cb;
  cb.function = [](Particle&, const CallbackContext&) {};
  cb.opencl = "if (py > 1.0f) return;";
  g.setActions({cb, Move{}});
  try {
    ctx.step();
    FAIL() << "a callback with 'return' was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("return"), std::string::npos) << e.what();
  }
}

// Death events on the device: the same deaths as the CPU's, step by step (ids, causes and
// times exactly, places and velocities within the parity tolerance), the first `room` in
// particle order when a step has more and the rest counted alike. A small group (one
// work-group's step when it does not record) and one of many tiles, and a group that stores
// no velocity (its events say zero).
TEST(OpenCLCore, DeathEventsAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend backend, double rate, std::size_t room, bool velocity) {
    Context ctx(parityOptions(backend));
    Group& g = ctx.createGroup("deaths", 40000);
    g.addEmitter(spray(Vec3(0.0f, 1.0f, 0.0f), rate));
    // Killed below the floor (Sink, action 1) or by age (KillOld, action 3).
    ActionList list{
        Gravity{kDown},
        Sink{.region = Domain::box(Vec3(-50.0f, -50.0f, -50.0f), Vec3(50.0f, -5.0f, 50.0f))},
        Move{}, KillOld{}};
    if (!velocity)
      list = {Sink{.region = Domain::box(Vec3(-0.05f), Vec3(0.05f, 2.0f, 0.05f))}, KillOld{}};
    g.setActions(list);
    g.recordDeaths(room);
    EXPECT_EQ(g.attributes().has(Attribute::Velocity), velocity);
    std::vector<std::vector<DeathEvent>> steps;
    for (int s = 0; s < 90; ++s) {
      ctx.step();
      steps.emplace_back(g.deaths().begin(), g.deaths().end());
    }
    return std::pair(steps, g.stats());
  };
  for (const auto& [rate, room, velocity] :
       {std::tuple(1500.0, std::size_t(1000000), true), std::tuple(1500.0, std::size_t(20), true),
        std::tuple(9000.0, std::size_t(1000000), true), std::tuple(9000.0, std::size_t(150), true),
        std::tuple(1500.0, std::size_t(1000000), false)}) {
    SCOPED_TRACE("rate " + std::to_string(rate) + ", room " + std::to_string(room) +
                 (velocity ? "" : ", no velocity"));
    const auto [cpu, cpuStats] = run(Backend::Cpu, rate, room, velocity);
    const auto [cl, clStats] = run(Backend::OpenCL, rate, room, velocity);
    ASSERT_EQ(cpu.size(), cl.size());
    std::size_t events = 0, causes[2] = {0, 0};
    for (std::size_t s = 0; s < cpu.size(); ++s) {
      ASSERT_EQ(cpu[s].size(), cl[s].size()) << "step " << s;
      for (std::size_t k = 0; k < cpu[s].size(); ++k) {
        const DeathEvent &a = cpu[s][k], &b = cl[s][k];
        ASSERT_EQ(a.id, b.id) << "step " << s << ", event " << k;
        EXPECT_EQ(a.action, b.action);
        EXPECT_EQ(a.time, b.time);
        for (int c = 0; c < 3; ++c) {
          expectClose(a.position[c], b.position[c], "position", a.id, c);
          expectClose(a.velocity[c], b.velocity[c], "velocity", a.id, c);
          if (!velocity) {
            EXPECT_EQ(b.velocity[c], 0.0f);
          }
        }
        ++causes[a.action == (velocity ? 1u : 0u) ? 0 : 1];  // the Sink, or KillOld
      }
      events += cpu[s].size();
    }
    EXPECT_EQ(cpuStats.deathEventsDropped, clStats.deathEventsDropped);
    EXPECT_EQ(cpuStats.killedByAction, clStats.killedByAction);
    // Each run has deaths of both causes, and the small rooms dropped some.
    EXPECT_GT(causes[0], 0u);
    if (velocity) {
      EXPECT_GT(causes[1], 0u);  // (without Move nothing ages)
    }
    if (room < 1000) {
      EXPECT_GT(cpuStats.deathEventsDropped, 0u);
    }
    EXPECT_GT(events, 0u);
  }
}

// Collision events on the device: the same deflections as the CPU's, step by step, in the
// CPU's order (particle, sub-step, action): ids and Bounces exactly, places, arriving
// velocities, normals and times within the parity tolerance; the first `room` when a step has
// more, the rest counted alike. A floor (a planar piece), a ball from outside and a box from
// inside, on the straight path (semi-implicit Euler, two sub-steps) and on the parabola
// (Exact: the floor bounces with the acceleration).
TEST(OpenCLCore, CollisionEventsAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend backend, Integrator integrator, std::size_t room) {
    Context ctx(parityOptions(backend));
    Group& g = ctx.createGroup("hits", 20000);
    g.addEmitter(spray(Vec3(0.0f, 1.0f, 0.0f), 3000));
    ActionList list{Gravity{kDown},
                    Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.6f, 0.1f},
                    Bounce{Domain::sphere(Vec3(0.3f, 2.5f, 0.0f), 0.6f), 0.8f},
                    Bounce{Domain::box(Vec3(-1.5f, -1.0f, -1.5f), Vec3(1.5f, 6.0f, 1.5f)), 0.9f,
                           0.0f, 0.0f, true},
                    Move{},
                    KillOld{}};
    list.setIntegrator(integrator);
    if (integrator == Integrator::SemiImplicitEuler) list.setSubsteps({1.0 / 60.0, 0.0f, 4});
    g.setActions(list);
    g.recordCollisions(room);
    std::vector<std::vector<CollisionEvent>> steps;
    for (int s = 0; s < 60; ++s) {
      ctx.step();
      steps.emplace_back(g.collisions().begin(), g.collisions().end());
    }
    return std::pair(steps, g.stats());
  };
  for (const auto& [integrator, room] :
       {std::pair(Integrator::SemiImplicitEuler, std::size_t(1 << 20)),
        std::pair(Integrator::SemiImplicitEuler, std::size_t(40)),
        std::pair(Integrator::Exact, std::size_t(1 << 20))}) {
    SCOPED_TRACE(std::string(integrator == Integrator::Exact ? "Exact" : "semi-implicit Euler") +
                 ", room " + std::to_string(room));
    const auto [cpu, cpuStats] = run(Backend::Cpu, integrator, room);
    const auto [cl, clStats] = run(Backend::OpenCL, integrator, room);
    ASSERT_EQ(cpu.size(), cl.size());
    std::size_t byBounce[3] = {0, 0, 0};
    for (std::size_t s = 0; s < cpu.size(); ++s) {
      ASSERT_EQ(cpu[s].size(), cl[s].size()) << "step " << s;
      for (std::size_t k = 0; k < cpu[s].size(); ++k) {
        const CollisionEvent &a = cpu[s][k], &b = cl[s][k];
        ASSERT_EQ(a.id, b.id) << "step " << s << ", event " << k;
        ASSERT_EQ(a.action, b.action) << "step " << s << ", event " << k;
        EXPECT_NEAR(a.time, b.time, 1e-6) << "particle " << a.id;
        for (int c = 0; c < 3; ++c) {
          expectClose(a.position[c], b.position[c], "position", a.id, c);
          expectClose(a.velocity[c], b.velocity[c], "velocity", a.id, c);
          expectClose(a.normal[c], b.normal[c], "normal", a.id, c);
        }
        if (a.action >= 1 && a.action <= 3) ++byBounce[a.action - 1];
      }
    }
    EXPECT_EQ(cpuStats.collisionEventsDropped, clStats.collisionEventsDropped);
    // Every Bounce deflected some, and the small room dropped some.
    for (std::size_t n : byBounce) EXPECT_GT(n, 0u);
    if (room < 1000) {
      EXPECT_GT(cpuStats.collisionEventsDropped, 0u);
    }
  }
}

// Sub-emitters on death, on collision and on birth with their source on the device: the
// source's events come back from the device, the host makes their newborns as on the CPU
// (emission.cpp emitFrom) and sends only those to the device's end of the group. The splashes
// are the same particles as the CPU's, step after step, flying on under their own list.
TEST(OpenCLCore, SubEmittersOnDeathCollisionAndBirthAsOnTheCpu) {
  auto build = [](Context& ctx) -> Group& {
    Group& sparks = ctx.createGroup("sparks", 20000);
    sparks.addEmitter(spray(Vec3(0.0f, 1.0f, 0.0f), 1500));
    sparks.setActions({Gravity{kDown},
                       Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f, 0.2f},
                       Move{}, KillOld{}});
    Group& splash = ctx.createGroup("splash", 30000);
    ParticleType drop;
    drop.velocity = Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 0.5f);
    drop.lifetime = Fuzzy(0.5f, 0.2f);
    DeathEmitter onDeath;
    onDeath.source = "sparks";
    onDeath.count = 2.5f;
    onDeath.shape = Domain::sphere(Vec3(0.0f), 0.05f);
    onDeath.types = {drop};
    splash.addDeathEmitter(onDeath);
    DeathEmitter onHit = onDeath;
    onHit.on = DeathEmitter::Trigger::Collision;
    onHit.count = 0.5f;
    onHit.inheritVelocity = 0.3f;
    splash.addDeathEmitter(onHit);
    DeathEmitter onBirth = onDeath;  // a puff where each spark is born, a third of the time
    onBirth.on = DeathEmitter::Trigger::Birth;
    onBirth.count = 0.3f;
    onBirth.inheritVelocity = 0.5f;
    splash.addDeathEmitter(onBirth);
    splash.setActions({Gravity{kDown}, Move{}, KillOld{}});
    return splash;
  };
  checkParity(build, 90);
}

// A particle budget on the device: the context brings the groups' counts up to date before it
// shares the room out, the host fits each group's births as the CPU does (DropNewest,
// ScaleEmission), and a DropOldest group past its share is trimmed on the host and goes back
// whole. The same shares, counts and particles as on the CPU, step after step, also when the
// budget is lowered below what lives.
TEST(OpenCLCore, AParticleBudgetAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend backend) {
    Context ctx(parityOptions(backend));
    auto group = [&](const char* name, BudgetPolicy policy, std::vector<float> xs, float life) {
      Group& g = ctx.createGroup(name, 6000);
      for (float x : xs) {
        Emitter e = spray(Vec3(x, 1.0f, 0.0f), 1800);
        e.types[0].lifetime = life;
        g.addEmitter(e);
      }
      g.setActions({Gravity{kDown}, Move{}, KillOld{}});
      g.setBudgetPolicy(policy);
      return &g;
    };
    const std::vector<Group*> groups{
        group("newest", BudgetPolicy::DropNewest, {0.0f}, 1.5f),
        group("scaled", BudgetPolicy::ScaleEmission, {-3.0f, 3.0f}, 1.5f),
        group("oldest", BudgetPolicy::DropOldest, {6.0f}, 100.0f)};
    ctx.setParticleBudget(4000);
    std::vector<std::vector<std::size_t>> sizes;
    for (int s = 0; s < 60; ++s) {
      if (s == 40) ctx.setParticleBudget(1500);  // below what lives: DropOldest shrinks at once
      ctx.step();
      // Not every step: asking a device group's size brings its count to the host, which the
      // context must do itself.
      if (s % 10 != 9) continue;
      sizes.emplace_back();
      for (Group* g : groups) sizes.back().push_back(g->size());
    }
    std::vector<RunResult> results;
    for (Group* g : groups) results.push_back(resultOf(*g));
    return std::pair(sizes, results);
  };
  const auto [cpuSizes, cpu] = run(Backend::Cpu);
  const auto [clSizes, cl] = run(Backend::OpenCL);
  for (std::size_t s = 0; s < cpuSizes.size(); ++s)
    ASSERT_EQ(cpuSizes[s], clSizes[s]) << "step " << 10 * s + 9;
  for (std::size_t k = 0; k < cpu.size(); ++k) {
    SCOPED_TRACE("group " + std::to_string(k));
    expectSame(cpu[k], cl[k]);
    EXPECT_EQ(cpu[k].stats.droppedAtBudget, cl[k].stats.droppedAtBudget);
    EXPECT_EQ(cpu[k].stats.killedByBudget, cl[k].stats.killedByBudget);
  }
  // Each policy gave up what it says.
  EXPECT_GT(cpu[0].stats.droppedAtBudget, 0u);
  EXPECT_GT(cpu[1].stats.droppedAtBudget, 0u);
  EXPECT_GT(cpu[2].stats.killedByBudget, 0u);
  std::size_t last = 0;
  for (std::size_t n : cpuSizes.back()) last += n;
  EXPECT_LE(last, 1500u);
}

// Trails on the device: the ring starts at each newborn's birth place, moves with its
// particle when the dead's holes are filled, turns each step, and comes to the host with the
// positions. The same trails as on the CPU, point for point, for particles born by emitters
// and by a sub-emitter (appended on the host), for a trail set on live particles midway, and
// after the trail is lengthened.
TEST(OpenCLCore, TrailsAsOnTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  using Trails = std::map<std::uint32_t, std::vector<Vec3>>;
  auto trailsOf = [](const Group& g) {
    Trails out;
    std::vector<Vec3> points(64);
    for (std::size_t i = 0; i < g.size(); ++i) {
      const std::size_t n = g.trail(i, points);
      out[g.particle(i).id].assign(points.begin(), points.begin() + std::ptrdiff_t(n));
    }
    return out;
  };
  auto run = [&](Backend backend) {
    Context ctx(parityOptions(backend));
    Group& sparks = ctx.createGroup("sparks", 6000);
    sparks.addEmitter(spray(Vec3(0.0f, 1.0f, 0.0f), 1500));
    // Killed below the floor's edge (a Sink) and by age: holes to fill every step.
    sparks.setActions(
        {Gravity{kDown}, Bounce{Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 2.0f), 0.5f, 0.1f},
         Sink{.region = Domain::box(Vec3(-50.0f), Vec3(50.0f, -1.0f, 50.0f))}, Move{}, KillOld{}});
    sparks.setTrail({.length = 6});
    Group& splash = ctx.createGroup("splash", 8000);
    DeathEmitter de;
    de.source = "sparks";
    de.count = 1.5f;
    de.types[0].velocity = Domain::sphere(Vec3(0.0f, 2.0f, 0.0f), 1.0f);
    de.types[0].lifetime = 0.7f;
    splash.addDeathEmitter(de);
    splash.setActions({Gravity{kDown}, Move{}, KillOld{}});
    std::vector<std::pair<Trails, Trails>> seen;
    for (int s = 0; s < 75; ++s) {
      if (s == 20) splash.setTrail({.length = 4});  // on live particles
      if (s == 45) sparks.setTrail({.length = 9});  // a new ring, begun where they are
      ctx.step();
      if (s % 6 == 5) seen.emplace_back(trailsOf(sparks), trailsOf(splash));
    }
    return seen;
  };
  const auto cpu = run(Backend::Cpu);
  const auto cl = run(Backend::OpenCL);
  ASSERT_EQ(cpu.size(), cl.size());
  std::size_t points = 0, longest = 0;
  for (std::size_t s = 0; s < cpu.size(); ++s) {
    for (int which = 0; which < 2; ++which) {
      const Trails& a = which ? cpu[s].second : cpu[s].first;
      const Trails& b = which ? cl[s].second : cl[s].first;
      ASSERT_EQ(a.size(), b.size()) << "sample " << s << ", group " << which;
      for (const auto& [id, ta] : a) {
        const auto it = b.find(id);
        ASSERT_NE(it, b.end()) << "particle " << id;
        ASSERT_EQ(ta.size(), it->second.size()) << "particle " << id << ", sample " << s;
        for (std::size_t k = 0; k < ta.size(); ++k)
          for (int c = 0; c < 3; ++c) expectClose(ta[k][c], it->second[k][c], "trail", id, c);
        points += ta.size();
        longest = std::max(longest, ta.size());
      }
    }
  }
  EXPECT_GT(points, 10000u);
  EXPECT_EQ(longest, 9u);  // the lengthened ring filled up
}
