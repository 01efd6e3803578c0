// Effects drawn at random (tests/effect/random_effect_draws.hpp: every action with every field
// anywhere in its documented range, random domains, integrators, step lengths; emission of
// every kind; instances placed anew before every step; hair mode and trails) stepped on the
// device beside the CPU backend: the device never fails where the CPU steps, keeps only
// finite particles inside its capacity and inside the box it reports, and gives the CPU's
// counts, statistics and ids, and its particles, strands and trails within the parity
// tolerance; where emission is drawn, its death and collision events too. (The first sweep found two defects: forces after the last Move dropped by the
// device under an integrating Move, and a MagneticField past ~1.8e19 that killed uncharged
// particles.)
//
// Each effect is a program of its own for PoCL to compile (a second or more), so the suite
// draws a few; FLURRY_RANDOM_EFFECTS="FIRST-LAST" sweeps more by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
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

struct Stepped {
  bool refused = false;
  std::string why;  // the Error that refused it
  std::vector<test::RunResult> groups;
  std::vector<Strands> strands;                                    // per group
  std::vector<std::map<std::uint32_t, std::vector<Vec3>>> trails;  // per group, by id
  std::vector<std::vector<DeathEvent>> deaths;                     // per group, all steps'
  std::vector<std::vector<CollisionEvent>> collisions;
};

/// Events are recorded (`events`) where the device's programs stay those the suite compiles
/// anyway: deaths everywhere (read from the kill codes every program writes), collisions
/// only on a group a collision emitter already records (a program that logs them is
/// another program for a group that does not).
void recordEvents(const Effect& fx, const std::vector<Group*>& groups) {
  for (Group* g : groups) {
    g->recordDeaths(100000);
    for (const auto& spec : fx.groups)
      for (const DeathEmitter& d : spec.deathEmitters)
        if (d.on == DeathEmitter::Trigger::Collision && g->name() == d.source)
          g->recordCollisions(100000);
  }
}

/// `moved`: as an instance placed anew before every step (test::randomPlacement); `events`:
/// recordEvents.
Stepped run(const Effect& fx, Backend backend, bool moved, int steps, bool events) {
  Stepped out;
  try {
    Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 2, .backend = backend});
    EffectInstance instance;
    std::vector<Group*> groups;
    if (moved) {
      instance = fx.instantiate(ctx, "x");
      groups = instance.groups();
    } else {
      groups = fx.build(ctx);
    }
    for (Group* g : groups) (void)g->bounds();  // kept by the passes from now on
    if (events) recordEvents(fx, groups);
    out.deaths.resize(groups.size());
    out.collisions.resize(groups.size());
    for (int s = 0; s < steps; ++s) {
      if (moved) instance.setTransform(test::randomPlacement(fx.seed, s));
      ctx.step();
      if (!test::stepLeftGroupsSound(groups, s)) return out;
      for (std::size_t k = 0; k < groups.size(); ++k) {
        const auto d = groups[k]->deaths();
        const auto c = groups[k]->collisions();
        out.deaths[k].insert(out.deaths[k].end(), d.begin(), d.end());
        out.collisions[k].insert(out.collisions[k].end(), c.begin(), c.end());
      }
    }
    for (const Group* g : groups) {
      out.groups.push_back(test::resultOf(*g));
      out.strands.push_back(g->strands());
      auto& trails = out.trails.emplace_back();
      std::vector<Vec3> points(g->trail().length);
      for (std::size_t i = 0; i < g->size() && !points.empty(); ++i)
        trails[g->particle(i).id].assign(points.begin(),
                                         points.begin() + std::ptrdiff_t(g->trail(i, points)));
    }
  } catch (const Error& e) {
    out.refused = true;
    out.why = e.what();
  }
  return out;
}

/// Draws effects with `draw` from the seeds (test::seeds(count)) and steps each the CPU steps
/// on the device too: checked every step (stepLeftGroupsSound), then compared (expectSame:
/// counts, statistics and ids exactly, every attribute within the parity tolerance).
void stepDraws(test::DrawEffect draw, std::uint32_t count, bool moved = false, int steps = 8,
               bool events = false) {
  FLURRY_REQUIRE_OPENCL();
  int stepped = 0;
  std::size_t vertices = 0, points = 0;  // strand vertices and trail points compared
  std::size_t deaths = 0, hits = 0;      // events compared
  test::forEachDrawnEffect({draw}, count, [&](std::uint32_t, test::DrawEffect, const Effect& fx) {
    const Stepped cpu = run(fx, Backend::Cpu, moved, steps, events);
    if (cpu.refused) return;
    const Stepped cl = run(fx, Backend::OpenCL, moved, steps, events);
    // (Hair mode with neighbours or sub-steps by distance is refused there, by design.)
    if (cl.refused && fx.groups.front().hair.enabled &&
        cl.why.find("hair mode with") != std::string::npos)
      return;
    ASSERT_FALSE(cl.refused) << "the device refused what the CPU steps: " << cl.why;
    ASSERT_FALSE(::testing::Test::HasFailure());  // (stepLeftGroupsSound said why)
    ++stepped;
    ASSERT_EQ(cpu.groups.size(), cl.groups.size());
    for (std::size_t k = 0; k < cpu.groups.size(); ++k) {
      SCOPED_TRACE("group " + std::to_string(k));
      test::expectSame(cpu.groups[k], cl.groups[k]);
      const Strands &a = cpu.strands[k], &b = cl.strands[k];
      ASSERT_EQ(a.start, b.start) << "the strands part";
      vertices += a.vertexCount();
      for (std::size_t v = 0; v < a.vertexCount(); ++v) {
        for (int c = 0; c < 3; ++c)
          test::expectClose(a.position[v][c], b.position[v][c], "strand vertex", std::uint32_t(v),
                            c);
        for (int c = 0; c < 4; ++c)
          test::expectClose(a.color[v][c], b.color[v][c], "strand colour", std::uint32_t(v), c);
        test::expectClose(a.radius[v], b.radius[v], "strand radius", std::uint32_t(v), 0);
      }
      for (const auto& [id, trail] : cpu.trails[k]) {
        const auto& other = cl.trails[k].at(id);  // (expectSame matched the ids)
        ASSERT_EQ(trail.size(), other.size()) << "the trail of particle " << id;
        points += trail.size();
        for (std::size_t j = 0; j < trail.size(); ++j)
          for (int c = 0; c < 3; ++c) test::expectClose(trail[j][c], other[j][c], "trail", id, c);
      }
      // The same events in the same order: ids, causes and times exactly, places and
      // velocities within the parity tolerance.
      ASSERT_EQ(cpu.deaths[k].size(), cl.deaths[k].size()) << "deaths recorded";
      deaths += cpu.deaths[k].size();
      for (std::size_t e = 0; e < cpu.deaths[k].size(); ++e) {
        const DeathEvent &p = cpu.deaths[k][e], &q = cl.deaths[k][e];
        ASSERT_EQ(p.id, q.id) << "death " << e;
        EXPECT_EQ(p.action, q.action) << "death " << e;
        EXPECT_EQ(p.time, q.time) << "death " << e;
        if (p.action == DeathEvent::kNonFinite) continue;
        for (int c = 0; c < 3; ++c) {
          test::expectClose(p.position[c], q.position[c], "death position", p.id, c);
          test::expectClose(p.velocity[c], q.velocity[c], "death velocity", p.id, c);
        }
      }
      ASSERT_EQ(cpu.collisions[k].size(), cl.collisions[k].size()) << "collisions recorded";
      hits += cpu.collisions[k].size();
      for (std::size_t e = 0; e < cpu.collisions[k].size(); ++e) {
        const CollisionEvent &p = cpu.collisions[k][e], &q = cl.collisions[k][e];
        ASSERT_EQ(p.id, q.id) << "collision " << e;
        EXPECT_EQ(p.action, q.action) << "collision " << e;
        EXPECT_NEAR(p.time, q.time, 1e-5 * fx.dt) << "collision " << e;
        for (int c = 0; c < 3; ++c) {
          test::expectClose(p.position[c], q.position[c], "collision position", p.id, c);
          test::expectClose(p.velocity[c], q.velocity[c], "collision velocity", p.id, c);
          test::expectClose(p.normal[c], q.normal[c], "collision normal", p.id, c);
        }
      }
    }
  });
  EXPECT_GT(stepped, 0);
  std::printf(
      "%d of %.0f drawn effects stepped on both backends, alike (%zu strand vertices, %zu "
      "trail points, %zu deaths, %zu collisions)\n",
      stepped, test::seedCount(count), vertices, points, deaths, hits);
}

}  // namespace

TEST(OpenCLRandomEffects, StepSafelyAndLikeTheCpu) {
  stepDraws(test::randomEffect, 12);
}

TEST(OpenCLRandomEffects, EmissionOfEveryKindStepsSafelyAndLikeTheCpu) {
  stepDraws(test::randomEmission, 8, false, 8, true);
}

TEST(OpenCLRandomEffects, InstancesMovedEveryStepStepSafelyAndLikeTheCpu) {
  stepDraws(test::randomPlacedEffect, 8, true);
}

TEST(OpenCLRandomEffects, HairAndTrailsLikeTheCpu) {
  stepDraws(test::randomLookEffect, 8, false, 24);
}

// A game's one-shot effects on the device: of two instances of each drawn effect, one killed
// and one stopped a few steps in, then stepped on until both are done (at most 40 steps):
// done() at the same steps, and the same particles and counts, as on the CPU.
TEST(OpenCLRandomEffects, KilledAndStoppedLikeTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  int compared = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission}, 8,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        struct Run {
          bool refused = false;
          std::vector<int> done;  // per step: 1 + 2 * b.done() when a.done()
          std::vector<test::RunResult> groups;
        };
        auto run = [&](Backend backend) {
          Run out;
          try {
            Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 2, .backend = backend});
            EffectInstance a = fx.instantiate(ctx, "a"), b = fx.instantiate(ctx, "b");
            ctx.run(1 + seed % 5);
            a.kill();
            b.stop();
            for (int s = 0; s < 40; ++s) {
              out.done.push_back(int(a.done()) + 2 * int(b.done()));
              if (a.done() && b.done()) break;
              ctx.step();
            }
            for (const EffectInstance* fxi : {&a, &b})
              for (const Group* g : fxi->groups()) out.groups.push_back(test::resultOf(*g));
          } catch (const Error&) {
            out.refused = true;
          }
          return out;
        };
        const Run cpu = run(Backend::Cpu);
        if (cpu.refused) return;
        const Run cl = run(Backend::OpenCL);
        ASSERT_FALSE(cl.refused);
        EXPECT_EQ(cpu.done, cl.done);
        ASSERT_EQ(cpu.groups.size(), cl.groups.size());
        for (std::size_t k = 0; k < cpu.groups.size(); ++k)
          test::expectSame(cpu.groups[k], cl.groups[k]);
        ++compared;
      });
  EXPECT_GT(compared, 0);
  std::printf("%d drawn effects killed and stopped alike on both backends\n", compared);
}
