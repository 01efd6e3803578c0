// A steady small group's step allocates nothing: no plan rebuilt, no job wrapped, no scratch
// grown (issue #11). Counts every operator new of this process while stepping.
#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
// About 1000 live fountain particles (rate 500/s, lifetime 2 s), with the curved
// integrators' guard too.
std::size_t allocationsPerSteadyStep(unsigned threads, Integrator integrator) {
  ContextOptions o;
  o.threads = threads;
  Context ctx(o);
  Group& g = ctx.createGroup("small", 1500);
  Emitter e;
  e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.1f);
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 8.0f, 0.0f), 1.5f);
  t.lifetime = Fuzzy::percent(2.0f, 10.0f);
  e.types = {t};
  e.rate = 500.0;
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
