#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "emission_plan.hpp"
#include "flurry/flurry.hpp"
#include "pass_options.hpp"

using namespace flurry;

namespace {
std::uint64_t emittedAfter(double rate, double seconds, double dt) {
  ContextOptions o;
  o.dt = dt;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1 << 20);
  Emitter e;
  e.rate = rate;
  g.addEmitter(e);
  ctx.run(std::size_t(std::llround(seconds / dt)));
  EXPECT_EQ(g.size(), g.stats().emitted);
  return g.stats().emitted;
}
}  // namespace

TEST(Emitter, FractionalRatesAreExactOverLongRuns) {
  EXPECT_EQ(emittedAfter(10.5, 10.0, 1.0 / 30.0), 105u);
  EXPECT_EQ(emittedAfter(10.5, 10.0, 1.0 / 60.0), 105u);
  EXPECT_EQ(emittedAfter(10.5, 10.0, 1.0 / 24.0), 105u);
  EXPECT_EQ(emittedAfter(0.3, 100.0, 0.01), 30u);
  EXPECT_EQ(emittedAfter(1000.0 / 3.0, 60.0, 1.0 / 30.0), 20000u);
  EXPECT_EQ(emittedAfter(7.25, 3600.0, 1.0 / 30.0), 26100u);
}

TEST(Emitter, BirthTimesDoNotDependOnTheStep) {
  // A particle's age at the end tells its birth time: the same at any dt.
  for (double dt : {1.0 / 24.0, 1.0 / 60.0, 1.0 / 240.0}) {
    ContextOptions o;
    o.dt = dt;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 100);
    g.require({Attribute::Age});
    Emitter e;
    e.rate = 4.0;  // births at 0.25, 0.5, 0.75, 1.0
    g.addEmitter(e);
    g.setActions({Move{}});
    ctx.run(std::size_t(std::llround(1.0 / dt)));
    ASSERT_EQ(g.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
      const Particle p = g.particle(i);
      EXPECT_NEAR(p.age, 1.0 - 0.25 * (p.id + 1), 1e-5) << "dt " << dt;
    }
  }
}

TEST(Emitter, BurstsFireOnceOrRepeat) {
  ContextOptions o;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  Emitter e;
  e.bursts = {{0.0, 50, 0.0, 1}, {0.45, 10, 0.3, 3}};  // at 0; at 0.45, 0.75, 1.05
  g.addEmitter(e);
  ctx.step();
  EXPECT_EQ(g.size(), 50u);
  ctx.run(4);  // to 0.5
  EXPECT_EQ(g.size(), 60u);
  ctx.run(10);
  EXPECT_EQ(g.size(), 80u);
}

TEST(Emitter, MovingEmitterLeavesAnEvenTrail) {
  ContextOptions o;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  Emitter e;
  e.rate = 100.0;
  e.velocity = Vec3(10, 0, 0);  // 0.1 units between births
  g.addEmitter(e);
  g.setActions({Move{}});
  ctx.run(10);
  ASSERT_EQ(g.size(), 100u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_NEAR(p.position.x, 0.1 * (p.id + 1), 1e-4);  // where the emitter was at birth
  }
}

TEST(Emitter, PathKeyframesAreInterpolated) {
  Emitter e;
  e.path = {{0.0, Vec3(0)}, {1.0, Vec3(10, 0, 0)}, {3.0, Vec3(10, 20, 0)}};
  EXPECT_EQ(e.positionAt(-1.0), Vec3(0));
  EXPECT_EQ(e.positionAt(0.5), Vec3(5, 0, 0));
  EXPECT_EQ(e.positionAt(2.0), Vec3(10, 10, 0));
  EXPECT_EQ(e.positionAt(9.0), Vec3(10, 20, 0));
}

// Births look their emitter's place up on its path starting from the key the last birth
// found (a step's births are close in time): whatever key it starts from, the place is the
// one a search from scratch finds, bit for bit, for times that go forward in small and large
// jumps, go back, loop, and fall before and after the path.
TEST(Emitter, PathLookupFromAnyKeyIsTheSearchFromScratch) {
  Emitter e;
  Random rng(3, 0, 0, 0);
  double t = 0.0;
  for (int k = 0; k < 500; ++k) {
    t += 0.001 + rng.uniform();
    e.path.push_back({t, Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 100.0f});
  }
  const double end = e.path.back().time;
  for (bool loop : {false, true}) {
    e.pathLoop = loop;
    std::size_t key = 0;
    // Linear search: the key later than t, as the definition says.
    const auto expected = [&](double x) {
      if (loop && x > end)
        x = e.path.front().time + std::fmod(x - e.path.front().time, end - e.path.front().time);
      if (x <= e.path.front().time) return e.path.front().position;
      if (x >= end) return e.path.back().position;
      std::size_t b = 1;
      while (!(x < e.path[b].time)) ++b;
      const Keyframe& a = e.path[b - 1];
      const double w = (x - a.time) / (e.path[b].time - a.time);
      return a.position + (e.path[b].position - a.position) * float(w);
    };
    std::vector<double> times;
    for (double x = -1.0; x < end + 3.0; x += 0.037) times.push_back(x);       // small steps
    for (double x = 0.0; x < 2.5 * end; x += 7.9) times.push_back(x);          // long jumps
    for (double x = end + 1.0; x > -2.0; x -= 3.3) times.push_back(x);         // backwards
    for (int k = 0; k < 300; ++k) times.push_back(3.0 * end * rng.uniform());  // anywhere
    for (const double x : times) {
      const Vec3 walked = detail::pathPositionAt(e, x, key);
      ASSERT_EQ(walked, expected(x)) << "t " << x << " loop " << loop;
      ASSERT_EQ(walked, e.positionAt(x)) << "t " << x << " loop " << loop;
      if (x > e.path.front().time && x < end) {
        ASSERT_GE(key, 1u);
        ASSERT_LT(key, e.path.size());
      }
    }
  }
}

// A looping path starts again from its first key after its last: births at rate 10 along
// a there-and-back path of period 2 s keep tracing it, where a path that stops would
// leave every birth after 2 s at its end.
TEST(Emitter, LoopingPathWrapsToTheFirstKey) {
  Emitter e;
  e.path = {{0.5, Vec3(0)}, {1.5, Vec3(10, 0, 0)}, {2.5, Vec3(0)}};
  e.pathLoop = true;
  EXPECT_EQ(e.positionAt(0.0), Vec3(0));  // before the first key: held
  EXPECT_EQ(e.positionAt(2.75), Vec3(2.5f, 0, 0));
  EXPECT_EQ(e.positionAt(8.0), Vec3(5, 0, 0));  // three loops and 1.5 s: on the way back
  ContextOptions o;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  e.rate = 4.0;  // births at 0.25, 0.5, ...: on the keys and halfway between
  g.addEmitter(e);
  ctx.run(60);
  ASSERT_EQ(g.size(), 24u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    const double t = 0.25 * (p.id + 1);
    const double phase = t < 0.5 ? 0.0 : std::fmod(t - 0.5, 2.0);  // 0..2 s around the loop
    const double x = phase <= 1.0 ? 10.0 * phase : 10.0 * (2.0 - phase);
    EXPECT_NEAR(p.position.x, x, 1e-4) << "born at " << t;
  }
}

// A step's births along a path are placed a segment at a time (newborns.cpp placeOnPath):
// with many keys a step, births before the first key, after the last and around a loop,
// every newborn sits exactly where Emitter::positionAt puts the emitter at its birth time.
TEST(Emitter, PathBirthsManyKeysAStepSitWhereTheEmitterWas) {
  for (bool loop : {false, true}) {
    Emitter e;
    Random rng(5, 0, 0, 0);
    double t = 0.3;  // births from 1/rate on: the first ones before the first key
    for (int k = 0; k < 200; ++k) {
      t += 0.002 + 0.05 * rng.uniform();
      e.path.push_back({t, Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0f});
    }
    e.pathLoop = loop;
    e.rate = 997.0;  // ~33 births a step over several keys each step
    ContextOptions o;
    o.dt = 1.0 / 30.0;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 20000);
    g.addEmitter(e);
    ctx.run(int(2.0 * t * 30.0));  // past the last key: held there, or looping
    ASSERT_GT(g.size(), 1000u);
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle p = g.particle(i);
      const double born = double(p.id + 1) / e.rate;
      ASSERT_EQ(p.position, e.positionAt(born)) << "born at " << born << " loop " << loop;
    }
  }
}

TEST(Emitter, CapacityOverflowIsCountedNotACrash) {
  Context ctx;
  Group& g = ctx.createGroup("g", 100);
  Emitter e;
  e.bursts = {{0.0, 250, 0.0, 1}};
  g.addEmitter(e);
  ctx.run(3);
  EXPECT_EQ(g.size(), 100u);
  EXPECT_EQ(g.stats().emitted, 250u);
  EXPECT_EQ(g.stats().droppedAtCapacity, 150u);
  Particle p;
  EXPECT_FALSE(g.add(p));
  EXPECT_EQ(g.stats().droppedAtCapacity, 151u);
}

TEST(Emitter, AttributesComeFromTheParticleType) {
  Context ctx;
  Group& g = ctx.createGroup("g", 5000);
  g.require({Attribute::Color, Attribute::Size, Attribute::Lifetime, Attribute::Velocity});
  Emitter e;
  e.shape = Domain::box(Vec3(-1), Vec3(1));
  ParticleType t;
  t.velocity = Domain::point(Vec3(0, 5, 0));
  t.color = Domain::point(Vec3(1, 0, 0));
  t.size = Fuzzy(0.5f, 0.1f);
  t.lifetime = Fuzzy::percent(2.0f, 25.0f);
  e.types = {t};
  e.bursts = {{0.0, 4000, 0, 1}};
  g.addEmitter(e);
  ctx.step();
  ASSERT_EQ(g.size(), 4000u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_EQ(p.velocity, Vec3(0, 5, 0));
    EXPECT_EQ(p.color, Vec4(1, 0, 0, 1));
    EXPECT_GE(p.size, 0.4f);
    EXPECT_LE(p.size, 0.6f);
    EXPECT_GE(p.lifetime, 1.5f);
    EXPECT_LE(p.lifetime, 2.5f);
    EXPECT_TRUE(std::abs(p.position.x) <= 1 && std::abs(p.position.z) <= 1);
  }
}

TEST(Emitter, InvalidParametersNameTheField) {
  Context ctx;
  Group& g = ctx.createGroup("g", 10);
  auto expectParam = [&](Emitter e, const std::string& param) {
    try {
      g.addEmitter(e);
      FAIL() << "accepted " << param;
    } catch (const InvalidArgument& err) {
      EXPECT_EQ(err.parameter(), param) << err.what();
    }
  };
  Emitter a;
  a.rate = -1;
  expectParam(a, "emitters[0].rate");
  Emitter b;
  b.rate = NAN;
  expectParam(b, "emitters[0].rate");
  Emitter c;
  c.types[0].lifetime = Fuzzy(NAN);
  expectParam(c, "emitters[0].types[0].lifetime");
  Emitter d;
  d.types.clear();
  expectParam(d, "emitters[0].types");
  Emitter f;
  f.path = {{1.0, Vec3(0)}, {0.5, Vec3(1)}};
  expectParam(f, "emitters[0].path[1].time");
  Emitter h;
  h.path = {{1.0, Vec3(0)}};
  h.pathLoop = true;  // a period of 0 s
  expectParam(h, "emitters[0].pathLoop");
}

TEST(Emitter, BurstRepeatedForeverCostsTheSameEveryStep) {
  // A burst repeated ~2^32 times ("forever"): a step finds its occurrences arithmetically.
  // Walking every repeat took about 5 s a step.
  ContextOptions o;
  o.dt = 0.1;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  Emitter e;
  e.bursts = {{0.05, 3, 0.1, 4'000'000'000u}};
  g.addEmitter(e);
  const auto start = std::chrono::steady_clock::now();
  ctx.run(3);
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(g.size(), 9u);
  EXPECT_LT(took.count(), 1.0);
}

TEST(Emitter, BurstOccurrencesFallInTheStepOfTheirTime) {
  // Per step, what the bursts fire is exactly the occurrences whose times fall in the step's
  // [t0, t1) and the emitter's [start, stop], also when a time lands on a step's boundary.
  // The steps tile the clock: a step's t1 is the next one's t0 (the context's time, steps·dt),
  // not t0 + dt, which rounds to either side of it (1.2000000000000002 + 0.1 is past 1.3 =
  // 13·0.1, 0.5 + 0.1 short of 0.6000000000000001): an occurrence there fired in two steps,
  // or in none. Over the run each occurrence fires once.
  const double dt = 0.1;
  Emitter e;
  e.start = 0.3;
  e.stop = 2.0;
  e.bursts = {{0.0, 1, 0.1, 40},
              {0.05, 2, 0.3, 7},
              {0.3, 4, 0.025, 100},
              {1.2, 8, 0.0, 1},
              {0.7, 16, 1e-4, 3000}};
  ContextOptions o;
  o.dt = dt;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1 << 20);
  g.addEmitter(e);
  auto due = [&](double t0, double t1) {
    std::uint64_t n = 0;
    for (const Burst& b : e.bursts)
      for (std::uint32_t r = 0; r < b.repeat; ++r) {
        const double tb = b.time + r * b.interval;
        if (tb >= t0 && tb < t1 && tb >= e.start && tb <= e.stop) n += b.count;
      }
    return n;
  };
  for (int step = 0; step < 30; ++step) {
    const double t0 = double(step) * dt, t1 = double(step + 1) * dt;
    ASSERT_EQ(ctx.time(), t0);
    const std::uint64_t before = g.stats().emitted;
    ctx.step();
    EXPECT_EQ(g.stats().emitted - before, due(t0, t1)) << "step " << step;
  }
  EXPECT_EQ(g.stats().emitted, due(0.0, ctx.time()));
}

TEST(Emitter, ABurstOnAStepsBoundaryFiresOnceOnEveryClock) {
  // A burst at each multiple of dt (written as a designer writes it: 0.6, not 6 * 0.1) fires
  // once, on the context's clock, ahead of it (prewarm, and a new step length after it) and
  // on a group's own clock (a time scale, an update interval). Before the steps tiled the clock, a
  // burst at 0.6 s never fired at dt = 0.1, and one at 1.3 s fired twice.
  for (const double dt : {0.1, 1.0 / 30.0, 1.0 / 60.0, 0.7}) {
    for (int clock = 0; clock < 5; ++clock) {
      Context ctx({.dt = dt, .threads = 1});
      Group& g = ctx.createGroup("g", 1 << 16);
      Emitter e;
      for (int k = 1; k <= 60; ++k) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", k * dt);  // as an effect file holds it
        e.bursts.push_back({std::strtod(text, nullptr), 1, 0.0, 1});
      }
      g.addEmitter(e);
      if (clock == 1) {
        std::vector<Group*> one{&g};
        ctx.prewarm(one, 7 * dt);
      }
      if (clock == 2) g.setTimeScale(0.5);
      if (clock == 3) g.setUpdateInterval(3);
      for (int s = 0; s < 300; ++s) {
        if (clock == 4 && s == 5) {  // ahead of the clock, then another step length
          std::vector<Group*> one{&g};
          ctx.prewarm(one, 7 * dt);
          ctx.setTimeStep(dt / 3);
        }
        ctx.step();
      }
      EXPECT_EQ(g.stats().emitted, 60u) << "dt " << dt << ", clock " << clock;
    }
  }
}

namespace {
// A group of 1000 fed by `e` for three steps: full, and the rest counted as dropped.
void expectFillsTheGroup(const Emitter& e) {
  ContextOptions o;
  o.dt = 0.1;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  g.addEmitter(e);
  ctx.run(3);
  const GroupStats& s = g.stats();
  EXPECT_EQ(g.size(), 1000u);
  EXPECT_GT(s.droppedAtCapacity, 0u);
  EXPECT_EQ(s.emitted, g.size() + s.droppedAtCapacity);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Vec3 p = g.particle(i).position;
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}
}  // namespace

TEST(Emitter, RatePast2To64FillsTheGroup) {
  // 1e25/s is 1e24 births a step: converted to an integer it emitted nothing.
  Emitter e;
  e.rate = 1e25;
  expectFillsTheGroup(e);
}

TEST(Emitter, SpacingAsksPast2To64FillsTheGroup) {
  // 0.1 units a step at 1e-30 apart: converted to an integer it emitted one a step.
  Emitter e;
  e.velocity = Vec3(1, 0, 0);
  e.spacing = 1e-30f;
  expectFillsTheGroup(e);
}

TEST(Emitter, BurstsAskingPast2To64FillTheGroup) {
  // Two bursts of 2^32 - 1 particles each fired 2^32 - 1 times in the first step: more
  // than 2^64 births together.
  Emitter e;
  const std::uint32_t most = 0xFFFFFFFFu;
  e.bursts = {{0.0, most, 1e-12, most}, {0.0, most, 1e-12, most}};
  expectFillsTheGroup(e);
}

// A newborn lives what is left of its birth step through the whole action list, like every
// other particle: a deflector in front of the nozzle bounces it in its birth step too (#11),
// a floor, a sphere or a box alike (each newborn with its own step length).
TEST(Emitter, NewbornsNearADeflectorNeverEndBehindIt) {
  const Domain floor = Domain::plane(Vec3(0), Vec3(0, 1, 0));
  const Domain ball = Domain::sphere(Vec3(0.0f, -1.0f, 0.0f), 1.0f);
  const Domain block = Domain::box(Vec3(-1.0f, -2.0f, -1.0f), Vec3(1.0f, 0.0f, 1.0f));
  for (const Domain* surface : {&floor, &ball, &block})
    for (double dt : {1.0 / 30.0, 0.1, 0.5}) {
      ContextOptions o;
      o.dt = dt;
      o.threads = 1;
      Context ctx(o);
      Group& g = ctx.createGroup("g", 100000);
      Emitter e;
      e.rate = 3000.0;
      e.shape = Domain::disc(Vec3(0.0f, 0.01f, 0.0f), Vec3(0, 1, 0), 0.2f);  // 0.01 above
      ParticleType t;
      t.velocity = Domain::box(Vec3(-1.0f, -4.0f, -1.0f), Vec3(1.0f, -2.0f, 1.0f));  // downwards
      e.types = {t};
      g.addEmitter(e);
      g.setActions({Gravity{}, Bounce{*surface, 0.5f, 0.0f, 0.0f}, Move{}});
      for (int s = 0; s < 12; ++s) {
        ctx.step();
        ASSERT_GT(g.size(), 0u);
        std::size_t behind = 0;
        for (std::size_t i = 0; i < g.size(); ++i) {
          const Vec3 p = g.particle(i).position;
          behind += surface == &floor ? p.y < 0.0f : surface->contains(p);
        }
        ASSERT_EQ(behind, 0u) << surface->name() << ", dt " << dt << ", step " << s << ", of "
                              << g.size();
      }
    }
}

// With Exact and a constant force a particle's path does not depend on the step: newborns
// included, which start on it at their birth times (#11).
TEST(Emitter, ExactFountainDoesNotDependOnTheStep) {
  auto heights = [](double dt) {
    ContextOptions o;
    o.dt = dt;
    o.threads = 1;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 1000);
    Emitter e;
    e.rate = 37.0;  // births between steps
    ParticleType t;
    t.velocity = Domain::point(Vec3(0.5f, 6.0f, 0.0f));
    e.types = {t};
    g.addEmitter(e);
    ActionList list{Gravity{}, Move{}};
    list.setIntegrator(Integrator::Exact);
    g.setActions(list);
    ctx.run(std::size_t(std::llround(1.0 / dt)));
    std::vector<float> y(g.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle p = g.particle(i);
      // Born at (id + 1) / 37: where the parabola has it at t = 1.
      const double tau = 1.0 - (p.id + 1) / 37.0;
      EXPECT_NEAR(p.position.y, 6.0 * tau - 0.5 * 9.81 * tau * tau, 2e-5) << "dt " << dt;
      EXPECT_NEAR(p.position.x, 0.5 * tau, 2e-6) << "dt " << dt;
      y[p.id] = p.position.y;
    }
    return y;
  };
  const std::vector<float> coarse = heights(1.0 / 24.0), fine = heights(1.0 / 240.0);
  ASSERT_EQ(coarse.size(), 37u);
  ASSERT_EQ(fine.size(), 37u);
  double mean = 0.0;
  for (std::size_t i = 0; i < coarse.size(); ++i) mean += double(coarse[i]) - double(fine[i]);
  EXPECT_NEAR(mean / 37.0, 0.0, 1e-5);
}

// Newborns run the action list over what is left of their birth step in one batch, each with
// its own step length: every one ends where the closed forms put it for that length, also
// when the newborns start in the middle of a block and span several blocks and threads.
TEST(Emitter, NewbornsRunTheActionsForTheirOwnPartOfTheStep) {
  const double rate = 1000.0, dt = 0.5;
  const Vec3 p0(0.5f, 1.0f, -0.25f), v0(1.0f, 2.0f, 0.5f), c0(0.2f, 0.4f, 0.6f);
  const Vec3 centre(2.0f, 0.0f, 0.0f), targetColour(1.0f, 0.0f, 0.5f);
  const float drag = 0.7f, pull = 3.0f, eps = 0.01f, colourRate = 2.0f;
  ContextOptions o;
  o.dt = dt;
  o.threads = 2;
  Context ctx(o);
  detail::setPassOptions(ctx,
                         {.blockSize = 64});  // the newborns begin inside a block and fill several
  Group& g = ctx.createGroup("g", 10000);
  Emitter e;
  e.rate = rate;
  e.shape = Domain::point(p0);
  ParticleType t;
  t.velocity = Domain::point(v0);
  t.color = Domain::point(c0);
  e.types = {t};
  g.addEmitter(e);
  g.setActions({Damping{Vec3(drag)}, OrbitPoint{centre, pull, eps},
                TargetColor{targetColour, 0.5f, colourRate}, Move{}, KillOld{}});
  ctx.run(2);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    const double born = double(p.id + 1) / rate;
    if (born <= dt) continue;  // born in the first step: ran a whole second one
    const double h = 2.0 * dt - born;
    // Damping, then the pull from the birth place, then Move (semi-implicit Euler).
    const glm::dvec3 d = glm::dvec3(centre) - glm::dvec3(p0);
    const double s = glm::dot(d, d) + eps;
    const glm::dvec3 v =
        glm::dvec3(v0) * std::exp(-double(drag) * h) + d * (double(pull) / (s * std::sqrt(s))) * h;
    const glm::dvec3 pos = glm::dvec3(p0) + v * h;
    const double k = 1.0 - std::exp(-double(colourRate) * h);
    const glm::dvec3 col = glm::dvec3(c0) + (glm::dvec3(targetColour) - glm::dvec3(c0)) * k;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(p.velocity[c], v[c], 2e-6 * (1.0 + std::abs(v[c]))) << "id " << p.id;
      EXPECT_NEAR(p.position[c], pos[c], 2e-6 * (1.0 + std::abs(pos[c]))) << "id " << p.id;
      EXPECT_NEAR(p.color[c], col[c], 2e-6) << "id " << p.id;
    }
    EXPECT_NEAR(p.color.a, 1.0 + (0.5 - 1.0) * k, 2e-6) << "id " << p.id;
    EXPECT_NEAR(p.age, h, 2e-6) << "id " << p.id;
    ++checked;
  }
  EXPECT_EQ(checked, 500u);
}
