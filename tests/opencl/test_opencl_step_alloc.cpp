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
