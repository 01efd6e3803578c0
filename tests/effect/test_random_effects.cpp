// Effects made at random: from the action descriptors, every field of every action drawn
// anywhere in its documented range (its ends, zero, huge and tiny values, infinity where the
// field takes it), with random domains, integrators and step lengths; and emission of every
// kind (bursts, paths, several types, births by distance, prime emitters three levels deep,
// sub-emitters on death, collision and birth); as instances moved every step; in hair mode or
// with trails. Each is stepped on one and two threads: whatever a valid file asks for, a step
// never crashes (the suite runs under AddressSanitizer and UndefinedBehaviorSanitizer), keeps
// no particle that is not finite, never holds more than its capacity, keeps a box that holds
// every particle, and gives the same particles (and strands and trails) bit for bit on any
// thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "pass_options.hpp"
#include "random_effect_draws.hpp"
#include "step_checks.hpp"

using namespace flurry;

namespace {

/// Runs `run(threads, refused)` on 1 thread and then on 2: both refuse the effect or neither,
/// and what they give is the same (words compared bit for bit). 1 where it stepped alike.
template <class Run>
int steppedAlike(Run&& run, const char* what) {
  bool refused1 = false, refused2 = false;
  const auto one = run(1u, refused1);
  if (::testing::Test::HasFailure()) return 0;
  const auto two = run(2u, refused2);
  EXPECT_EQ(refused1, refused2);
  EXPECT_TRUE(one == two) << what << " of 1 thread and 2 differ";
  return !refused1 && !::testing::Test::HasFailure();
}

/// The particles after `steps` steps on `threads` threads, checked every step; empty when a
/// step refused the effect with an Error.
std::vector<std::uint32_t> run(const Effect& fx, unsigned threads, int steps, bool& refused,
                               bool moved) {
  Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = threads, .backend = Backend::Cpu});
  detail::setPassOptions(ctx, {.blockSize = 256});  // a few hundred alive: several blocks
  refused = false;
  std::vector<Group*> groups;
  EffectInstance instance;
  try {
    if (moved) {
      instance = fx.instantiate(ctx, "x");
      groups = instance.groups();
    } else {
      groups = fx.build(ctx);
    }
  } catch (const Error&) {
    refused = true;
    return {};
  }
  for (Group* g : groups) (void)g->bounds();  // kept by the passes from now on
  for (int s = 0; s < steps; ++s) {
    try {
      if (moved) instance.setTransform(test::randomPlacement(fx.seed, s));
      ctx.step();
    } catch (const Error&) {
      refused = true;
      return {};
    }
    if (!test::stepLeftGroupsSound(groups, s)) return {};
    if (moved) {  // the instance's box holds every particle of its groups (an engine culls by it)
      const Bounds box = instance.bounds();
      std::size_t alive = 0;
      for (const Group* g : groups) {
        alive += g->size();
        const Bounds own = g->bounds();
        if (own.empty) continue;
        for (int c = 0; c < 3; ++c)
          if (box.empty || own.min[c] < box.min[c] || own.max[c] > box.max[c]) {
            ADD_FAILURE() << "step " << s << ": the instance's box misses " << g->name() << "'s";
            return {};
          }
      }
      EXPECT_EQ(box.empty, alive == 0) << "step " << s;
    }
  }
  return test::bitsOf(groups);
}

/// Draws effects with `draw` from the seeds (test::seeds(count)), and steps each that loads
/// on one and on two threads (run: checked every step; `moved`: as an instance placed anew
/// before each step), their particles compared bit for bit.
void stepDraws(test::DrawEffect draw, std::uint32_t count, bool moved = false) {
  int loaded = 0, stepped = 0;
  test::forEachDrawnEffect({draw}, count, [&](std::uint32_t, test::DrawEffect, const Effect& fx) {
    ++loaded;
    bool refused1 = false, refused2 = false;
    const auto one = run(fx, 1, 25, refused1, moved);
    const auto two = run(fx, 2, 25, refused2, moved);
    ASSERT_EQ(refused1, refused2);
    if (refused1) return;
    ++stepped;
    ASSERT_TRUE(one == two) << "1 thread and 2 differ";
  });
  // Most draws must load and step, or the test would check little.
  const double drawn = test::seedCount(count);
  EXPECT_GT(loaded, 0.5 * drawn);
  EXPECT_GT(stepped, 0.4 * drawn);
  std::printf("%d of %.0f drawn effects loaded, %d stepped\n", loaded, drawn, stepped);
}

}  // namespace

TEST(RandomEffects, StepSafelyAndAlikeOnAnyThreadCount) {
  stepDraws(test::randomEffect, 400);
}

TEST(RandomEffects, EmissionOfEveryKindStepsSafelyAndAlike) {
  stepDraws(test::randomEmission, 300);
}

TEST(RandomEffects, InstancesMovedEveryStepStepSafelyAndAlike) {
  stepDraws(test::randomPlacedEffect, 200, true);
}

TEST(RandomEffects, HairAndTrailsStepSafelyAndAlike) {
  stepDraws(test::randomLookEffect, 100);
}

// saveEffect writes what parseEffect reads back to the same effect, for every kind drawn:
// the text once more the same, and the same particles (and strands and trails) bit for bit.
TEST(RandomEffects, SaveAndLoadGiveTheSameEffect) {
  int saved = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission, test::randomPlacedEffect, test::randomLookEffect},
      100, [&](std::uint32_t, test::DrawEffect draw, const Effect& fx) {
        const std::string once = saveEffect(fx);
        Effect back;
        try {
          back = parseEffect(once, "saved.json");
        } catch (const EffectError& e) {
          FAIL() << "the saved effect does not load: " << e.what() << "\n" << once;
        }
        ASSERT_EQ(saveEffect(back), once);
        bool refusedA = false, refusedB = false;
        const bool moved = draw == test::randomPlacedEffect;
        ASSERT_TRUE(run(fx, 1, 10, refusedA, moved) == run(back, 1, 10, refusedB, moved))
            << "the saved effect steps otherwise\n"
            << once;
        ASSERT_EQ(refusedA, refusedB);
        ++saved;
      });
  EXPECT_GT(saved, 2.0 * test::seedCount(100));
  std::printf("%d drawn effects saved, loaded back and stepped alike\n", saved);
}

// Context::prewarm's promise, for every kind drawn: an instance prewarmed by n steps' time
// holds the particles of one stepped n times by hand, bit for bit, and goes on alike.
TEST(RandomEffects, PrewarmIsSteppingByHand) {
  int compared = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission}, 100,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        const int n = 1 + int(seed % 12);
        try {
          Context byHand({.seed = fx.seed, .dt = fx.dt, .threads = 1}),
              warm({.seed = fx.seed, .dt = fx.dt, .threads = 1});
          EffectInstance a = fx.instantiate(byHand, "a"), b = fx.instantiate(warm, "a");
          byHand.run(std::size_t(n));
          ASSERT_EQ(b.prewarm(double(n) * fx.dt), std::uint64_t(n));
          ASSERT_TRUE(test::bitsOf(a.groups()) == test::bitsOf(b.groups())) << "after the prewarm";
          byHand.run(5);
          warm.run(5);
          ASSERT_TRUE(test::bitsOf(a.groups()) == test::bitsOf(b.groups())) << "five steps later";
          ++compared;
        } catch (const Error&) {
          // a step refused it (the other tests check that it is refused alike)
        }
      });
  EXPECT_GT(compared, test::seedCount(100));
  std::printf("%d drawn effects prewarmed as stepped by hand\n", compared);
}

// A game's budget over random effects (actions, emission, hair and trails): three instances
// of each drawn effect share a context budget (50-549 particles), each group under a policy
// drawn at random. After every step the groups together hold at most the budget, every group
// accounts for each particle it emitted (GroupStats: emitted == size + killedByAge + absorbed
// + droppedAtCapacity + droppedAtBudget + killedByBudget + killedNonFinite), and the
// particles are bitwise the same on 1 and 2 threads.
TEST(RandomEffects, UnderABudgetEveryParticleIsAccountedFor) {
  int stepped = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission, test::randomLookEffect}, 60,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        test::Draw d(seed * 7919u + 3u);
        const std::size_t budget = 50 + std::size_t(d.below(500));
        std::vector<BudgetPolicy> policies;
        for (int k = 0; k < 3 * int(fx.groups.size()); ++k)
          policies.push_back(BudgetPolicy(d.below(3)));
        auto run = [&](unsigned threads, bool& refused) -> std::vector<std::uint32_t> {
          refused = false;
          try {
            Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = threads});
            ctx.setParticleBudget(budget);
            std::vector<Group*> groups;
            for (int k = 0; k < 3; ++k) {
              const EffectInstance instance = fx.instantiate(ctx, std::to_string(k));
              for (Group* g : instance.groups()) {
                g->setBudgetPolicy(policies[groups.size()]);
                groups.push_back(g);
              }
            }
            for (int s = 0; s < 15; ++s) {
              ctx.step();
              std::size_t alive = 0;
              for (const Group* g : groups) {
                alive += g->size();
                const GroupStats& st = g->stats();
                EXPECT_EQ(st.emitted, g->size() + st.killedByAge + st.absorbed +
                                          st.droppedAtCapacity + st.droppedAtBudget +
                                          st.killedByBudget + st.killedNonFinite)
                    << g->name() << ", step " << s;
              }
              EXPECT_LE(alive, budget) << "step " << s;
              if (::testing::Test::HasFailure()) return {};
            }
            return test::bitsOf(groups);
          } catch (const Error&) {
            refused = true;
          }
          return {};
        };
        stepped += steppedAlike(run, "the particles");
      });
  EXPECT_GT(stepped, test::seedCount(60));
  std::printf("%d drawn effects stepped under a budget\n", stepped);
}

// What a game relies on to retire one-shot effects, for random effects of every kind: an
// instance killed has nothing alive and nothing born after (showers and sub-emitters
// included); one stopped lives out its particles, and once done() it stays empty and never
// emits again.
TEST(RandomEffects, KilledAndStoppedInstancesStayDone) {
  int killed = 0, finished = 0;
  auto emitted = [](const EffectInstance& fxi) {
    std::uint64_t n = 0;
    for (const Group* g : fxi.groups()) n += g->stats().emitted;
    return n;
  };
  auto alive = [](const EffectInstance& fxi) {
    std::size_t n = 0;
    for (const Group* g : fxi.groups()) n += g->size();
    return n;
  };
  test::forEachDrawnEffect({test::randomEffect, test::randomEmission, test::randomLookEffect}, 60,
                           [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
                             try {
                               Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 1});
                               EffectInstance a = fx.instantiate(ctx, "a"),
                                              b = fx.instantiate(ctx, "b");
                               ctx.run(1 + seed % 10);
                               a.kill();
                               EXPECT_EQ(alive(a), 0u);
                               const std::uint64_t was = emitted(a);
                               ctx.run(3);
                               EXPECT_EQ(alive(a), 0u) << "after kill()";
                               EXPECT_EQ(emitted(a), was) << "born after kill()";
                               EXPECT_TRUE(a.done());
                               ++killed;
                               b.stop();
                               for (int s = 0; s < 300 && !b.done(); ++s) ctx.step();
                               if (!b.done()) return;  // (long lives)
                               const std::uint64_t at = emitted(b);
                               ctx.run(20);
                               EXPECT_EQ(alive(b), 0u) << "alive again after done()";
                               EXPECT_EQ(emitted(b), at) << "born after done()";
                               EXPECT_TRUE(b.done());
                               ++finished;
                             } catch (const Error&) {
                               // a step refused it (the other tests check that it is refused alike)
                             }
                           });
  EXPECT_GT(killed, test::seedCount(60));
  EXPECT_GT(finished, 0.5 * test::seedCount(60));
  std::printf("%d drawn effects killed, %d stopped and done, and stayed so\n", killed, finished);
}

// Instances come and go in a game: destroying one (and making a new one in its place) leaves
// the others' particles bitwise as they would have been, for random effects of every kind,
// on 1 and 2 threads.
TEST(RandomEffects, DestroyingAnInstanceLeavesTheOthersAsTheyWere) {
  int compared = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission, test::randomLookEffect}, 50,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        const unsigned threads = 1 + seed % 2;
        const std::size_t before = 1 + seed % 7, after = 6;
        try {
          Context kept({.seed = fx.seed, .dt = fx.dt, .threads = threads}),
              gone({.seed = fx.seed, .dt = fx.dt, .threads = threads});
          EffectInstance a = fx.instantiate(kept, "a"), b = fx.instantiate(kept, "b"),
                         c = fx.instantiate(kept, "c");
          EffectInstance a2 = fx.instantiate(gone, "a"), b2 = fx.instantiate(gone, "b"),
                         c2 = fx.instantiate(gone, "c");
          kept.run(before);
          gone.run(before);
          b2.destroy();
          EffectInstance d2 = fx.instantiate(gone, "d");  // b's place, and its random streams
          kept.run(after);
          gone.run(after);
          ASSERT_TRUE(test::bitsOf(a.groups()) == test::bitsOf(a2.groups()))
              << "the first instance changed";
          ASSERT_TRUE(test::bitsOf(c.groups()) == test::bitsOf(c2.groups()))
              << "the last instance changed";
          ++compared;
        } catch (const Error&) {
          // a step refused it (the other tests check that it is refused alike)
        }
      });
  EXPECT_GT(compared, test::seedCount(50));
  std::printf("%d drawn effects: the others untouched by a destroyed instance\n", compared);
}

// A game edits its effects between steps: each step, now and then, one edit drawn at random
// (another action list, an emitter removed, added or edited through its span, a time scale,
// an update interval, a seed, a transform, a space, a clear, events recorded, a trail, more
// attributes stored, a particle added, another step length, a prewarm). Whatever the edits, every
// step is sound (stepLeftGroupsSound) and the particles, strands and trails are bitwise the same on
// 1 and 2 threads. An edit a group refuses throws InvalidArgument, which is fine.
TEST(RandomEffects, EditsBetweenStepsStaySafeAndAlike) {
  int stepped = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission, test::randomLookEffect}, 60,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        Effect other, source;
        // What the edits put in: another draw's action list (none that reads every pair of
        // particles: put on a group that holds thousands, it would take minutes) and emitter.
        for (std::uint32_t k = 1; k < 50 && other.groups.empty(); ++k) try {
            other = parseEffect(test::randomEffect(seed + 7919u * k), "other.json");
            if (other.groups[0].actions.readsNeighbours()) other = {};
          } catch (const EffectError&) {
          }
        for (std::uint32_t k = 1; k < 50 && source.groups.empty(); ++k) try {
            source = parseEffect(test::randomEmission(seed + 104729u * k), "source.json");
          } catch (const EffectError&) {
          }
        ASSERT_FALSE(other.groups.empty() || source.groups.empty());
        // (At most ~2,000 alive, as the draws keep: some actions read every pair.)
        Emitter added = source.groups[0].emitters.at(0);
        added.rate = std::min(added.rate, 100.0);
        for (ParticleType& t : added.types) t.lifetime = Fuzzy(0.3f);
        auto run = [&](unsigned threads, bool& refused) -> std::vector<std::uint32_t> {
          refused = false;
          try {
            Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = threads});
            EffectInstance instance = fx.instantiate(ctx, "x");
            const std::vector<Group*>& groups = instance.groups();
            test::Draw d(seed * 31u + 11u);
            for (int s = 0; s < 20; ++s) {
              Group& g = *groups[std::size_t(d.below(int(groups.size())))];
              try {
                switch (d.below(26)) {  // an edit about every other step
                  case 0:
                    g.setActions(other.groups[0].actions);
                    break;
                  case 1:
                    if (!g.emitters().empty()) g.removeEmitter(0);
                    break;
                  case 2:
                    g.addEmitter(added);
                    break;
                  case 3:
                    if (!g.emitters().empty()) g.emitters()[0].rate *= 2.0f;
                    break;
                  case 4: {
                    const double scales[] = {0.0, 0.5, 2.0, 1.0};
                    instance.setTimeScale(scales[d.below(4)]);
                    break;
                  }
                  case 5:
                    instance.setUpdateInterval(std::uint32_t(1 + d.below(4)));
                    break;
                  case 6:
                    instance.setSeed(std::uint64_t(d.below(1000)));
                    break;
                  case 7:
                    instance.setTransform(test::randomPlacement(seed, s));
                    break;
                  case 8:
                    g.setSpace(d.below(2) ? Space::Local : Space::World);
                    break;
                  case 9:
                    g.clear();
                    break;
                  case 10:
                    g.recordDeaths(std::size_t(d.below(16)));
                    g.recordCollisions(std::size_t(d.below(16)));
                    break;
                  case 11:
                    g.setTrail({std::uint32_t(d.below(6))});
                    break;
                  case 12:
                    g.require({Attribute::Color, Attribute::Size, Attribute::Age});
                    break;
                  case 13: {
                    Particle p;
                    p.position = Vec3(float(d.between(-5, 5)), float(d.between(-5, 5)), 0.0f);
                    p.velocity = Vec3(0.0f, float(d.between(-5, 5)), 0.0f);
                    g.add(p);
                    break;
                  }
                  case 14: {
                    const double dts[] = {0.1, 1.0 / 60.0, 0.7, fx.dt};
                    ctx.setTimeStep(dts[d.below(4)]);
                    break;
                  }
                  case 15:
                    instance.prewarm(d.between(0.0, 0.5));
                    break;
                  default:
                    break;
                }
              } catch (const InvalidArgument&) {
              }
              ctx.step();
              if (!test::stepLeftGroupsSound(groups, s)) return {};
            }
            return test::bitsOf(groups);
          } catch (const Error&) {
            refused = true;
          }
          return {};
        };
        stepped += steppedAlike(run, "the particles");
      });
  EXPECT_GT(stepped, test::seedCount(60));
  std::printf("%d drawn effects edited between steps, alike on 1 and 2 threads\n", stepped);
}

namespace {

/// The stats a step's events are checked against, per group: what died by an action (or for a
/// NaN), per action, and what the events left out.
struct DeathCounts {
  std::uint64_t died = 0, deathsDropped = 0, collisionsDropped = 0;
  std::vector<std::uint64_t> byAction;
};
DeathCounts deathCounts(const Group& g) {
  const GroupStats& s = g.stats();
  return {s.killedByAge + s.absorbed + s.killedNonFinite, s.deathEventsDropped,
          s.collisionEventsDropped, s.killedByAction};
}

/// Checks one step's events of `g` (recording at most `room` of each a step) against what the
/// step did: `before` the counts and `alive` the ids at its start (sorted), [t0, t1] its span.
/// Returns the events as words (for the comparison across thread counts), and adds a failure naming
/// the step and the event where one is wrong.
std::vector<std::uint32_t> checkEvents(const Group& g, std::size_t room, const DeathCounts& before,
                                       const std::vector<std::uint32_t>& alive, double t0,
                                       double t1, int step) {
  std::vector<std::uint32_t> bits;
  auto put = [&](Vec3 v) {
    for (int c = 0; c < 3; ++c) bits.push_back(std::bit_cast<std::uint32_t>(v[c]));
  };
  auto putTime = [&](double t) {
    const auto w = std::bit_cast<std::uint64_t>(t);
    bits.push_back(std::uint32_t(w));
    bits.push_back(std::uint32_t(w >> 32));
  };
  auto finite = [](Vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  const DeathCounts after = deathCounts(g);
  const auto& acts = g.actions().actions();
  const std::string where = g.name() + ", step " + std::to_string(step);
  std::vector<std::uint32_t> now(g.ids().begin(), g.ids().end());
  std::sort(now.begin(), now.end());

  // Deaths: each one the step made, up to the room; the rest counted as dropped.
  const auto deaths = g.deaths();
  EXPECT_LE(deaths.size(), room) << where;
  EXPECT_EQ(deaths.size() + (after.deathsDropped - before.deathsDropped), after.died - before.died)
      << where << ": deaths recorded and dropped against those counted";
  std::vector<std::uint64_t> byAction(acts.size(), 0);
  std::vector<std::uint32_t> dead;
  for (std::size_t e = 0; e < deaths.size(); ++e) {
    const DeathEvent& d = deaths[e];
    const std::string what = where + ", death " + std::to_string(e);
    EXPECT_EQ(d.time, t1) << what << ": not at the step's end";
    EXPECT_FALSE(std::binary_search(now.begin(), now.end(), d.id)) << what << ": still alive";
    dead.push_back(d.id);
    if (d.action == DeathEvent::kNonFinite) continue;
    EXPECT_TRUE(finite(d.position) && finite(d.velocity)) << what;
    if (d.action >= acts.size()) {
      ADD_FAILURE() << what << ": action " << d.action << " past the list";
      continue;
    }
    ++byAction[d.action];
    bits.push_back(d.id);
    bits.push_back(d.action);
    put(d.position);
    put(d.velocity);
    putTime(d.time);
  }
  std::sort(dead.begin(), dead.end());
  EXPECT_TRUE(std::adjacent_find(dead.begin(), dead.end()) == dead.end())
      << where << ": a particle died twice";
  const bool allDeaths = after.deathsDropped == before.deathsDropped;
  for (std::size_t k = 0; k < acts.size(); ++k) {
    const std::uint64_t killed =
        after.byAction[k] - (k < before.byAction.size() ? before.byAction[k] : 0);
    if (allDeaths)
      EXPECT_EQ(byAction[k], killed) << where << ": deaths by action " << k;
    else
      EXPECT_LE(byAction[k], killed) << where << ": deaths by action " << k;
  }

  // Collisions: by a Bounce, on a particle alive at the step's start or born in it, within
  // the step, with a unit normal.
  const auto hits = g.collisions();
  EXPECT_LE(hits.size(), room) << where;
  for (std::size_t e = 0; e < hits.size(); ++e) {
    const CollisionEvent& c = hits[e];
    const std::string what = where + ", collision " + std::to_string(e);
    EXPECT_TRUE(c.action < acts.size() && std::holds_alternative<Bounce>(acts[c.action]))
        << what << ": action " << c.action << " is not a Bounce";
    EXPECT_TRUE(finite(c.position) && finite(c.velocity) && finite(c.normal)) << what;
    EXPECT_NEAR(glm::length(c.normal), 1.0f, 1e-3f) << what << ": normal not of unit length";
    // (The moment inside a step is a float fraction of the float step length: within a few
    // of its roundings.)
    const double slack = 1e-6 * (t1 - t0) + 1e-12 * std::abs(t1);
    // A newborn of an emitter that started before the step (a negative start) lived the
    // time since its birth in this step: its collisions may be earlier.
    const bool old = std::binary_search(alive.begin(), alive.end(), c.id);
    EXPECT_TRUE((c.time >= t0 - slack || !old) && c.time <= t1 + slack)
        << what << ": at " << c.time << ", outside the step [" << t0 << ", " << t1 << "]";
    EXPECT_EQ(c.reserved, 0u) << what;
    bits.push_back(c.id);
    bits.push_back(c.action);
    put(c.position);
    put(c.velocity);
    put(c.normal);
    putTime(c.time);
  }
  return bits;
}

}  // namespace

// Deaths and collisions recorded as events, from effects drawn at random, with room for one,
// a few or all of a step's: every step's deaths are those the stats count (recorded, or counted
// as dropped where the room ran out), each by the action that killed it, at the step's end,
// of a particle no longer alive, none twice; every collision by a Bounce, inside the step, on a
// unit normal; and the events of 1 and 2 threads are bitwise the same.
TEST(RandomEffects, EventsAreThoseOfTheStepAndAlike) {
  int stepped = 0;
  std::uint64_t deathsSeen = 0, hitsSeen = 0;
  test::forEachDrawnEffect(
      {test::randomEffect, test::randomEmission}, 100,
      [&](std::uint32_t seed, test::DrawEffect, const Effect& fx) {
        const std::size_t rooms[] = {1, 3, 40, 100000};
        const std::size_t room = rooms[seed % 4];
        auto run = [&](unsigned threads, bool& refused) -> std::vector<std::uint32_t> {
          refused = false;
          std::vector<std::uint32_t> bits;
          try {
            Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = threads});
            detail::setPassOptions(ctx, {.blockSize = 256});
            const std::vector<Group*> groups = fx.build(ctx);
            for (Group* g : groups) g->recordDeaths(room).recordCollisions(room);
            for (int s = 0; s < 25; ++s) {
              std::vector<DeathCounts> before;
              std::vector<std::vector<std::uint32_t>> alive;
              for (const Group* g : groups) {
                before.push_back(deathCounts(*g));
                alive.emplace_back(g->ids().begin(), g->ids().end());
                std::sort(alive.back().begin(), alive.back().end());
              }
              const double t0 = ctx.time();
              ctx.step();
              for (std::size_t k = 0; k < groups.size(); ++k) {
                const auto b =
                    checkEvents(*groups[k], room, before[k], alive[k], t0, ctx.time(), s);
                if (::testing::Test::HasFailure()) return {};
                if (threads == 1) {
                  deathsSeen += groups[k]->deaths().size();
                  hitsSeen += groups[k]->collisions().size();
                }
                bits.insert(bits.end(), b.begin(), b.end());
              }
            }
          } catch (const Error&) {
            refused = true;
            return {};
          }
          return bits;
        };
        stepped += steppedAlike(run, "the events");
      });
  EXPECT_GT(stepped, test::seedCount(100));
  std::printf(
      "%d drawn effects: %llu deaths and %llu collisions recorded, alike on 1 and 2 "
      "threads\n",
      stepped, (unsigned long long)deathsSeen, (unsigned long long)hitsSeen);
}

// A sub-emitter with a whole count gives exactly that many newborns for each death, collision
// or birth of its source, every step (the newborns it could not place counted as dropped):
// emission drawn at random, the second group fed by the first, its count made 1, 2 or 3.
TEST(RandomEffects, SubEmittersSpawnTheExactCount) {
  int checked = 0;
  std::uint64_t spawned = 0;
  test::forEachDrawnEffect(
      {test::randomEmission}, 150, [&](std::uint32_t seed, test::DrawEffect, const Effect& drawn) {
        Effect fx = drawn;
        ASSERT_EQ(fx.groups.size(), 2u);
        DeathEmitter& sub = fx.groups[1].deathEmitters.at(0);
        const std::uint64_t k = 1 + seed % 3;
        sub.count = Fuzzy(float(k));
        try {
          Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 1 + seed % 2});
          const std::vector<Group*> groups = fx.build(ctx);
          Group &a = *groups[0], &b = *groups[1];
          a.recordDeaths(a.capacity()).recordCollisions(1u << 30);
          for (int s = 0; s < 25; ++s) {
            const GroupStats before = a.stats();
            const std::uint64_t made = b.stats().emitted;
            ctx.step();
            const GroupStats& after = a.stats();
            std::uint64_t events = 0;
            switch (sub.on) {
              case DeathEmitter::Trigger::Death:
                events = a.deaths().size();
                break;
              case DeathEmitter::Trigger::Collision:
                events = a.collisions().size();
                break;
              case DeathEmitter::Trigger::Birth:
                events = (after.emitted - after.droppedAtCapacity - after.droppedAtBudget) -
                         (before.emitted - before.droppedAtCapacity - before.droppedAtBudget);
                break;
            }
            ASSERT_EQ(after.deathEventsDropped + after.collisionEventsDropped, 0u);
            ASSERT_EQ(b.stats().emitted - made, k * events) << "step " << s << ", " << k << " each";
            spawned += k * events;
          }
        } catch (const Error&) {
          return;  // (a draw a step refuses: the other tests check those)
        }
        ++checked;
      });
  EXPECT_GT(checked, test::seedCount(150) / 2);
  std::printf("%d drawn effects: %llu newborns of sub-emitters, each as many as asked\n", checked,
              (unsigned long long)spawned);
}
