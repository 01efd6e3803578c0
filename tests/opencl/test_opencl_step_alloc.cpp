// A steady OpenCL group's step allocates nothing on the host: no emitter signature, no
// repacked constants, no fresh emission tables or in-flight records (issue #11). Counts
// every operator new of this process while stepping; its own executable, as it replaces
// the global operator new.
#include <gtest/gtest.h>

#include "../allocation_counter.hpp"
#include "builtin.hpp"
#include "opencl_test.hpp"

using namespace flurry;

namespace {
// The built-in fountain (the program other OpenCL tests build, so a warm cache serves it):
// `capacity` 10000 steps in one launch (fl_small), 100000 in the full chain of kernels.
std::size_t allocationsPerSteadyStep(std::size_t capacity, double rate) {
  ContextOptions o;
  o.seed = 3;
  o.threads = 2;
  o.backend = Backend::OpenCL;
  Context ctx(o);
  Group& g = samples::buildFountain(ctx, capacity, rate, 2.0f);
  ctx.run(90);  // past the longest life: scratch and device buffers have grown
  EXPECT_GT(g.size(), std::size_t(rate));
  allocations = 0;
  counting = true;
  ctx.run(30);
  counting = false;
  return allocations;
}
}  // namespace

TEST(OpenCLStepAllocations, SteadyGroupAllocatesNothing) {
  FLURRY_REQUIRE_OPENCL();
  EXPECT_EQ(allocationsPerSteadyStep(10000, 2000), 0u);
  EXPECT_EQ(allocationsPerSteadyStep(100000, 20000), 0u);
}

// An instance moved every step: the move only changes the actions' constants, which go up
// without the program's text being generated again (issue #15).
TEST(OpenCLStepAllocations, AnInstanceMovedEveryStepAllocatesNothing) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.seed = 3;
  o.threads = 2;
  o.backend = Backend::OpenCL;
  Context ctx(o);
  Group& g = samples::buildFountain(ctx, 10000, 2000, 2.0f);
  std::size_t frame = 0;
  auto moveAndRun = [&](int steps) {
    for (int k = 0; k < steps; ++k, ++frame) {
      const float f = float(frame);
      g.setTransform(Transform{Vec3(0.01f * f, 0.0f, 0.02f * f),
                               glm::angleAxis(0.01f * f, Vec3(0.0f, 1.0f, 0.0f)), 1.0f});
      ctx.step();
    }
  };
  moveAndRun(90);
  allocations = 0;
  counting = true;
  moveAndRun(30);
  counting = false;
  EXPECT_GT(g.size(), 2000u);
  EXPECT_EQ(allocations, 0u);
}
