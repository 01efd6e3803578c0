// A steady small group's step allocates nothing: no plan rebuilt, no job wrapped, no scratch
// grown (issue #11). Counts every operator new of this process while stepping.
#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
// A fountain's nozzle: about 1000 live particles at 500/s for 2 s.
Emitter fountainEmitter() {
  Emitter e;
  e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.1f);
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 8.0f, 0.0f), 1.5f);
  t.lifetime = Fuzzy::percent(2.0f, 10.0f);
  e.types = {t};
  e.rate = 500.0;
  return e;
}

// About 1000 live fountain particles (rate 500/s, lifetime 2 s), with the curved
// integrators' guard too.
std::size_t allocationsPerSteadyStep(unsigned threads, Integrator integrator) {
  ContextOptions o;
  o.threads = threads;
  Context ctx(o);
  Group& g = ctx.createGroup("small", 1500);
  Emitter e = fountainEmitter();
  g.addEmitter(e);
  ActionList list{Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                  Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f},
                  Move{}, KillOld{}};
  list.setIntegrator(integrator);
  g.setActions(list);
  ctx.run(150);  // past the longest life: the scratch has grown to the steady state's needs
  allocations = 0;
  counting = true;
  ctx.run(60);
  counting = false;
  EXPECT_GT(g.size(), 800u);
  return allocations;
}
}  // namespace

TEST(StepAllocations, SteadySmallGroupAllocatesNothing) {
  for (unsigned threads : {1u, 2u}) {
    EXPECT_EQ(allocationsPerSteadyStep(threads, Integrator::SemiImplicitEuler), 0u) << threads;
    EXPECT_EQ(allocationsPerSteadyStep(threads, Integrator::RK4), 0u) << threads;
  }
}

namespace {
// The fountain above as an effect instance a game moves every frame: setTransform before
// each step, and the emitters read through the non-const span (which may edit them) and the
// const accessors (issue #15).
std::size_t allocationsPerMovingStep(Space space, Integrator integrator, bool edit = true) {
  Context ctx;
  Group& g = ctx.createGroup("moving", 1500);
  Emitter e = fountainEmitter();
  e.path = {{0.0, Vec3(0.0f)}, {10.0, Vec3(1.0f, 0.0f, 0.0f)}};
  g.addEmitter(e);
  ActionList list{Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                  Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f},
                  Sink{Domain::sphere(Vec3(0.0f, 4.0f, 0.0f), 0.5f)}, Move{}, KillOld{}};
  list.setIntegrator(integrator);  // an integrating Move plans its forces and guards
  g.setActions(list);
  g.setSpace(space);
  std::size_t frame = 0;
  auto moveAndStep = [&] {
    Transform at;
    at.position = Vec3(0.01f * float(frame), 0.0f, 0.02f * float(frame));
    at.rotation = glm::angleAxis(0.01f * float(frame), Vec3(0.0f, 1.0f, 0.0f));
    at.scale = 1.0f + 0.001f * float(frame);
    ++frame;
    g.setTransform(at);
    if (edit) g.emitters()[0].rate = 500.0;  // an edit through the span, as a game's may
    EXPECT_EQ(g.actions().size(), 5u);
    EXPECT_EQ(g.transform().position, at.position);
    ctx.step();
  };
  for (int k = 0; k < 150; ++k) moveAndStep();
  allocations = 0;
  counting = true;
  for (int k = 0; k < 60; ++k) moveAndStep();
  counting = false;
  EXPECT_GT(g.size(), 800u);
  return allocations;
}
}  // namespace

TEST(StepAllocations, AnInstanceMovedEveryStepAllocatesNothing) {
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::Exact}) {
    EXPECT_EQ(allocationsPerMovingStep(Space::World, integrator), 0u);
    EXPECT_EQ(allocationsPerMovingStep(Space::Local, integrator), 0u);
    // Lists that stand still are placed by the step (Frame::placed), on its threads.
    EXPECT_EQ(allocationsPerMovingStep(Space::World, integrator, false), 0u);
    EXPECT_EQ(allocationsPerMovingStep(Space::Local, integrator, false), 0u);
  }
}
