// Shared helpers of the OpenCL tests: device detection (a missing device skips, visibly)
// and running one effect on a backend.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>

#include "flurry/flurry.hpp"
#include "flurry/opencl.hpp"

namespace flurry::test {

/// Why OpenCL tests cannot run here, or empty when they can.
/// How many times openclUnavailable() ran in this process (the first loads the driver).
inline int& openclChecks() {
  static int n = 0;
  return n;
}

inline std::string openclUnavailable() {
  ++openclChecks();
  try {
    if (openclDevices().empty()) return "no OpenCL platform or device (install pocl-opencl-icd)";
  } catch (const std::exception& e) {
    return std::string("OpenCL devices cannot be listed: ") + e.what();
  }
  return {};
}

#define FLURRY_REQUIRE_OPENCL()                                       \
  do {                                                                \
    const std::string why = ::flurry::test::openclUnavailable();      \
    if (!why.empty()) GTEST_SKIP() << "OpenCL test skipped: " << why; \
  } while (0)

/// A finished run: particles by id, and the group's counts.
struct RunResult {
  std::size_t size = 0;
  GroupStats stats;
  std::map<std::uint32_t, Particle> byId;
  AttributeSet stored;
};

/// A group's particles by id, count, statistics and stored attributes.
inline RunResult resultOf(const Group& g) {
  RunResult r;
  r.size = g.size();
  r.stats = g.stats();
  r.stored = g.attributes();
  for (std::size_t i = 0; i < r.size; ++i) {
    const Particle p = g.particle(i);
    r.byId[p.id] = p;
  }
  return r;
}

using Build = std::function<Group&(Context&)>;
/// The options parity runs take: one seed and step on both backends, two threads.
inline ContextOptions parityOptions(Backend backend, std::uint64_t seed = 7,
                                    double dt = 1.0 / 30.0) {
  ContextOptions o;
  o.seed = seed;
  o.dt = dt;
  o.threads = 2;
  o.backend = backend;
  return o;
}

inline RunResult runEffect(Backend backend, const Build& build, int steps, std::uint64_t seed = 7,
                           double dt = 1.0 / 30.0) {
  Context ctx(parityOptions(backend, seed, dt));
  Group& g = build(ctx);
  ctx.run(std::size_t(steps));
  return resultOf(g);
}

}  // namespace flurry::test
