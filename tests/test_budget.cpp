// A particle budget per Context (Context::setParticleBudget) and each group's policy past its
// share (Group::setBudgetPolicy): the context stays within it, every particle is accounted for,
// each policy gives up what it says, and the result is the same on any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

Group& spray(Context& ctx, const std::string& name, std::size_t capacity, float lifetime,
             std::vector<float> xs = {0.0f}, double rate = 3000.0) {
  Group& g = ctx.createGroup(name, capacity);
  for (float x : xs) {
    Emitter e;
    e.shape = Domain::sphere(Vec3(x, 0, 0), 0.2f);
    e.rate = rate;
    e.types[0].velocity = Domain::sphere(Vec3(0, 1, 0), 0.5f);
    e.types[0].lifetime = lifetime;
    g.addEmitter(e);
  }
  g.setActions({Move{}, KillOld{}});
  return g;
}

std::size_t live(Context& ctx) {
  std::size_t n = 0;
  for (Group* g : ctx.groups()) n += g->size();
  return n;
}

void expectAccounted(const Group& g) {
  const GroupStats& s = g.stats();
  EXPECT_EQ(s.emitted, g.size() + s.killedByAge + s.absorbed + s.droppedAtCapacity +
                           s.droppedAtBudget + s.killedByBudget + s.killedNonFinite)
      << g.name();
}

}  // namespace

TEST(Budget, TheContextStaysWithinItAndEveryGroupGetsAShare) {
  Context ctx({.seed = 3, .dt = 1.0 / 30, .threads = 2});
  Group& a = spray(ctx, "a", 10000, 1.0f);
  Group& b = spray(ctx, "b", 10000, 1.0f, {0.0f}, 1500.0);
  ctx.setParticleBudget(2000);
  EXPECT_EQ(ctx.particleBudget(), 2000u);
  for (int s = 0; s < 90; ++s) {
    ctx.step();
    ASSERT_LE(live(ctx), 2000u) << "step " << s;
  }
  // Shared by what each asks for: a asks twice what b does.
  EXPECT_GT(a.size(), 1000u);
  EXPECT_GT(b.size(), 500u);
  EXPECT_GT(a.stats().droppedAtBudget, 0u);
  EXPECT_EQ(a.stats().killedByBudget, 0u);
  expectAccounted(a);
  expectAccounted(b);
  const ContextStats cs = ctx.stats();
  EXPECT_EQ(cs.droppedAtBudget, a.stats().droppedAtBudget + b.stats().droppedAtBudget);
  // Lifted: the groups fill to what their emitters give (3000 and 1500 alive).
  ctx.setParticleBudget(0);
  ctx.run(60);
  EXPECT_GT(live(ctx), 4000u);
}

TEST(Budget, ScaleEmissionThinsEveryEmitterAlike) {
  auto sides = [](BudgetPolicy policy) {
    Context ctx({.seed = 5, .dt = 1.0 / 30, .threads = 1});
    Group& g = spray(ctx, "g", 20000, 1.0f, {-5.0f, 5.0f});
    g.setBudgetPolicy(policy);
    ctx.setParticleBudget(100);  // each emitter alone asks for 100 a step
    ctx.run(90);
    expectAccounted(g);
    EXPECT_LE(g.size(), 100u);
    std::size_t left = 0;
    for (float x : g.lane(Attribute::Position, 0)) left += x < 0.0f;
    return std::pair{left, g.size() - left};
  };
  // Dropping the newest keeps the first emitter's births: the second goes quiet.
  const auto [newestLeft, newestRight] = sides(BudgetPolicy::DropNewest);
  EXPECT_GT(newestLeft, 90u);
  EXPECT_EQ(newestRight, 0u);
  // Scaled, both keep the same fraction.
  const auto [scaledLeft, scaledRight] = sides(BudgetPolicy::ScaleEmission);
  EXPECT_GT(scaledLeft + scaledRight, 90u);
  EXPECT_LT(std::max(scaledLeft, scaledRight), 1.15 * std::min(scaledLeft, scaledRight));
}

TEST(Budget, DropOldestKeepsTheNewest) {
  Context ctx({.seed = 7, .dt = 1.0 / 30, .threads = 1});
  Group& g = spray(ctx, "g", 20000, 100.0f);  // nothing dies of age
  g.setBudgetPolicy(BudgetPolicy::DropOldest);
  EXPECT_EQ(g.budgetPolicy(), BudgetPolicy::DropOldest);
  ctx.setParticleBudget(500);
  for (int s = 0; s < 40; ++s) {
    ctx.step();
    ASSERT_LE(g.size(), 500u);
  }
  // Every birth made; the survivors are the last 500 born (ids count births).
  EXPECT_EQ(g.stats().droppedAtBudget, 0u);
  EXPECT_GT(g.stats().killedByBudget, 2000u);
  const auto ids = g.ids();
  EXPECT_EQ(*std::min_element(ids.begin(), ids.end()), g.stats().emitted - g.size());
  expectAccounted(g);
  // A lower budget: it shrinks at once.
  ctx.setParticleBudget(200);
  ctx.step();
  EXPECT_LE(g.size(), 200u);
  EXPECT_THROW(g.setBudgetPolicy(BudgetPolicy(7)), InvalidArgument);
}

TEST(Budget, BitwiseTheSameOnAnyThreadCount) {
  auto run = [](unsigned threads) {
    Context ctx({.seed = 11, .dt = 1.0 / 30, .threads = threads});
    for (int k = 0; k < 24; ++k) {
      Group& g = spray(ctx, "g" + std::to_string(k), 2000, 0.5f + 0.1f * float(k % 5), {float(k)},
                       500.0 + 100.0 * k);
      g.setBudgetPolicy(BudgetPolicy(k % 3));
    }
    ctx.setParticleBudget(6000);
    ctx.run(45);
    std::vector<float> all;
    for (Group* g : ctx.groups()) {
      const auto x = g->lane(Attribute::Position, 0);
      all.insert(all.end(), x.begin(), x.end());
    }
    EXPECT_LE(all.size(), 6000u);
    return all;
  };
  const auto one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
}

// Many small groups and little room: the rounding's remainders are handed out, so the room
// is used to the last particle.
TEST(Budget, ThousandsOfSmallSharesUseAllTheRoom) {
  Context ctx({.seed = 13, .dt = 1.0 / 30, .threads = 2});
  for (int k = 0; k < 100; ++k) spray(ctx, "g" + std::to_string(k), 64, 100.0f, {0.0f}, 300.0);
  ctx.setParticleBudget(50);
  ctx.step();
  EXPECT_EQ(live(ctx), 50u);  // 100 groups each asking 10: 50 of them get one
  ctx.run(5);
  EXPECT_EQ(live(ctx), 50u);
}

// A DropOldest group fed by a death emitter makes room for those newborns too: the context is
// within its budget after every step.
TEST(Budget, DeathEmittersNewbornsAreHeldToItToo) {
  Context ctx({.seed = 17, .dt = 1.0 / 30, .threads = 1});
  spray(ctx, "shells", 1000, 0.2f, {0.0f}, 600.0);
  Group& sparks = ctx.createGroup("sparks", 20000);
  sparks.setActions({Move{}, KillOld{}});
  sparks.setBudgetPolicy(BudgetPolicy::DropOldest);
  DeathEmitter de;
  de.source = "shells";
  de.count = 10.0f;
  de.types[0].lifetime = 100.0f;
  sparks.addDeathEmitter(de);
  ctx.setParticleBudget(800);
  for (int s = 0; s < 60; ++s) {
    ctx.step();
    ASSERT_LE(live(ctx), 800u) << "step " << s;
  }
  EXPECT_GT(sparks.stats().killedByBudget, 1000u);
  expectAccounted(sparks);
}
