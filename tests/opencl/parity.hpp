// Parity checks shared by the OpenCL test files: run one build on the CPU and on the
// device from the same seed and compare the particles by id.
//
// Tolerance. The device runs the CPU's float operations in the CPU's order, with
// contraction off and correctly rounded division and sqrt, and the emitters' sampling is
// libm-free on both sides (Box-Muller's log and cos too), so nearly everything agrees to
// the bit. Two things may not:
//  - forces and damping that call exp, pow, sin or cos, whose OpenCL builtins may differ
//    from glibc's by an ulp or two;
//  - an ulp of difference, carried through 200 steps of gravity and bounces, grows.
// So attributes are compared with |cpu - cl| <= kAbs + kRel * |cpu|, kAbs = kRel = 1e-4
// (positions are O(1..10) here: a few hundred float ulps), and the test reports the largest
// difference it saw; counts and ids must be equal exactly.
#pragma once

#include <cmath>
#include <cstdio>

#include "opencl_test.hpp"

namespace flurry::test {

constexpr float kAbs = 1e-4f, kRel = 1e-4f;
constexpr int kSteps = 200;

inline float maxDiff = 0;  // over all tests, for the summary line

inline void expectClose(float cpu, float cl, const char* what, std::uint32_t id, int c) {
  const float d = std::abs(cpu - cl);
  if (std::isfinite(d)) maxDiff = std::max(maxDiff, d);
  EXPECT_TRUE(d <= kAbs + kRel * std::abs(cpu) || (std::isnan(cpu) && std::isnan(cl)))
      << what << "[" << c << "] of particle " << id << ": cpu " << cpu << ", opencl " << cl;
}

inline void expectSame(const RunResult& cpu, const RunResult& cl) {
  ASSERT_EQ(cpu.size, cl.size);
  EXPECT_EQ(cpu.stats.emitted, cl.stats.emitted);
  EXPECT_EQ(cpu.stats.killedByAge, cl.stats.killedByAge);
  EXPECT_EQ(cpu.stats.absorbed, cl.stats.absorbed);
  EXPECT_EQ(cpu.stats.droppedAtCapacity, cl.stats.droppedAtCapacity);
  EXPECT_EQ(cpu.stats.killedByAction, cl.stats.killedByAction);
  EXPECT_EQ(cpu.stats.killedNonFinite, cl.stats.killedNonFinite);
  int bad = 0;
  for (const auto& [id, p] : cpu.byId) {
    auto it = cl.byId.find(id);
    ASSERT_NE(it, cl.byId.end()) << "particle " << id << " is missing on the device";
    const Particle& q = it->second;
    const int failuresBefore = ::testing::UnitTest::GetInstance()->failed_test_count();
    (void)failuresBefore;
    for (int c = 0; c < 3; ++c) {
      expectClose(p.position[c], q.position[c], "position", id, c);
      expectClose(p.velocity[c], q.velocity[c], "velocity", id, c);
      expectClose(p.prevPosition[c], q.prevPosition[c], "prevPosition", id, c);
      expectClose(p.up[c], q.up[c], "up", id, c);
      expectClose(p.rotVelocity[c], q.rotVelocity[c], "rotVelocity", id, c);
      expectClose(p.positionB[c], q.positionB[c], "positionB", id, c);
      expectClose(p.velocityB[c], q.velocityB[c], "velocityB", id, c);
    }
    for (int c = 0; c < 4; ++c) expectClose(p.color[c], q.color[c], "color", id, c);
    expectClose(p.size, q.size, "size", id, 0);
    expectClose(p.mass, q.mass, "mass", id, 0);
    expectClose(p.age, q.age, "age", id, 0);
    expectClose(p.lifetime, q.lifetime, "lifetime", id, 0);
    expectClose(p.charge, q.charge, "charge", id, 0);
    expectClose(p.userData, q.userData, "userData", id, 0);
    EXPECT_EQ(p.visible, q.visible);
    if (::testing::Test::HasFailure() && ++bad > 5) FAIL() << "stopping after 5 particles";
  }
}

inline void checkParity(const Build& build, int steps = kSteps, std::uint64_t seed = 7) {
  FLURRY_REQUIRE_OPENCL();
  const RunResult cpu = runEffect(Backend::Cpu, build, steps, seed);
  const RunResult cl = runEffect(Backend::OpenCL, build, steps, seed);
  EXPECT_GT(cpu.stats.emitted, 0u);
  expectSame(cpu, cl);
  ::testing::Test::RecordProperty("max_abs_difference", std::to_string(maxDiff));
}

// The list without actions[k], with the same integrator and sub-steps.
inline ActionList withoutAction(const ActionList& list, std::size_t k) {
  ActionList out;
  for (std::size_t j = 0; j < list.size(); ++j)
    if (j != k) out.add(list.actions()[j]);
  out.setIntegrator(list.integrator());
  out.setSubsteps(list.substeps());
  return out;
}

// Whether two runs differ in some particle by more than `scale` times the parity tolerance
// (0: any difference), or in their counts. Parity alone would also pass if an action did
// nothing on either backend: its tests check on the CPU that dropping it changes the run.
inline bool differs(const RunResult& x, const RunResult& y, float scale) {
  if (x.size != y.size || x.stats.absorbed != y.stats.absorbed) return true;
  auto far = [scale](float a, float b) {
    return !(std::abs(a - b) <= scale * (kAbs + kRel * std::abs(a)));
  };
  for (const auto& [id, p] : x.byId) {
    auto it = y.byId.find(id);
    if (it == y.byId.end()) return true;
    const Particle& q = it->second;
    if (p.visible != q.visible || far(p.size, q.size)) return true;
    for (int c = 0; c < 3; ++c)
      if (far(p.position[c], q.position[c]) || far(p.velocity[c], q.velocity[c]) ||
          far(p.rotVelocity[c], q.rotVelocity[c]))
        return true;
    for (int c = 0; c < 4; ++c)
      if (far(p.color[c], q.color[c])) return true;
  }
  return false;
}

// Parity of `build`, printing the largest |cpu - opencl| of this run alone.
inline void checkParityReporting(const Build& build) {
  const float before = maxDiff;
  maxDiff = 0;
  checkParity(build);
  std::printf("[ parity   ] largest |cpu - opencl|: %g\n", maxDiff);
  maxDiff = std::max(before, maxDiff);
}

// A jet of particles from a small sphere, sprayed into a box of obstacles.
inline Emitter spray(Vec3 at = Vec3(0.0f, 1.0f, 0.0f), double rate = 1500) {
  Emitter e;
  e.shape = Domain::sphere(Vec3(0.0f), 0.2f);
  e.position = at;
  e.rate = rate;
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 5.0f, 0.0f), 3.0f);
  t.lifetime = Fuzzy(2.0f, 0.5f);
  e.types = {t};
  return e;
}

inline Build withActions(ActionList actions, Emitter e = spray(), std::size_t capacity = 20000) {
  return [=](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("parity", capacity);
    g.addEmitter(e);
    g.setActions(actions);
    return g;
  };
}

inline const Vec3 kDown(0.0f, -9.81f, 0.0f);

}  // namespace flurry::test
