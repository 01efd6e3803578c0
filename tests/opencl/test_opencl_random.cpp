// Effects drawn at random (tests/effect/random_effect_draws.hpp: every action with every field
// anywhere in its documented range, random domains, integrators, step lengths; emission of
// every kind) stepped on the device beside the CPU backend: the device never fails where the
// CPU steps, keeps only finite particles inside its capacity and inside the box it reports,
// and gives the CPU's counts, statistics and ids, and its particles within the parity
// tolerance. (The first sweep found two defects: forces after the last Move dropped by the
// device under an integrating Move, and a MagneticField past ~1.8e19 that killed uncharged
// particles.)
//
// Each effect is a program of its own for PoCL to compile (a second or more), so the suite
// draws a few; FLURRY_RANDOM_EFFECTS="FIRST-LAST" sweeps more by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "opencl_test.hpp"
#include "parity.hpp"
#include "random_effect_draws.hpp"
#include "step_checks.hpp"

using namespace flurry;

namespace {

constexpr int kRandomSteps = 8;

struct Stepped {
  bool refused = false;
  std::string why;  // the Error that refused it
  std::vector<test::RunResult> groups;
};

Stepped run(const Effect& fx, Backend backend) {
  Stepped out;
  try {
    Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 2, .backend = backend});
    const std::vector<Group*> groups = fx.build(ctx);
    for (Group* g : groups) (void)g->bounds();  // kept by the passes from now on
    for (int s = 0; s < kRandomSteps; ++s) {
      ctx.step();
      if (!test::stepLeftGroupsSound(groups, s)) return out;
    }
    for (const Group* g : groups) out.groups.push_back(test::resultOf(*g));
  } catch (const Error& e) {
    out.refused = true;
    out.why = e.what();
  }
  return out;
}

/// Draws effects with `make` from the seeds (test::seeds(count)) and steps each the CPU steps
/// on the device too: checked every step (stepLeftGroupsSound), then compared (expectSame:
/// counts, statistics and ids exactly, every attribute within the parity tolerance).
void stepDraws(std::string (*make)(std::uint32_t), std::uint32_t count) {
  FLURRY_REQUIRE_OPENCL();
  int stepped = 0;
  const auto [first, last] = test::seeds(count);
  for (std::uint32_t seed = first; seed <= last; ++seed) {
    const std::string text = make(seed);
    SCOPED_TRACE("seed " + std::to_string(seed) + ":\n" + text);
    Effect fx;
    try {
      fx = parseEffect(text, "random.json");
    } catch (const EffectError&) {
      continue;  // (the CPU tests count these)
    }
    const Stepped cpu = run(fx, Backend::Cpu);
    if (cpu.refused) continue;
    const Stepped cl = run(fx, Backend::OpenCL);
    ASSERT_FALSE(cl.refused) << "the device refused what the CPU steps: " << cl.why;
    if (::testing::Test::HasFailure()) return;  // (stepLeftGroupsSound said why)
    ++stepped;
    ASSERT_EQ(cpu.groups.size(), cl.groups.size());
    for (std::size_t k = 0; k < cpu.groups.size(); ++k) {
      SCOPED_TRACE("group " + std::to_string(k));
      test::expectSame(cpu.groups[k], cl.groups[k]);
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(stepped, 0);
  std::printf("%d of %u drawn effects stepped on both backends, alike\n", stepped,
              last - first + 1);
}

}  // namespace

TEST(OpenCLRandomEffects, StepSafelyAndLikeTheCpu) {
  stepDraws(test::randomEffect, 12);
}

TEST(OpenCLRandomEffects, EmissionOfEveryKindStepsSafelyAndLikeTheCpu) {
  stepDraws(test::randomEmission, 8);
}
