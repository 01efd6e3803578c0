// Every built-in sample is an effect file: it loads, builds, runs 100 steps and stays finite;
// the embedded copy is the file in samples/effects/; the fountain helper matches the file.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "builtin.hpp"
#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

bool allFinite(const Group& g) {
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(p.position[k]) || !std::isfinite(p.velocity[k])) return false;
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(p.color[k])) return false;
    if (!std::isfinite(p.size) || !std::isfinite(p.age)) return false;
  }
  const Strands& s = g.strands();
  for (std::size_t i = 0; i < s.vertexCount(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(s.position[i][k])) return false;
  return true;
}

}  // namespace

TEST(BuiltinEffects, ListIsComplete) {
  const auto& all = samples::builtinSamples();
  for (const char* name : {"fountain", "fireworks", "snow", "hair", "tornado", "pinball2d",
                           "magnetic", "galaxy", "smoke", "shockwave", "campfire", "comet",
                           "waterfall", "rain_on_glass", "grass", "fur", "rain", "grinder"})
    EXPECT_NE(samples::findSample(name), nullptr) << name;
  for (const auto& s : all) {
    EXPECT_TRUE(s.effect) << s.name << ": " << s.description;
    EXPECT_FALSE(s.description.empty()) << s.name;
    EXPECT_EQ(s.description.find('\n'), std::string::npos) << s.name;
    EXPECT_LE(s.description.size(), 120u) << s.name << ": keep it one line for `flurry list`";
  }
}

class EachBuiltin : public ::testing::TestWithParam<std::string> {};

TEST_P(EachBuiltin, LoadsRuns100StepsAndStaysFinite) {
  const samples::Sample* s = samples::findSample(GetParam());
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->effect) << s->description;
  ContextOptions co = s->effect->contextOptions();
  co.threads = 2;
  Context ctx(co);
  s->build(ctx, 0);
  ASSERT_FALSE(ctx.groups().empty());
  std::uint64_t emitted = 0;
  for (int i = 0; i < 100; ++i) {
    ctx.step();
    if (i % 25 == 24) {
      for (Group* g : ctx.groups()) ASSERT_TRUE(allFinite(*g)) << g->name() << " step " << i;
    }
  }
  for (Group* g : ctx.groups()) {
    ASSERT_TRUE(allFinite(*g)) << g->name();
    emitted += g->stats().emitted;
    EXPECT_EQ(g->stats().droppedAtCapacity, 0u) << g->name() << ": capacity too small";
  }
  EXPECT_GT(emitted, 0u) << "an effect that shows nothing";
}

/// GroupStats' identity: every particle emitted is alive, or was killed (by age, by an
/// absorber, as non-finite), or was dropped at capacity.
void expectAccounted(const Group& g, const std::string& when) {
  const GroupStats& s = g.stats();
  EXPECT_EQ(s.emitted,
            g.size() + s.killedByAge + s.absorbed + s.killedNonFinite + s.droppedAtCapacity)
      << g.name() << " " << when << ": emitted " << s.emitted << ", alive " << g.size()
      << ", killed by age " << s.killedByAge << ", absorbed " << s.absorbed << ", non-finite "
      << s.killedNonFinite << ", dropped " << s.droppedAtCapacity;
}

TEST_P(EachBuiltin, AccountsForEveryParticle) {
  const samples::Sample* s = samples::findSample(GetParam());
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->effect) << s->description;
  EXPECT_TRUE(s->effect->warnings.empty())
      << GetParam() << ": " << s->effect->warnings.front().message();
  ContextOptions co = s->effect->contextOptions();
  co.backend = Backend::Cpu;
  co.threads = 2;
  Context ctx(co);
  // A small capacity, so that dropping at capacity is part of what is checked.
  s->build(ctx, 2000);
  for (int i = 1; i <= 150; ++i) {
    ctx.step();
    if (i % 30 == 0)
      for (const Group* g : ctx.groups()) expectAccounted(*g, "step " + std::to_string(i));
  }
}

TEST(BuiltinEffects, NonFiniteParticlesAreAccounted) {
  // Every particle overflows to infinity within a few steps and is killed as non-finite.
  const Effect fx = parseEffect(R"({"groups": [{"capacity": 100,
      "emitters": [{"bursts": [{"count": 50}], "types": [{"velocity": [0, 3e38, 0]}]}],
      "actions": [{"type": "Gravity", "acceleration": [0, 3e38, 0]}, {"type": "Move"},
                  {"type": "KillOld"}]}]})");
  Context ctx({.threads = 1, .backend = Backend::Cpu});
  Group& g = *fx.build(ctx).at(0);
  ctx.run(10);
  EXPECT_EQ(g.stats().emitted, 50u);
  EXPECT_EQ(g.stats().killedNonFinite, 50u);
  expectAccounted(g, "after 10 steps");
}

std::vector<std::string> builtinNames() {
  std::vector<std::string> names;
  for (const auto& s : samples::builtinSamples()) names.push_back(s.name);
  return names;
}

/// Every particle's state, bit for bit, group after group.
std::vector<std::uint32_t> particleBits(Context& ctx) {
  std::vector<std::uint32_t> bits;
  for (Group* g : ctx.groups())
    for (std::size_t i = 0; i < g->size(); ++i) {
      const Particle p = g->particle(i);
      for (int c = 0; c < 3; ++c) {
        bits.push_back(std::bit_cast<std::uint32_t>(p.position[c]));
        bits.push_back(std::bit_cast<std::uint32_t>(p.velocity[c]));
      }
      for (int c = 0; c < 4; ++c) bits.push_back(std::bit_cast<std::uint32_t>(p.color[c]));
      bits.push_back(std::bit_cast<std::uint32_t>(p.size));
      bits.push_back(std::bit_cast<std::uint32_t>(p.age));
      bits.push_back(p.visible ? 1u : 0u);
      bits.push_back(p.id);
    }
  for (Group* g : ctx.groups()) {  // hair: the strands of particles that died
    const Strands& s = g->strands();
    for (std::size_t i = 0; i < s.vertexCount(); ++i)
      for (int c = 0; c < 3; ++c) bits.push_back(std::bit_cast<std::uint32_t>(s.position[i][c]));
  }
  return bits;
}

// Spatial culling is exact: every group's particles, bit for bit, with it and without it.
TEST_P(EachBuiltin, CullingOnAndOffAreBitwiseIdenticalFor60Steps) {
  const samples::Sample* s = samples::findSample(GetParam());
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->effect) << s->description;
  auto run = [&](bool cull) {
    ContextOptions co = s->effect->contextOptions();
    co.threads = 2;
    co.cull = cull;
    Context ctx(co);
    s->build(ctx, 20000);
    ctx.run(60);
    return particleBits(ctx);
  };
  const auto on = run(true), off = run(false);
  EXPECT_EQ(on.size(), off.size());
  EXPECT_TRUE(on == off);
}

// saveEffect writes what the loader reads back to the same effect: the text is a fixed point
// of load -> save, and the reloaded effect runs bit for bit as the file does.
TEST_P(EachBuiltin, SavesAndReloadsToTheSameEffect) {
  const samples::Sample* s = samples::findSample(GetParam());
  ASSERT_NE(s, nullptr);
  ASSERT_TRUE(s->effect) << s->description;
  const Effect& original = *s->effect;
  const std::string saved = saveEffect(original);
  Effect reloaded;
  try {
    reloaded = parseEffect(saved, GetParam() + ".saved.json");
  } catch (const EffectError& e) {
    FAIL() << e.what() << "\n" << saved;
  }
  EXPECT_EQ(saveEffect(reloaded), saved);
  EXPECT_EQ(reloaded.name, original.name);
  EXPECT_EQ(reloaded.render, original.render);
  ASSERT_EQ(reloaded.groups.size(), original.groups.size());
  for (std::size_t i = 0; i < original.groups.size(); ++i) {
    EXPECT_EQ(reloaded.groups[i].actions.size(), original.groups[i].actions.size());
    EXPECT_EQ(reloaded.groups[i].actions.attributes(), original.groups[i].actions.attributes());
  }
  auto run = [](const Effect& fx) {
    ContextOptions co = fx.contextOptions();
    co.threads = 2;
    Context ctx(co);
    fx.build(ctx, 20000);
    ctx.run(60);
    return particleBits(ctx);
  };
  const auto a = run(original), b = run(reloaded);
  EXPECT_GT(a.size(), 0u);
  EXPECT_TRUE(a == b) << GetParam() << ": the saved effect runs differently\n" << saved;
}

INSTANTIATE_TEST_SUITE_P(All, EachBuiltin, ::testing::ValuesIn(builtinNames()),
                         [](const auto& info) { return info.param; });

TEST(BuiltinEffects, EmbeddedCopiesMatchTheFiles) {
  const std::filesystem::path dir = FLURRY_EFFECTS_DIR;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    ++files;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const Effect fx = loadEffect(entry.path());
    const samples::Sample* s = samples::findSample(fx.name);
    ASSERT_NE(s, nullptr) << entry.path();
    EXPECT_EQ(s->file, entry.path().filename().string()) << "name and file name differ";
    EXPECT_EQ(std::string(s->json), ss.str()) << entry.path() << ": rebuild to re-embed";
  }
  EXPECT_EQ(files, samples::builtinSamples().size());
}

TEST(BuiltinEffects, LoadEffectOrSample) {
  EXPECT_EQ(samples::loadEffectOrSample("fountain").name, "fountain");
  const std::filesystem::path file = std::filesystem::path(FLURRY_EFFECTS_DIR) / "snow.json";
  const Effect fx = samples::loadEffectOrSample(file.string());
  EXPECT_EQ(fx.file, file);
  try {
    samples::loadEffectOrSample("fountian");
    FAIL();
  } catch (const EffectError& e) {
    EXPECT_NE(e.why().find("no built-in effect"), std::string::npos) << e.what();
  }
  EXPECT_THROW(samples::loadEffectOrSample("nowhere/none.json"), EffectError);
}

TEST(BuiltinEffects, BuildFountainMatchesTheEffectFile) {
  // The helper the tests and benchmark use is the fountain file with its rate and lifetime set.
  Context a({.seed = 3, .threads = 1});
  Group& ga = samples::buildFountain(a, 20000, 2000.0, 3.0f);
  Context b({.seed = 3, .threads = 1});
  const samples::Sample* s = samples::findSample("fountain");
  ASSERT_NE(s, nullptr);
  s->build(b, 0);
  Group& gb = b.group("fountain");
  EXPECT_EQ(ga.name(), gb.name());
  for (int i = 0; i < 60; ++i) {
    a.step();
    b.step();
  }
  ASSERT_EQ(ga.size(), gb.size());
  const auto xa = ga.lane(Attribute::Position, 1), xb = gb.lane(Attribute::Position, 1);
  for (std::size_t i = 0; i < ga.size(); ++i) ASSERT_EQ(xa[i], xb[i]) << i;
}

// A quality knob (Niagara's spawn count scale): rates, bursts, births by distance, the
// emitters prime emitters spawn (every level) and capacities scale; the particles made scale
// with them.
TEST(Effect, ScaleSpawningScalesWhatIsBornAndTheRoom) {
  const samples::Sample* galaxy = samples::findSample("galaxy");
  const samples::Sample* fireworks = samples::findSample("fireworks");
  ASSERT_TRUE(galaxy && galaxy->effect && fireworks && fireworks->effect);

  Effect fx = *galaxy->effect;
  fx.scaleSpawning(3.0);
  for (std::size_t g = 0; g < fx.groups.size(); ++g) {
    const EffectGroup &a = galaxy->effect->groups[g], &b = fx.groups[g];
    EXPECT_EQ(b.capacity, a.capacity * 3);
    for (std::size_t e = 0; e < a.emitters.size(); ++e) {
      EXPECT_DOUBLE_EQ(b.emitters[e].rate, a.emitters[e].rate * 3.0);
      for (std::size_t k = 0; k < a.emitters[e].bursts.size(); ++k)
        EXPECT_EQ(b.emitters[e].bursts[k].count, a.emitters[e].bursts[k].count * 3);
    }
  }
  // Three times the stars, within the randomness of their lifetimes.
  auto alive = [](const Effect& e, int steps) {
    Context ctx(e.contextOptions());
    e.build(ctx);
    ctx.run(steps);
    std::size_t n = 0;
    for (const Group* g : ctx.groups()) n += g->size();
    return double(n);
  };
  EXPECT_NEAR(alive(fx, 60) / alive(*galaxy->effect, 60), 3.0, 0.15);

  // The showers' own bursts scale at every level of the chain; the original is untouched.
  Effect fw = *fireworks->effect;
  fw.scaleSpawning(0.5);
  const EmitterSpec* before = &fireworks->effect->groups[0].primeEmitters[0].child;
  const EmitterSpec* after = &fw.groups[0].primeEmitters[0].child;
  int levels = 0;
  for (; before && after; before = before->next.get(), after = after->next.get(), ++levels) {
    EXPECT_DOUBLE_EQ(after->emitter.rate, before->emitter.rate * 0.5);
    EXPECT_FLOAT_EQ(after->emitter.spacing, before->emitter.spacing * 2.0f);
    if (before->deathBurst > 0) {
      EXPECT_EQ(after->deathBurst,
                std::max(1u, std::uint32_t(std::round(before->deathBurst * 0.5))));
    }
  }
  EXPECT_GE(levels, 2);
  EXPECT_NE(fireworks->effect->groups[0].primeEmitters[0].child.next.get(),
            fw.groups[0].primeEmitters[0].child.next.get());

  for (double bad : {0.0, -1.0, std::nan(""), double(INFINITY)})
    EXPECT_THROW(fx.scaleSpawning(bad), InvalidArgument) << bad;
}
