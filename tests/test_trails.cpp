// Trails (Group::setTrail): each live particle keeps where it was at the end of its last N
// steps. The points are exactly the positions the particle had (read back after each step),
// follow their particle through deaths and compaction, start where a newborn was born inside
// its step, are bitwise the same on any thread count, and move with a group in local space.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

std::vector<Vec3> trailOf(const Group& g, std::size_t i) {
  std::vector<Vec3> out(TrailOptions::kMaxLength);
  out.resize(g.trail(i, out));
  return out;
}

Vec3 positionOf(const Group& g, std::size_t i) {
  return {g.lane(Attribute::Position, 0)[i], g.lane(Attribute::Position, 1)[i],
          g.lane(Attribute::Position, 2)[i]};
}

}  // namespace

TEST(Trail, KeepsTheLastPositionsNewestFirst) {
  Context ctx({.seed = 1, .dt = 0.1, .threads = 1});
  Group& g = ctx.createGroup("g", 4);
  g.setActions({Gravity{Vec3(0, -9.81f, 0)}, Move{}});
  g.setTrail({.length = 4});
  Particle p;
  p.position = Vec3(1, 2, 3);
  p.velocity = Vec3(1, 5, 0);
  ASSERT_TRUE(g.add(p));
  std::vector<Vec3> seen{p.position};  // the trail starts where the particle was added
  EXPECT_EQ(trailOf(g, 0), seen);
  for (int step = 1; step <= 7; ++step) {
    ctx.step();
    seen.insert(seen.begin(), positionOf(g, 0));
    if (seen.size() > 4) seen.pop_back();
    // Bitwise the positions it had, newest first, at most `length` of them.
    EXPECT_EQ(trailOf(g, 0), seen) << "step " << step;
  }
  // A shorter buffer takes the newest; the count says how many there are.
  std::vector<Vec3> two(2);
  EXPECT_EQ(g.trail(0, two), 4u);
  EXPECT_EQ(two[0], seen[0]);
  EXPECT_EQ(two[1], seen[1]);
}

// Many births and deaths a step, each particle on its own straight line: every live
// particle's trail is its own history (read back step by step, by id) and begins where it was
// born inside its first step (p - v·age).
TEST(Trail, FollowsEachParticleThroughDeathsAndCompaction) {
  Context ctx({.seed = 5, .dt = 1.0 / 60, .threads = 2});
  Group& g = ctx.createGroup("g", 4000);
  Emitter e;
  e.shape = Domain::sphere(Vec3(0), 1.0f);
  e.rate = 12000.0;
  e.types[0].velocity = Domain::sphere(Vec3(0), 3.0f);
  e.types[0].lifetime = Fuzzy(0.175f, 0.125f);
  g.addEmitter(e);
  g.setActions({Move{}, KillOld{}});
  const std::uint32_t length = 6;
  g.setTrail({.length = length});
  std::map<std::uint32_t, std::vector<Vec3>> history;  // by id: positions after each step
  std::size_t checked = 0, full = 0;
  for (int step = 0; step < 60; ++step) {
    ctx.step();
    std::map<std::uint32_t, std::vector<Vec3>> alive;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const std::uint32_t id = g.ids()[i];
      auto& h = alive[id];
      if (auto it = history.find(id); it != history.end()) h = std::move(it->second);
      h.insert(h.begin(), positionOf(g, i));
      const std::vector<Vec3> trail = trailOf(g, i);
      ASSERT_EQ(trail.size(), std::min<std::size_t>(h.size() + 1, length)) << "id " << id;
      for (std::size_t k = 0; k < trail.size() && k < h.size(); ++k)
        ASSERT_EQ(trail[k], h[k]) << "id " << id << " point " << k;
      if (trail.size() == h.size() + 1) {
        // The oldest point is the birth place, inside its first step.
        const Particle q = g.particle(i);
        const Vec3 born = q.position - q.velocity * q.age;
        EXPECT_NEAR(trail.back().x, born.x, 1e-5f);
        EXPECT_NEAR(trail.back().y, born.y, 1e-5f);
        EXPECT_NEAR(trail.back().z, born.z, 1e-5f);
      } else {
        ++full;
      }
      ++checked;
    }
    history = std::move(alive);
  }
  EXPECT_GT(g.stats().killedByAge, 5000u);  // compaction moved particles every step
  EXPECT_GT(checked, 50000u);
  EXPECT_GT(full, 10000u);
}

TEST(Trail, BitwiseTheSameOnAnyThreadCount) {
  auto run = [](unsigned threads) {
    Context ctx({.seed = 9, .dt = 1.0 / 30, .threads = threads});
    Group& g = ctx.createGroup("fountain", 120000);  // large enough to be shared out
    Emitter e;
    e.shape = Domain::disc(Vec3(0, 0.2f, 0), Vec3(0, 1, 0), 0.3f);
    e.rate = 600000.0;
    e.types[0].velocity = Domain::cone(Vec3(0), Vec3(0, 6, 0), 2.0f);
    e.types[0].lifetime = Fuzzy(0.6f, 0.4f);
    g.addEmitter(e);
    g.setActions({Gravity{Vec3(0, -9.81f, 0)},
                  Bounce{Domain::plane(Vec3(0), Vec3(0, 1, 0)), 0.4f, 0.1f, 0.0f}, Move{},
                  KillOld{}});
    g.setTrail({.length = 5});
    for (int s = 0; s < 20; ++s) ctx.step();
    std::vector<Vec3> all;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const auto t = trailOf(g, i);
      all.insert(all.end(), t.begin(), t.end());
      all.push_back(Vec3(float(t.size())));
    }
    return all;
  };
  const auto one = run(1), two = run(2);
  ASSERT_GT(one.size(), 100000u);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_TRUE(one == two);
}

TEST(Trail, StartsWhereTheParticlesAreAndStops) {
  Context ctx({.seed = 1, .dt = 0.5, .threads = 1});
  Group& g = ctx.createGroup("g", 8);
  g.setActions({Move{}});
  Particle p;
  p.velocity = Vec3(2, 0, 0);
  g.add(p);
  ctx.step();
  EXPECT_EQ(g.trail(0, {}), 0u);  // no trail asked for
  g.setTrail({.length = 3});
  EXPECT_EQ(trailOf(g, 0), std::vector<Vec3>{Vec3(1, 0, 0)});
  ctx.step();
  EXPECT_EQ(trailOf(g, 0), (std::vector<Vec3>{Vec3(2, 0, 0), Vec3(1, 0, 0)}));
  // The look alone changes nothing kept.
  g.setTrail({.length = 3, .width = 0.1f, .taper = 0.2f, .fade = 0.5f});
  EXPECT_EQ(trailOf(g, 0).size(), 2u);
  EXPECT_EQ(g.trail().width, 0.1f);
  g.setTrail({});
  ctx.step();
  EXPECT_EQ(g.trail(0, {}), 0u);
  EXPECT_THROW(g.trail(1, {}), InvalidArgument);
}

TEST(Trail, BadOptionsNameTheField) {
  Context ctx({.threads = 1});
  Group& g = ctx.createGroup("g", 8);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto field = [&](const TrailOptions& o) {
    try {
      g.setTrail(o);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(field({.length = 257}).find("trail.length"), std::string::npos);
  EXPECT_NE(field({.length = 4, .width = -1.0f}).find("trail.width"), std::string::npos);
  EXPECT_NE(field({.length = 4, .taper = nan}).find("trail.taper"), std::string::npos);
  EXPECT_NE(field({.length = 4, .fade = inf}).find("trail.fade"), std::string::npos);
  EXPECT_EQ(g.trail().length, 0u);  // left as it was
}

TEST(Trail, MovesWithAGroupInLocalSpace) {
  Context ctx({.seed = 1, .dt = 0.1, .threads = 1});
  Group& g = ctx.createGroup("g", 8);
  g.setSpace(Space::Local);
  g.setActions({Move{}});
  g.setTrail({.length = 4});
  Particle p;
  p.velocity = Vec3(0, 1, 0);
  g.add(p);
  for (int s = 0; s < 3; ++s) ctx.step();
  const auto before = trailOf(g, 0);
  ASSERT_EQ(before.size(), 4u);
  g.setTransform({Vec3(5, 0, 0)});
  const auto after = trailOf(g, 0);
  ASSERT_EQ(after.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(after[k], before[k] + Vec3(5, 0, 0));
}

TEST(Trail, NewbornsOfADeathEmitterStartTheirOwn) {
  Context ctx({.seed = 2, .dt = 0.1, .threads = 1});
  Group& shells = ctx.createGroup("shells", 4);
  shells.setActions({Move{}, KillOld{}});
  Particle p;
  p.velocity = Vec3(0, 1, 0);
  p.lifetime = 0.25f;
  shells.add(p);
  Group& sparks = ctx.createGroup("sparks", 64);
  DeathEmitter d;
  d.source = "shells";
  d.count = Fuzzy(10.0f);
  sparks.addDeathEmitter(d);
  sparks.setActions({Move{}});
  sparks.setTrail({.length = 8});
  for (int s = 0; s < 3; ++s) ctx.step();
  ASSERT_EQ(sparks.size(), 10u);
  for (std::size_t i = 0; i < sparks.size(); ++i)
    EXPECT_EQ(trailOf(sparks, i), std::vector<Vec3>{positionOf(sparks, i)});
  ctx.step();
  for (std::size_t i = 0; i < sparks.size(); ++i) EXPECT_EQ(trailOf(sparks, i).size(), 2u);
}

TEST(Trail, StrandsTaperAndFadeAlongIt) {
  Context ctx({.seed = 1, .dt = 0.5, .threads = 1});
  Group& g = ctx.createGroup("g", 8);
  g.require({Attribute::Color, Attribute::Size});
  g.setActions({Move{}});
  g.setTrail({.length = 3, .width = 0.0f, .taper = 0.5f, .fade = 0.25f});
  Particle p;
  p.velocity = Vec3(2, 0, 0);
  p.color = Vec4(1.0f, 0.5f, 0.25f, 0.8f);
  p.size = 0.2f;
  g.add(p);
  p.position = Vec3(0, 10, 0);  // to be left out by a blocker
  g.add(p);
  for (int s = 0; s < 3; ++s) ctx.step();
  p.position = Vec3(0, -10, 0);  // one point only: no strand
  g.add(p);
  Strands strands;
  const Domain blocker = Domain::sphere(Vec3(3, 10, 0), 1.0f);
  ASSERT_EQ(trailStrands(g, strands, {.blockers = std::span(&blocker, 1)}), 1u);
  ASSERT_EQ(strands.vertexCount(), 3u);
  EXPECT_EQ(strands.position[0], Vec3(3, 0, 0));  // newest first
  EXPECT_EQ(strands.position[2], Vec3(1, 0, 0));
  const float radius[] = {0.2f, 0.15f, 0.1f}, alpha[] = {0.8f, 0.5f, 0.2f};
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(strands.radius[k], radius[k]);
    EXPECT_FLOAT_EQ(strands.color[k].a, alpha[k]);
    EXPECT_EQ(Vec3(strands.color[k]), Vec3(1.0f, 0.5f, 0.25f));
  }
  // A fixed width is the radius at the particle; without a trail there are none.
  g.setTrail({.length = 3, .width = 0.05f, .taper = 1.0f, .fade = 1.0f});
  ASSERT_EQ(trailStrands(g, strands), 2u);  // the blocked one too; the newest has one point
  for (float r : strands.radius) EXPECT_EQ(r, 0.05f);
  g.setTrail({});
  EXPECT_EQ(trailStrands(g, strands), 0u);
  EXPECT_EQ(strands.vertexCount(), 0u);
}
