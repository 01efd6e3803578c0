// Prime emitters (showers of showers), emitters along normals and by distance, hair strands.
#include <gtest/gtest.h>

#include <cmath>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {
ParticleType spark(float life) {
  ParticleType t;
  t.velocity = Domain::sphere(Vec3(0), 2.0f);
  t.lifetime = life;
  return t;
}
}  // namespace

TEST(PrimeEmitter, ShowersOfShowersThreeLevelsDeep) {
  ContextOptions o;
  o.dt = 1.0 / 30.0;
  Context ctx(o);
  Group& g = ctx.createGroup("fireworks", 20000);
  // Level 3: small emitters that trail a few sparks and burst at death.
  auto level3 = std::make_shared<EmitterSpec>();
  level3->emitter.rate = 30;
  level3->emitter.types = {spark(0.5f)};
  level3->lifetime = Fuzzy(0.3f, 0.05f);
  level3->deathBurst = 10;
  // Level 2: spark emitters from each shell's death, which spawn level 3 at theirs.
  auto level2 = std::make_shared<EmitterSpec>();
  level2->emitter.rate = 50;
  level2->emitter.types = {spark(0.5f)};
  level2->velocity = Domain::sphere(Vec3(0), 8.0f, 8.0f);
  level2->lifetime = Fuzzy(0.5f, 0.1f);
  level2->deathChildren = 4;
  level2->next = level3;
  // Level 1: shells from the prime emitter.
  PrimeEmitter prime;
  prime.bursts = {{0.0, 3, 0.0, 1}};
  prime.child.emitter.rate = 100;  // a smoke trail
  prime.child.emitter.types = {spark(1.0f)};
  prime.child.velocity = Domain::cone(Vec3(0), Vec3(0, 20, 0), 3.0f);
  prime.child.lifetime = Fuzzy(1.0f, 0.1f);
  prime.child.deathChildren = 12;
  prime.child.next = level2;
  g.addPrimeEmitter(prime);
  g.setActions({Gravity{}, Move{}, KillOld{}});
  std::size_t mostEmitters = 0;
  for (int s = 0; s < 90; ++s) {
    ctx.step();
    mostEmitters = std::max(mostEmitters, g.liveEmitterCount());
  }
  const auto& byGen = g.stats().emittedByGeneration;
  ASSERT_GE(byGen.size(), 4u);
  EXPECT_GT(byGen[1], 0u);  // shells' trails
  EXPECT_GT(byGen[2], 0u);  // sparks
  EXPECT_GT(byGen[3], 0u);  // third-generation sparks
  EXPECT_EQ(g.stats().emittersSpawned, 3u + 3 * 12 + 3 * 12 * 4);
  EXPECT_GT(mostEmitters, 36u);
  EXPECT_EQ(g.liveEmitterCount(), 0u);  // all have died by now
  const auto& st = g.stats();
  EXPECT_EQ(st.emitted, g.size() + st.killedByAge + st.absorbed + st.droppedAtCapacity);
}

TEST(PrimeEmitter, SpawnedEmittersFlyBallistically) {
  ContextOptions o;
  o.dt = 0.01;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 10000);
  PrimeEmitter prime;
  prime.bursts = {{0.0, 1, 0.0, 1}};
  prime.child.velocity = Domain::point(Vec3(3, 10, 0));
  prime.child.acceleration = Vec3(0, -10, 0);
  prime.child.lifetime = 2.0f;
  prime.child.emitter.spacing = 0.0f;
  prime.child.deathBurst = 1;
  prime.child.emitter.types = {spark(10.0f)};
  prime.child.emitter.types[0].velocity = Domain::point(Vec3(0));
  g.addPrimeEmitter(prime);
  ctx.run(201);
  // The death burst's particle is where the emitter died: p = v t + a t²/2 at t = 2.
  ASSERT_EQ(g.size(), 1u);
  const Vec3 p = g.particle(0).position;
  EXPECT_NEAR(p.x, 6.0f, 1e-3f);
  EXPECT_NEAR(p.y, 0.0f, 1e-3f);
}

TEST(PrimeEmitter, LiveEmittersAreBoundedByDefault) {
  // 1e6 spawns a second with nothing to end them grew without bound (1e7: bad_alloc).
  ContextOptions o;
  o.dt = 1.0 / 30.0;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  PrimeEmitter prime;
  prime.rate = 1e6;
  prime.child.lifetime = 100.0f;
  g.addPrimeEmitter(prime);
  ctx.run(3);
  EXPECT_EQ(g.liveEmitterCount(), 4096u);
  EXPECT_EQ(g.stats().emittersSpawned, 4096u);
}

TEST(PrimeEmitter, MaxEmittersDropsAndCountsSpawnsPastIt) {
  ContextOptions o;
  o.dt = 0.1;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 1000);
  auto next = std::make_shared<EmitterSpec>();
  next->lifetime = 10.0f;
  PrimeEmitter prime;
  prime.maxEmitters = 8;
  prime.bursts = {{0.0, 3, 0.0, 1}};
  prime.child.lifetime = 0.25f;  // all three die in the third step
  prime.child.deathChildren = 2;
  prime.child.next = next;
  g.addPrimeEmitter(prime);
  ctx.step();
  EXPECT_EQ(g.liveEmitterCount(), 3u);
  ctx.run(2);
  // The dying three hold their places until the step ends: room for 5 of their 6 children.
  EXPECT_EQ(g.liveEmitterCount(), 5u);
  EXPECT_EQ(g.stats().emittersSpawned, 8u);
  EXPECT_EQ(g.stats().emittersDropped, 1u);
  // A rate of 1e7 a second adds nothing past the limit, and counts what it drops.
  // A second prime emitter has its own limit.
  PrimeEmitter fast;
  fast.maxEmitters = 100;
  fast.rate = 1e7;
  fast.start = 0.3;
  fast.child.lifetime = 100.0f;
  g.addPrimeEmitter(fast);
  ctx.run(3);
  EXPECT_EQ(g.liveEmitterCount(), 105u);
  EXPECT_EQ(g.stats().emittersSpawned, 108u);
  EXPECT_EQ(g.stats().emittersDropped, 1u + 3u * 1'000'000u - 100u);
  PrimeEmitter zero;
  zero.maxEmitters = 0;
  EXPECT_THROW(g.addPrimeEmitter(zero), InvalidArgument);
}

TEST(PrimeEmitter, MaxEmittersFromAnEffectFile) {
  const Effect fx = parseEffect(R"({"version": 1, "groups": [{"capacity": 10,
      "primeEmitters": [{"rate": 1, "maxEmitters": 12, "child": {}}]}]})");
  ASSERT_EQ(fx.groups.at(0).primeEmitters.size(), 1u);
  EXPECT_EQ(fx.groups[0].primeEmitters[0].maxEmitters, 12u);
  EXPECT_THROW(parseEffect(R"({"version": 1, "groups": [{"capacity": 10,
      "primeEmitters": [{"rate": 1, "maxEmitters": 0, "child": {}}]}]})"),
               EffectError);
}

TEST(Emitter, ByDistanceLeavesAnEvenTrailAtAnySpeed) {
  for (float speed : {1.0f, 100.0f, 1e4f}) {
    ContextOptions o;
    o.dt = 1.0 / 30.0;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 100000);
    Emitter e;
    e.velocity = Vec3(speed, 0, 0);
    e.spacing = speed / 100.0f;  // 100 births per second of travel
    e.types[0].velocity = Domain::point(Vec3(0));
    g.addEmitter(e);
    ctx.run(30);  // 1 s
    ASSERT_NEAR(double(g.size()), 100.0, 1.0) << speed;
    std::vector<float> xs;
    for (std::size_t i = 0; i < g.size(); ++i) xs.push_back(g.particle(i).position.x);
    std::sort(xs.begin(), xs.end());
    for (std::size_t i = 1; i < xs.size(); ++i)
      ASSERT_NEAR(xs[i] - xs[i - 1], e.spacing, e.spacing * 1e-3f) << speed;
  }
}

TEST(Emitter, PolyhedronFacesEmitAlongTheirNormals) {
  // A tetrahedron, counter-clockwise from outside.
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<glm::uvec3> t = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const Domain mesh = Domain::mesh(v, t);
  EXPECT_TRUE(mesh.contains(Vec3(0.1f, 0.1f, 0.1f)));
  EXPECT_FALSE(mesh.contains(Vec3(1, 1, 1)));
  ContextOptions o;
  o.dt = 0.1;
  Context ctx(o);
  Group& g = ctx.createGroup("g", 5000);
  g.require({Attribute::Velocity});
  Emitter e;
  e.shape = mesh;
  e.normalSpeed = 2.0f;
  e.types[0].velocity = Domain::point(Vec3(0));
  e.bursts = {{0.0, 4000, 0.0, 1}};
  g.addEmitter(e);
  ctx.step();
  ASSERT_EQ(g.size(), 4000u);
  int outward = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_NEAR(glm::length(p.velocity), 2.0f, 1e-4f);
    // Born on the surface, moving away from the inside.
    outward += glm::dot(p.velocity, p.position - Vec3(0.25f)) > 0.0f;
  }
  EXPECT_EQ(outward, 4000);
}

// A newborn takes the normal of the face it was born on, not of the face nearest its birth
// place: a two-sided square (each side's two triangles in the same plane, wound opposite
// ways) emits from each side in proportion to its area, where the nearest face, the first
// of equals, would send every particle up. The same with one particle type and with two
// (whose newborns are shaped type by type).
TEST(Emitter, TwoSidedFaceEmitsFromTheSideEachParticleWasBornOn) {
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  const std::vector<glm::uvec3> t = {{0, 3, 2}, {0, 2, 1}, {0, 2, 3}, {0, 1, 2}};
  for (int types : {1, 2}) {
    Context ctx;
    Group& g = ctx.createGroup("g", 5000);
    g.require({Attribute::Velocity});
    Emitter e;
    e.shape = Domain::mesh(v, t);
    e.normalSpeed = 2.0f;
    e.types[0].velocity = Domain::point(Vec3(0));
    if (types == 2) e.types.push_back(e.types[0]);
    e.bursts = {{0.0, 4000, 0.0, 1}};
    g.addEmitter(e);
    g.setActions({});
    ctx.step();
    ASSERT_EQ(g.size(), 4000u);
    int up = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Vec3 vel = g.particle(i).velocity;
      ASSERT_EQ(std::abs(vel.y), 2.0f) << i;
      up += vel.y > 0.0f;
    }
    EXPECT_GT(up, 1800) << types;  // half of them: 2000 ± 3.2 standard deviations
    EXPECT_LT(up, 2200) << types;
  }
}

TEST(Hair, StrandsHoldEachParticlesWholeLife) {
  ContextOptions o;
  o.dt = 0.05;
  Context ctx(o);
  Group& g = ctx.createGroup("hair", 1000);
  g.setHair({true, 1, 64});
  g.require({Attribute::Color, Attribute::Size});
  Emitter e;
  e.bursts = {{0.0, 20, 0.0, 1}};
  e.types[0].velocity = Domain::point(Vec3(1, 5, 0));
  e.types[0].lifetime = 1.0f;
  g.addEmitter(e);
  g.setActions({Gravity{}, Move{}, KillOld{}, SizeOverLife{}});
  ctx.step();
  EXPECT_EQ(g.size(), 0u);  // a hair group holds strands, not particles
  const Strands& s = g.strands();
  ASSERT_EQ(s.size(), 20u);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const std::size_t n = s.start[k + 1] - s.start[k];
    EXPECT_GE(n, 19u);  // ages 0.05 .. 1 s in steps of 0.05 s
    // A parabola: it rises, then falls.
    const Vec3 first = s.position[s.start[k]], last = s.position[s.start[k + 1] - 1];
    EXPECT_NEAR(last.x - first.x, 1.0f, 0.1f);
    EXPECT_GT(s.radius[s.start[k]], s.radius[s.start[k + 1] - 1]);  // thins along its life
  }
  EXPECT_EQ(g.stats().emitted, 20u);
}

// Newborns that die in their birth step leave holes that compaction fills from the tail
// before the strands are made: particle 0's place then holds the last-born. Each survivor
// still gets its own strand, in the order of birth (ids), and the dead none.
TEST(Hair, NewbornsDeadInTheirBirthStepLeaveNoStrand) {
  for (unsigned threads : {1u, 2u}) {
    ContextOptions o;
    o.dt = 0.05;
    o.threads = threads;
    Context ctx(o);
    Group& g = ctx.createGroup("hair", 1000);
    g.setHair({true, 1, 64});
    auto burst = [&](float lifetime, float x) {
      Emitter e;
      e.bursts = {{0.0, 10, 0.0, 1}};
      e.position = Vec3(x, 0.0f, 0.0f);
      e.types[0].velocity = Domain::point(Vec3(0, 5, 0));
      e.types[0].lifetime = lifetime;
      g.addEmitter(e);
    };
    burst(0.001f, 0.0f);  // the first ten born: dead within their birth step
    burst(1.0f, 1.0f);    // the next ten live a second
    g.setActions({Gravity{}, Move{}, KillOld{}});
    ctx.step();
    const Strands& s = g.strands();
    ASSERT_EQ(s.size(), 10u) << threads;
    for (std::size_t k = 0; k < s.size(); ++k) {
      EXPECT_GE(s.start[k + 1] - s.start[k], 19u);
      EXPECT_EQ(s.position[s.start[k]].x, 1.0f);  // the second emitter's
    }
  }
}

TEST(UnionDomain, SamplesAllPartsByMeasure) {
  const Domain u =
      Domain::unite({Domain::box(Vec3(0), Vec3(1)), Domain::box(Vec3(10, 0, 0), Vec3(13, 1, 1))});
  EXPECT_NEAR(u.measure(), 4.0, 1e-6);
  Random rng(5, 0, 0, 0);
  int inSecond = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = u.sample(rng);
    ASSERT_TRUE(u.contains(p));
    inSecond += p.x >= 10.0f;
  }
  EXPECT_NEAR(double(inSecond) / n, 0.75, 0.02);
}
