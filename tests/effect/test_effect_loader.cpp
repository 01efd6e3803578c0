// The effect-file loader: what it accepts, and that every kind of bad input is refused with
// the file, the JSON path of the bad field and why.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

/// A minimal valid effect with `group` spliced in as its only group's extra fields.
std::string withGroup(const std::string& group) {
  return R"({"name": "t", "groups": [{"name": "g", "capacity": 100)" +
         (group.empty() ? std::string() : ", " + group) + "}]}";
}

/// Parses `json`, expecting an EffectError; returns it.
EffectError errorOf(const std::string& json, const EffectLoadOptions& opts = {}) {
  try {
    parseEffect(json, "test.json", opts);
  } catch (const EffectError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for: " << json;
  return EffectError("", "", "");
}

}  // namespace

TEST(EffectLoader, MinimalEffect) {
  const Effect fx = parseEffect(withGroup(""), "t.json");
  EXPECT_EQ(fx.name, "t");
  ASSERT_EQ(fx.groups.size(), 1u);
  EXPECT_EQ(fx.groups[0].name, "g");
  EXPECT_EQ(fx.groups[0].capacity, 100u);
  EXPECT_EQ(fx.render, "{}");
  EXPECT_EQ(fx.frames, 300);
  EXPECT_DOUBLE_EQ(fx.dt, 1.0 / 30.0);
}

TEST(EffectLoader, NameDefaultsToFileStem) {
  const Effect fx = parseEffect(R"({"groups": [{"capacity": 1}]})", "dir/sparkle.json");
  EXPECT_EQ(fx.name, "sparkle");
  EXPECT_EQ(fx.groups[0].name, "group0");
}

TEST(EffectLoader, TopLevelFieldsAndRenderKeptAsText) {
  const Effect fx = parseEffect(
      R"({"name": "x", "description": "d", "dt": 0.01, "seed": 18446744073709551615,
          "frames": 7, "groups": [{"capacity": 5}],
          "render": {"sprite": "spark", "camera": {"distance": 3}}})",
      "x.json");
  EXPECT_EQ(fx.description, "d");
  EXPECT_DOUBLE_EQ(fx.dt, 0.01);
  EXPECT_EQ(fx.seed, 18446744073709551615ull);
  EXPECT_EQ(fx.frames, 7);
  EXPECT_NE(fx.render.find("\"spark\""), std::string::npos);
  EXPECT_NE(fx.render.find("\"distance\":3"), std::string::npos);
  const ContextOptions co = fx.contextOptions();
  EXPECT_EQ(co.seed, fx.seed);
  EXPECT_DOUBLE_EQ(co.dt, 0.01);
}

TEST(EffectLoader, CommentsAreAllowed) {
  const Effect fx = parseEffect(R"({
    // a line comment
    "groups": [{"capacity": 3, /* a block comment */ "$comment": "documentation"}]
  })");
  EXPECT_EQ(fx.groups[0].capacity, 3u);
}

TEST(EffectLoader, SyntaxErrorGivesLineAndColumn) {
  const EffectError e = errorOf("{\n  \"groups\": [\n    {\"capacity\": 1,}\n  ]\n}");
  EXPECT_EQ(e.file(), "test.json");
  EXPECT_EQ(e.path(), "");
  EXPECT_NE(std::string(e.what()).find("test.json: "), std::string::npos) << e.what();
  EXPECT_NE(e.why().find("line 3"), std::string::npos) << e.what();
  EXPECT_NE(e.why().find("column"), std::string::npos) << e.what();
}

TEST(EffectLoader, EmptyAndNonObjectInputs) {
  for (const char* s : {"", " ", "[]", "3", "null", "\"x\"", "{}", R"({"groups": []})",
                        R"({"groups": {}})", R"({"groups": [3]})"}) {
    const EffectError e = errorOf(s);
    EXPECT_FALSE(e.why().empty()) << s;
  }
}

TEST(EffectLoader, UnknownFieldSuggestsNearestName) {
  const EffectError e = errorOf(withGroup(R"("emiters": [])"));
  EXPECT_EQ(e.path(), "groups[0].emiters");
  EXPECT_STREQ(e.what(), "test.json: groups[0].emiters: unknown field; did you mean \"emitters\"?");
  const EffectError top = errorOf(R"({"grups": [], "groups": [{"capacity": 1}]})");
  EXPECT_EQ(top.path(), "grups");
  EXPECT_NE(top.why().find("did you mean \"groups\""), std::string::npos);
  // Far from every known name: no suggestion.
  const EffectError far = errorOf(withGroup(R"("zzzzzzzzzzzz": 1)"));
  EXPECT_EQ(far.why(), "unknown field");
}

TEST(EffectLoader, InvalidEmitterRateNamesItsPath) {
  const std::string em = R"({"rate": 1})";
  const EffectError e =
      errorOf(withGroup(R"("emitters": [)" + em + "," + em + R"(, {"rate": -5}])"));
  EXPECT_STREQ(e.what(), "test.json: groups[0].emitters[2].rate: must be finite and >= 0");
  EXPECT_EQ(e.file(), "test.json");
  EXPECT_EQ(e.path(), "groups[0].emitters[2].rate");
  EXPECT_EQ(e.parameter(), e.path());
  // It is an InvalidArgument (and so a flurry::Error) for callers that catch those.
  EXPECT_THROW(parseEffect(withGroup(R"("emitters": [{"rate": -1}])")), InvalidArgument);
}

TEST(EffectLoader, TypeErrorsSayWhatWasExpected) {
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"rate": "fast"}])")).why(),
            "expected a number or \"inf\", got the string \"fast\"");
  EXPECT_EQ(errorOf(R"({"groups": [{"capacity": -1}]})").path(), "groups[0].capacity");
  EXPECT_EQ(errorOf(R"({"groups": [{"capacity": 1.5}]})").path(), "groups[0].capacity");
  EXPECT_EQ(errorOf(R"({"groups": [{"capacity": 0}]})").path(), "groups[0].capacity");
  EXPECT_EQ(errorOf(R"({"groups": [{"capacity": 1e12}]})").path(), "groups[0].capacity");
  EXPECT_EQ(errorOf(R"({"groups": [{}]})").why(), "missing (the most particles the group holds)");
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"position": [1, 2]}])")).path(),
            "groups[0].emitters[0].position");
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"position": [1, 2, "z"]}])")).path(),
            "groups[0].emitters[0].position[2]");
  EXPECT_NE(errorOf(withGroup(R"("emitters": [{"rate": 1e400}])")).why().find("overflow"),
            std::string::npos);
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"spacing": 1e39}])")).why(),
            "out of range for a float");
  EXPECT_EQ(errorOf(R"({"dt": 0, "groups": [{"capacity": 1}]})").path(), "dt");
  EXPECT_EQ(errorOf(R"({"frames": 0, "groups": [{"capacity": 1}]})").path(), "frames");
  EXPECT_EQ(errorOf(R"({"version": 2, "groups": [{"capacity": 1}]})").path(), "version");
  EXPECT_EQ(errorOf(R"({"description": "a\nb", "groups": [{"capacity": 1}]})").path(),
            "description");
}

TEST(EffectLoader, NamesAreSafeForFileNames) {
  // Names become output file names: nothing that could leave the output folder.
  for (const char* bad : {"", "../x", "a/b", ".hidden", "a b", "-x"}) {
    EXPECT_EQ(
        errorOf(std::string(R"({"name": ")") + bad + R"(", "groups": [{"capacity": 1}]})").path(),
        "name")
        << bad;
    EXPECT_EQ(
        errorOf(std::string(R"({"groups": [{"name": ")") + bad + R"(", "capacity": 1}]})").path(),
        "groups[0].name")
        << bad;
  }
  EXPECT_EQ(parseEffect(R"({"groups": [{"capacity": 1}]})", "my effect (2).json").name,
            "my_effect__2_");
  EXPECT_EQ(parseEffect(R"({"groups": [{"capacity": 1}]})", "/x/.json").name, "effect");
}

TEST(EffectLoader, DeepRenderObjectIsRefused) {
  const std::string deep = std::string(100000, '[') + "1" + std::string(100000, ']');
  const EffectError e = errorOf(R"({"groups": [{"capacity": 1}], "render": {"x": )" + deep + "}}");
  EXPECT_EQ(e.path(), "render");
}

TEST(EffectLoader, DuplicateGroupNames) {
  const EffectError e =
      errorOf(R"({"groups": [{"name": "a", "capacity": 1}, {"name": "a", "capacity": 1}]})");
  EXPECT_EQ(e.path(), "groups[1].name");
}

TEST(EffectLoader, FuzzyForms) {
  const Effect fx = parseEffect(withGroup(R"("emitters": [{"types": [
      {"size": 2, "mass": [3, 0.5], "lifetime": {"center": 60, "percent": 25},
       "charge": {"center": 1, "spread": 0.1, "distribution": "normal"}}]}])"));
  const ParticleType& t = fx.groups[0].emitters[0].types[0];
  EXPECT_EQ(t.size.center, 2.0f);
  EXPECT_EQ(t.size.spread, 0.0f);
  EXPECT_EQ(t.mass.center, 3.0f);
  EXPECT_EQ(t.mass.spread, 0.5f);
  EXPECT_EQ(t.lifetime.center, 60.0f);
  EXPECT_EQ(t.lifetime.spread, 15.0f);
  EXPECT_EQ(t.charge.distribution, Fuzzy::Distribution::Normal);
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"types": [{"size": [1, -1]}]}])")).path(),
            "groups[0].emitters[0].types[0].size");
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"types": [{"size": {"center": 1, "spread": 1,
      "percent": 3}}]}])"))
                .path(),
            "groups[0].emitters[0].types[0].size.percent");
  const EffectError d = errorOf(
      withGroup(R"("emitters": [{"types": [{"size": {"center": 1, "distribution": "normel"}}]}])"));
  EXPECT_EQ(d.path(), "groups[0].emitters[0].types[0].size.distribution");
  EXPECT_NE(d.why().find("did you mean \"normal\""), std::string::npos);
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"types": [{"lifetime": 0}]}])")).path(),
            "groups[0].emitters[0].types[0].lifetime");
}

TEST(EffectLoader, EveryDomainType) {
  const Effect fx = parseEffect(withGroup(R"("actions": [
    {"type": "Sink", "region": [1, 2, 3]},
    {"type": "Sink", "region": {"type": "point", "point": [1, 2, 3]}},
    {"type": "Sink", "region": {"type": "line", "p0": [0, 0, 0], "p1": [1, 0, 0]}},
    {"type": "Sink", "region": {"type": "triangle", "p0": [0, 0, 0], "p1": [1, 0, 0], "p2": [0, 1, 0]}},
    {"type": "Sink", "region": {"type": "plane", "normal": [0, 1, 0]}},
    {"type": "Sink", "region": {"type": "rectangle", "u": [1, 0, 0], "v": [0, 0, 1]}},
    {"type": "Sink", "region": {"type": "disc", "normal": [0, 1, 0], "outerRadius": 2, "innerRadius": 1}},
    {"type": "Sink", "region": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}},
    {"type": "Sink", "region": {"type": "sphere", "outerRadius": 1}},
    {"type": "Sink", "region": {"type": "cylinder", "p0": [0, 0, 0], "p1": [0, 1, 0], "outerRadius": 1}},
    {"type": "Sink", "region": {"type": "cone", "base": [0, 1, 0], "outerRadius": 1}},
    {"type": "Sink", "region": {"type": "blob", "stddev": 0.5}},
    {"type": "Sink", "region": {"type": "mesh", "vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
                                "triangles": [[0,2,1],[0,1,3],[0,3,2],[1,2,3]]}},
    {"type": "Sink", "region": {"type": "union", "parts": [{"type": "sphere", "outerRadius": 1},
                                                           {"type": "box", "min": [2,0,0], "max": [3,1,1]}]}}
  ])"));
  const auto& as = fx.groups[0].actions.actions();
  ASSERT_EQ(as.size(), 14u);
  const char* names[] = {"point", "point",  "line",     "triangle", "plane", "rectangle", "disc",
                         "box",   "sphere", "cylinder", "cone",     "blob",  "mesh",      "union"};
  for (std::size_t i = 0; i < as.size(); ++i)
    EXPECT_STREQ(std::get<Sink>(as[i]).region.name(), names[i]) << i;
  const auto& sphere = std::get<SphereDomain>(std::get<Sink>(as[8]).region.shape());
  EXPECT_EQ(sphere.outerRadius, 1.0f);
  EXPECT_EQ(sphere.innerRadius, 0.0f);
}

TEST(EffectLoader, DomainErrors) {
  auto sinkOf = [](const std::string& region) {
    return withGroup(R"("actions": [{"type": "Sink", "region": )" + region + "}]");
  };
  const EffectError unknown = errorOf(sinkOf(R"({"type": "spere", "outerRadius": 1})"));
  EXPECT_EQ(unknown.path(), "groups[0].actions[0].region.type");
  EXPECT_NE(unknown.why().find("did you mean \"sphere\""), std::string::npos);
  const EffectError missing = errorOf(sinkOf(R"({"type": "sphere"})"));
  EXPECT_EQ(missing.path(), "groups[0].actions[0].region.outerRadius");
  // The core's factory check, reported at the field.
  const EffectError bad = errorOf(sinkOf(R"({"type": "sphere", "outerRadius": -1})"));
  EXPECT_EQ(bad.path(), "groups[0].actions[0].region.outerRadius") << bad.what();
  const EffectError field = errorOf(sinkOf(R"({"type": "sphere", "outerRadius": 1, "raduis": 2})"));
  EXPECT_EQ(field.path(), "groups[0].actions[0].region.raduis");
  const EffectError mesh = errorOf(
      sinkOf(R"({"type": "mesh", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,3]]})"));
  EXPECT_EQ(mesh.path(), "groups[0].actions[0].region.triangles[0][2]");
  EXPECT_FALSE(errorOf(sinkOf(R"({"type": "union", "parts": []})")).why().empty());
  EXPECT_FALSE(errorOf(sinkOf(R"({"type": "box", "min": [0,0,0], "max": [0,1,1]})")).why().empty());
  // Deep nesting is refused, not recursed into.
  std::string deep = R"({"type": "sphere", "outerRadius": 1})";
  for (int i = 0; i < 40; ++i) deep = R"({"type": "union", "parts": [)" + deep + "]}";
  EXPECT_NE(errorOf(sinkOf(deep)).why().find("nested"), std::string::npos);
}

TEST(EffectLoader, ActionsByName) {
  const Effect fx = parseEffect(withGroup(R"("actions": [
    {"type": "Gravity", "acceleration": [0, -2, 0], "falloff": {"center": [1, 0, 0], "radius": 5}},
    {"type": "Damping", "rate": [1, 2, 3]},
    {"type": "OrbitPoint", "magnitude": 3, "maxRadius": "inf"},
    {"type": "Vortex", "aroundSpeed": 4, "upSpeed": 1},
    {"type": "Turbulence", "amplitude": 2, "octaves": 3, "drift": [1, 0, 0]},
    {"type": "MagneticField", "field": [0, 0, 2]},
    {"type": "SpeedClamp", "maxSpeed": 10},
    {"type": "ColorOverLife", "keys": [{"t": 0, "color": [1, 0, 0]}, {"t": 1, "color": [0, 0, 1, 0]}]},
    {"type": "SizeOverLife", "keys": [{"t": 0, "size": 1}, {"t": 1, "size": 2}], "mode": "replace"},
    {"type": "Bounce", "surface": {"type": "plane", "normal": [0, 1, 0]}, "restitution": 0.5, "friction": 0.25},
    {"type": "Sink", "region": {"type": "sphere", "outerRadius": 9}, "mode": "outside", "passThrough": 0.5},
    {"type": "Block", "region": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}},
    {"type": "Move"},
    {"type": "KillOld"}
  ])"));
  const auto& as = fx.groups[0].actions.actions();
  ASSERT_EQ(as.size(), 14u);
  EXPECT_EQ(std::get<Gravity>(as[0]).acceleration.y, -2.0f);
  EXPECT_EQ(std::get<Gravity>(as[0]).falloff.radius, 5.0f);
  EXPECT_EQ(std::get<Damping>(as[1]).rate.z, 3.0f);
  EXPECT_TRUE(std::isinf(std::get<OrbitPoint>(as[2]).maxRadius));
  EXPECT_EQ(std::get<Vortex>(as[3]).aroundSpeed, 4.0f);
  EXPECT_EQ(std::get<Turbulence>(as[4]).octaves, 3);
  EXPECT_EQ(std::get<MagneticField>(as[5]).field.z, 2.0f);
  EXPECT_EQ(std::get<SpeedClamp>(as[6]).maxSpeed, 10.0f);
  const auto& col = std::get<ColorOverLife>(as[7]);
  ASSERT_EQ(col.keys.size(), 2u);
  EXPECT_EQ(col.keys[0].color.w, 1.0f);  // [r, g, b] is opaque
  EXPECT_EQ(col.keys[1].color.w, 0.0f);
  EXPECT_EQ(std::get<SizeOverLife>(as[8]).keys[1].size, 2.0f);
  EXPECT_EQ(col.mode, OverLifeMode::Multiply);  // the default
  EXPECT_EQ(std::get<SizeOverLife>(as[8]).mode, OverLifeMode::Replace);
  EXPECT_EQ(std::get<Bounce>(as[9]).friction, 0.25f);
  EXPECT_EQ(std::get<Sink>(as[10]).mode, Sink::Mode::Outside);
  EXPECT_EQ(std::get<Sink>(as[10]).passThrough, 0.5f);
  EXPECT_TRUE(std::holds_alternative<Block>(as[11]));
  EXPECT_TRUE(std::holds_alternative<Move>(as[12]));
}

TEST(EffectLoader, ActionErrors) {
  const EffectError unknown = errorOf(withGroup(R"("actions": [{"type": "Gravty"}])"));
  EXPECT_EQ(unknown.path(), "groups[0].actions[0].type");
  EXPECT_NE(unknown.why().find("did you mean \"Gravity\""), std::string::npos);
  const EffectError field = errorOf(
      withGroup(R"("actions": [{"type": "Move"}, {"type": "Gravity", "acceleraton": [0, 1, 0]}])"));
  EXPECT_EQ(field.path(), "groups[0].actions[1].acceleraton");
  EXPECT_NE(field.why().find("did you mean \"acceleration\""), std::string::npos);
  // The core's validation, rewritten to the JSON path of the field.
  const EffectError friction = errorOf(withGroup(
      R"("actions": [{"type": "Move"}, {"type": "Bounce", "surface": {"type": "plane", "normal": [0,1,0]}, "friction": 2}])"));
  EXPECT_EQ(friction.path(), "groups[0].actions[1].friction") << friction.what();
  EXPECT_EQ(errorOf(withGroup(R"("actions": [{"type": "Bounce"}])")).path(),
            "groups[0].actions[0].surface");
  EXPECT_NE(errorOf(withGroup(R"("actions": [{"type": "Callback"}])")).why().find("C++"),
            std::string::npos);
  const EffectError mode =
      errorOf(withGroup(R"("actions": [{"type": "Sink", "region": [0, 0, 0], "mode": "hitt"}])"));
  EXPECT_EQ(mode.path(), "groups[0].actions[0].mode");
  EXPECT_NE(mode.why().find("did you mean \"hit\""), std::string::npos);
  EXPECT_EQ(errorOf(withGroup(R"("actions": [{"gravity": 1}])")).path(),
            "groups[0].actions[0].type");
  EXPECT_EQ(errorOf(withGroup(R"("actions": {"type": "Move"})")).path(), "groups[0].actions");
}

// A Sink says inside or outside by "mode" alone; the classic API's "killInside": false, once a
// second switch beside it, still reads as mode "outside" (with a warning), and is refused
// where it would contradict the mode.
TEST(EffectLoader, SinkKillInsideIsADeprecatedAliasOfModeOutside) {
  auto sink = [](const std::string& fields) {
    return withGroup(
        R"("actions": [{"type": "Sink", "region": {"type": "sphere", "outerRadius": 1})" + fields +
        "}]");
  };
  const Effect fx = parseEffect(sink(R"(, "killInside": false)"), "k.json");
  EXPECT_EQ(std::get<Sink>(fx.groups[0].actions.actions()[0]).mode, Sink::Mode::Outside);
  bool warned = false;
  for (const EffectWarning& w : fx.warnings)
    warned |=
        w.path == "groups[0].actions[0].killInside" && w.why.find("\"mode\"") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_EQ(
      std::get<Sink>(
          parseEffect(sink(R"(, "killInside": true)"), "k.json").groups[0].actions.actions()[0])
          .mode,
      Sink::Mode::Inside);
  for (const char* mode : {"outside", "enter", "leave"}) {
    const EffectError e =
        errorOf(sink(R"(, "killInside": false, "mode": ")" + std::string(mode) + "\""));
    EXPECT_EQ(e.path(), "groups[0].actions[0].killInside") << mode;
    EXPECT_NE(e.why().find("use \"mode\""), std::string::npos) << e.why();
  }
  // Saved, it is the mode alone.
  const std::string saved = saveEffect(fx);
  EXPECT_EQ(saved.find("killInside"), std::string::npos) << saved;
  EXPECT_NE(saved.find("\"outside\""), std::string::npos) << saved;
}

// Death emitters: read, linked to a group of the effect (the cause indexed as the file writes
// the list, past a mode2d plane), saved and read back the same, built per instance (each
// instance's splash fed by its own drops), and refused with the JSON path when they name no
// group or no action.
TEST(EffectLoader, DeathEmitters) {
  const std::string json = R"({"name": "rain", "dt": 0.125, "groups": [
    {"name": "splash", "capacity": 1000,
     "deathEmitters": [{"source": "drops", "count": 2, "inheritVelocity": 0.5, "cause": 1,
                        "types": [{"velocity": [0, 1, 0], "lifetime": 1}]}],
     "actions": [{"type": "Move"}, {"type": "KillOld"}]},
    {"name": "drops", "capacity": 100, "mode2d": true,
     "emitters": [{"bursts": [{"time": 0, "count": 10}], "shape": [0, 5, 0],
                   "types": [{"velocity": [1, -4, 0], "lifetime": 10}]}],
     "actions": [{"type": "Move"},
                 {"type": "Sink", "region": {"type": "box", "min": [-1000, -100, -1],
                                             "max": [1000, 0, 1]}}]}]})";
  const Effect fx = parseEffect(json, "rain.json");
  ASSERT_EQ(fx.groups[0].deathEmitters.size(), 1u);
  const DeathEmitter& de = fx.groups[0].deathEmitters[0];
  EXPECT_EQ(de.source, "drops");
  EXPECT_EQ(de.count.center, 2.0f);
  // mode2d put its Constrain2D before Move: the Sink, written second, is third in the list.
  ASSERT_EQ(fx.groups[1].actions.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<Sink>(fx.groups[1].actions.actions()[2]));
  EXPECT_EQ(de.cause, 2);
  const std::string saved = saveEffect(fx);
  EXPECT_EQ(saveEffect(parseEffect(saved, "saved.json")), saved);
  EXPECT_EQ(parseEffect(saved, "saved.json").groups[0].deathEmitters[0].cause, 2);

  Context ctx(fx.contextOptions());
  EffectInstance a = fx.instantiate(ctx, "a");
  EffectInstance b = fx.instantiate(ctx, "b");
  b.setTransform({{100, 0, 0}, glm::quat(1, 0, 0, 0), 1.0f});
  ctx.run(12);  // the drops fall 5 m at 4 m/s: through the floor in the tenth step
  Group& splashA = ctx.group("splash@a");
  Group& splashB = ctx.group("splash@b");
  EXPECT_EQ(splashA.size(), 20u);
  EXPECT_EQ(splashB.size(), 20u);
  for (std::size_t i = 0; i < splashB.size(); ++i) EXPECT_GT(splashB.particle(i).position.x, 50);
  for (std::size_t i = 0; i < splashA.size(); ++i) EXPECT_LT(splashA.particle(i).position.x, 50);

  auto withDeath = [](const std::string& fields) {
    return R"({"name": "t", "groups": [{"name": "g", "capacity": 10, "actions": [{"type": "Move"}],
               "deathEmitters": [{)" +
           fields + "}]}]}";
  };
  const EffectError nobody = errorOf(withDeath(R"("source": "h")"));
  EXPECT_EQ(nobody.path(), "groups[0].deathEmitters[0].source") << nobody.what();
  EXPECT_NE(nobody.why().find("its groups: g"), std::string::npos) << nobody.what();
  const EffectError noAction = errorOf(withDeath(R"("source": "g", "cause": 1)"));
  EXPECT_EQ(noAction.path(), "groups[0].deathEmitters[0].cause") << noAction.what();
  EXPECT_EQ(errorOf(withDeath(R"("source": "g", "cause": -2)")).path(),
            "groups[0].deathEmitters[0].cause");
  EXPECT_EQ(errorOf(withDeath(R"("source": "g", "count": -1)")).path(),
            "groups[0].deathEmitters[0].count");
  EXPECT_EQ(errorOf(withDeath(R"("count": 1)")).path(), "groups[0].deathEmitters[0].source");
  EXPECT_NO_THROW(parseEffect(withDeath(R"("source": "g", "cause": 0)"), "t.json"));
  // On collision: the cause must be a Bounce; "on" takes "death" or "collision".
  const EffectError notBounce =
      errorOf(withDeath(R"("source": "g", "on": "collision", "cause": 0)"));
  EXPECT_EQ(notBounce.path(), "groups[0].deathEmitters[0].cause") << notBounce.what();
  EXPECT_NE(notBounce.why().find("not a Bounce"), std::string::npos) << notBounce.what();
  EXPECT_EQ(errorOf(withDeath(R"("source": "g", "on": "impact")")).path(),
            "groups[0].deathEmitters[0].on");
  const Effect onHit = parseEffect(withDeath(R"("source": "g", "on": "collision")"), "t.json");
  EXPECT_EQ(onHit.groups[0].deathEmitters[0].on, DeathEmitter::Trigger::Collision);
  const std::string savedOnHit = saveEffect(onHit);
  EXPECT_NE(savedOnHit.find(R"("on": "collision")"), std::string::npos) << savedOnHit;
  EXPECT_EQ(saveEffect(parseEffect(savedOnHit, "saved.json")), savedOnHit);
  // On birth: no cause.
  const Effect onBirth = parseEffect(withDeath(R"("source": "g", "on": "birth")"), "t.json");
  EXPECT_EQ(onBirth.groups[0].deathEmitters[0].on, DeathEmitter::Trigger::Birth);
  EXPECT_NE(saveEffect(onBirth).find(R"("on": "birth")"), std::string::npos);
  const EffectError birthCause = errorOf(withDeath(R"("source": "g", "on": "birth", "cause": 0)"));
  EXPECT_EQ(birthCause.path(), "groups[0].deathEmitters[0].cause") << birthCause.what();
}

TEST(EffectLoader, EmittersAndPrimeEmitters) {
  const Effect fx = parseEffect(withGroup(R"(
    "emitters": [{"name": "e", "shape": {"type": "sphere", "outerRadius": 1}, "rate": 10.5,
                  "bursts": [{"time": 1, "count": 5, "interval": 0.5, "repeat": 3}],
                  "path": [{"time": 0, "position": [0, 0, 0]}, {"time": 2, "position": [2, 0, 0]}],
                  "pathLoop": true, "start": 0.5, "stop": 9, "spacing": 0.1,
                  "normalSpeed": [1, 0.1],
                  "types": [{"weight": 2, "velocity": [0, 1, 0]}, {"weight": 1}]}],
    "primeEmitters": [{"name": "p", "rate": 2, "child": {
        "lifetime": 1, "deathChildren": 3, "emitter": {"rate": 50},
        "next": {"lifetime": 0.5, "deathBurst": 10, "drag": 1}}}])"));
  const Emitter& e = fx.groups[0].emitters[0];
  EXPECT_EQ(e.name, "e");
  EXPECT_EQ(e.rate, 10.5);
  ASSERT_EQ(e.bursts.size(), 1u);
  EXPECT_EQ(e.bursts[0].repeat, 3u);
  ASSERT_EQ(e.path.size(), 2u);
  EXPECT_EQ(e.path[1].position.x, 2.0f);
  EXPECT_TRUE(e.pathLoop);
  EXPECT_EQ(e.stop, 9.0);
  ASSERT_EQ(e.types.size(), 2u);
  EXPECT_EQ(e.types[0].weight, 2.0f);
  const PrimeEmitter& p = fx.groups[0].primeEmitters[0];
  EXPECT_EQ(p.child.deathChildren, 3u);
  ASSERT_TRUE(p.child.next);
  EXPECT_EQ(p.child.next->deathBurst, 10u);
  EXPECT_EQ(p.child.emitter.rate, 50.0);
  EXPECT_FALSE(p.pathLoop);
  // Written back and read again: the loop stays, and a path that does not loop says nothing.
  const std::string saved = saveEffect(fx);
  EXPECT_NE(saved.find("\"pathLoop\": true"), std::string::npos) << saved;
  EXPECT_EQ(saved.find("pathLoop"), saved.rfind("pathLoop")) << saved;
  EXPECT_TRUE(parseEffect(saved, "saved.json").groups[0].emitters[0].pathLoop);
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"pathLoop": true}])")).path(),
            "groups[0].emitters[0].pathLoop");
  // deathChildren without a next level: the core's check, at the JSON path.
  const EffectError noNext =
      errorOf(withGroup(R"("primeEmitters": [{"rate": 1, "child": {"deathChildren": 2}}])"));
  EXPECT_EQ(noNext.path(), "groups[0].primeEmitters[0].child.next") << noNext.what();
  EXPECT_EQ(errorOf(withGroup(R"("primeEmitters": [{"rate": 1}])")).path(),
            "groups[0].primeEmitters[0].child");
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"types": []}])")).path(),
            "groups[0].emitters[0].types");
  EXPECT_EQ(errorOf(withGroup(R"("emitters": [{"bursts": [{"time": 1}]}])")).path(),
            "groups[0].emitters[0].bursts[0].count");
  std::string deep = R"({"lifetime": 1})";
  for (int i = 0; i < 40; ++i) deep = R"({"lifetime": 1, "next": )" + deep + "}";
  EXPECT_FALSE(
      errorOf(withGroup(R"("primeEmitters": [{"rate": 1, "child": )" + deep + "}]")).why().empty());
}

TEST(EffectLoader, Mode2dInsertsTheConstraintAndSetsSegmentPlanes) {
  const Effect fx = parseEffect(withGroup(R"("mode2d": {"point": [0, 0, 1], "normal": [0, 0, 2]},
    "actions": [{"type": "Gravity"}, {"type": "Bounce", "surface": {"type": "line", "p0": [0,0,1], "p1": [1,0,1]}},
                {"type": "Move"}])"));
  const auto& as = fx.groups[0].actions.actions();
  ASSERT_EQ(as.size(), 4u);
  ASSERT_TRUE(std::holds_alternative<Constrain2D>(as[1]));
  EXPECT_EQ(std::get<Constrain2D>(as[1]).normal, Vec3(0, 0, 1));
  EXPECT_EQ(std::get<Constrain2D>(as[1]).point, Vec3(0, 0, 1));
  EXPECT_EQ(std::get<Bounce>(as[2]).planeNormal, Vec3(0, 0, 1));
  // true: the z = 0 plane, appended when nothing moves.
  const Effect b = parseEffect(withGroup(R"("mode2d": true, "actions": [{"type": "Gravity"}])"));
  ASSERT_EQ(b.groups[0].actions.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<Constrain2D>(b.groups[0].actions.actions()[1]));
  EXPECT_EQ(errorOf(withGroup(R"("mode2d": {"normal": [0, 0, 0]})")).path(),
            "groups[0].mode2d.normal");
  EXPECT_EQ(parseEffect(withGroup(R"("mode2d": false)")).groups[0].actions.size(), 0u);
}

TEST(EffectLoader, IntegratorAndSubsteps) {
  const Effect fx = parseEffect(withGroup(R"("integrator": "RK4",
      "substeps": {"maxStep": 0.01, "maxDistance": 0.5, "maxSubsteps": 8},
      "actions": [{"type": "Gravity"}, {"type": "Move"}])"));
  const ActionList& a = fx.groups[0].actions;
  EXPECT_EQ(a.integrator(), Integrator::RK4);
  EXPECT_EQ(a.substeps().maxStep, 0.01);
  EXPECT_EQ(a.substeps().maxDistance, 0.5f);
  EXPECT_EQ(a.substeps().maxSubsteps, 8u);
  const EffectError e = errorOf(withGroup(R"("integrator": "RK5")"));
  EXPECT_EQ(e.path(), "groups[0].integrator");
  EXPECT_NE(e.why().find("did you mean \"RK4\""), std::string::npos) << e.what();
  EXPECT_EQ(
      errorOf(withGroup(R"("substeps": {"maxStep": -1})")).path().rfind("groups[0].substeps", 0),
      0u);
}

TEST(EffectLoader, HairAndRequire) {
  const Effect fx = parseEffect(withGroup(R"("hair": {"every": 2, "maxVertices": 10},
                                              "require": ["color", "size"])"));
  EXPECT_TRUE(fx.groups[0].hair.enabled);
  EXPECT_EQ(fx.groups[0].hair.every, 2u);
  EXPECT_EQ(fx.groups[0].hair.maxVertices, 10u);
  EXPECT_TRUE(fx.groups[0].require.has(Attribute::Color));
  EXPECT_TRUE(fx.groups[0].require.has(Attribute::Size));
  EXPECT_TRUE(parseEffect(withGroup(R"("hair": true)")).groups[0].hair.enabled);
  const EffectError e = errorOf(withGroup(R"("require": ["colour"])"));
  EXPECT_EQ(e.path(), "groups[0].require[0]");
  EXPECT_NE(e.why().find("did you mean \"color\""), std::string::npos);
  EXPECT_EQ(errorOf(withGroup(R"("hair": {"every": 0})")).path(), "groups[0].hair.every");
}

TEST(EffectLoader, Trail) {
  const Effect fx = parseEffect(
      withGroup(R"("trail": {"length": 12, "width": 0.02, "taper": 0.3, "fade": 0.1})"));
  const TrailOptions& t = fx.groups[0].trail;
  EXPECT_EQ(t.length, 12u);
  EXPECT_EQ(t.width, 0.02f);
  EXPECT_EQ(t.taper, 0.3f);
  EXPECT_EQ(t.fade, 0.1f);
  // Saved and loaded again, the same; built, the group keeps it.
  const std::string saved = saveEffect(fx);
  EXPECT_NE(saved.find("\"trail\""), std::string::npos);
  EXPECT_EQ(saveEffect(parseEffect(saved, "saved.json")), saved);
  Context ctx(fx.contextOptions());
  fx.build(ctx);
  EXPECT_EQ(ctx.groups()[0]->trail().length, 12u);
  EXPECT_EQ(parseEffect(withGroup(R"("trail": {"length": 3})")).groups[0].trail.taper, 1.0f);
  EXPECT_EQ(errorOf(withGroup(R"("trail": {"length": 300})")).path(), "groups[0].trail.length");
  EXPECT_EQ(errorOf(withGroup(R"("trail": {"length": 3, "width": -1})")).path(),
            "groups[0].trail.width");
  const EffectError e = errorOf(withGroup(R"("trail": {"lenght": 3})"));
  EXPECT_EQ(e.path(), "groups[0].trail.lenght");
  EXPECT_NE(e.why().find("did you mean \"length\""), std::string::npos);
}

TEST(EffectLoader, BudgetPolicy) {
  const Effect fx = parseEffect(withGroup(R"("budget": "scaleEmission")"));
  EXPECT_EQ(fx.groups[0].budget, BudgetPolicy::ScaleEmission);
  const std::string saved = saveEffect(fx);
  EXPECT_NE(saved.find(R"("budget": "scaleEmission")"), std::string::npos) << saved;
  EXPECT_EQ(saveEffect(parseEffect(saved, "saved.json")), saved);
  Context ctx(fx.contextOptions());
  fx.build(ctx);
  EXPECT_EQ(ctx.groups()[0]->budgetPolicy(), BudgetPolicy::ScaleEmission);
  const EffectError e = errorOf(withGroup(R"("budget": "dropOlder")"));
  EXPECT_EQ(e.path(), "groups[0].budget");
  EXPECT_NE(e.why().find("did you mean \"dropOldest\""), std::string::npos) << e.what();
}

TEST(EffectLoader, DenseSampledField) {
  const Effect fx =
      parseEffect(withGroup(R"("actions": [{"type": "SampledField", "mode": "velocity",
      "field": {"origin": [1, 2, 3], "voxelSize": 0.5, "dims": [2, 1, 1], "data": [[1, 0, 0], [0, 1, 0]]}}])"));
  const auto& f = std::get<SampledField>(fx.groups[0].actions.actions()[0]);
  ASSERT_TRUE(f.field);
  EXPECT_EQ(f.mode, SampledField::Mode::Velocity);
  EXPECT_EQ(f.field->dims, glm::ivec3(2, 1, 1));
  EXPECT_EQ(f.field->data[1], Vec3(0, 1, 0));
  EXPECT_EQ(f.field->origin, Vec3(1, 2, 3));
  const EffectError count = errorOf(withGroup(R"("actions": [{"type": "SampledField",
      "field": {"dims": [2, 2, 2], "data": [[1, 0, 0]]}}])"));
  EXPECT_EQ(count.path(), "groups[0].actions[0].field.data");
  const EffectError huge = errorOf(withGroup(R"("actions": [{"type": "SampledField",
      "field": {"dims": [100000, 100000, 100000], "data": []}}])"));
  EXPECT_EQ(huge.path(), "groups[0].actions[0].field.dims");
}

TEST(EffectLoader, VdbFieldNeedsAResolver) {
  const std::string json = withGroup(
      R"("actions": [{"type": "SampledField", "field": {"vdb": "wind.vdb", "grid": "vel"}}])");
  const EffectError none = errorOf(json);
  EXPECT_EQ(none.path(), "groups[0].actions[0].field.vdb");
  EXPECT_NE(none.why().find("flurry::vdb"), std::string::npos);

  EffectLoadOptions opts;
  opts.baseDir = "/some/dir";
  std::filesystem::path seenPath;
  std::string seenGrid;
  opts.fieldResolver = [&](const std::filesystem::path& p, const std::string& grid) {
    seenPath = p;
    seenGrid = grid;
    VectorField f;
    f.dims = glm::ivec3(1);
    f.data = {Vec3(1, 2, 3)};
    return f;
  };
  const Effect fx = parseEffect(json, "t.json", opts);
  EXPECT_EQ(seenPath, std::filesystem::path("/some/dir/wind.vdb"));
  EXPECT_EQ(seenGrid, "vel");
  EXPECT_EQ(std::get<SampledField>(fx.groups[0].actions.actions()[0]).field->data[0],
            Vec3(1, 2, 3));

  // The resolver's failure is reported at the field.
  opts.fieldResolver = [](const std::filesystem::path& p, const std::string&) -> VectorField {
    throw IoError(p.string(), "no such grid");
  };
  const EffectError failed = errorOf(json, opts);
  EXPECT_EQ(failed.path(), "groups[0].actions[0].field.vdb");
  EXPECT_NE(failed.why().find("no such grid"), std::string::npos);
  // A bad field from the resolver is caught too.
  opts.fieldResolver = [](const std::filesystem::path&, const std::string&) {
    return VectorField{};
  };
  EXPECT_EQ(errorOf(json, opts).path().rfind("groups[0].actions[0].field", 0), 0u);
}

TEST(EffectLoader, LoadEffectFromDisk) {
  const auto dir = std::filesystem::temp_directory_path() / "flurry_effect_test";
  std::filesystem::create_directories(dir);
  const auto file = dir / "disk.json";
  { std::ofstream(file) << withGroup(""); }
  const Effect fx = loadEffect(file);
  EXPECT_EQ(fx.file, file);
  try {
    loadEffect(dir / "missing.json");
    FAIL();
  } catch (const EffectError& e) {
    EXPECT_EQ(e.file(), (dir / "missing.json").string());
    EXPECT_NE(e.why().find("cannot open"), std::string::npos);
  }
  { std::ofstream(file) << R"({"groups": [{"capacity": 1, "emitters": [{"rate": -1}]}]})"; }
  try {
    loadEffect(file);
    FAIL();
  } catch (const EffectError& e) {
    EXPECT_EQ(std::string(e.what()),
              file.string() + ": groups[0].emitters[0].rate: must be finite and >= 0");
  }
  std::filesystem::remove_all(dir);
}

TEST(EffectLoader, BuildCreatesTheGroups) {
  const Effect fx = parseEffect(R"({"groups": [
      {"name": "a", "capacity": 1000, "require": ["color"],
       "emitters": [{"rate": 300, "types": [{"lifetime": 1}]}],
       "actions": [{"type": "Gravity"}, {"type": "Move"}, {"type": "KillOld"}]},
      {"name": "b", "capacity": 50}]})");
  Context ctx(fx.contextOptions());
  const std::vector<Group*> gs = fx.build(ctx, 500);
  ASSERT_EQ(gs.size(), 2u);
  EXPECT_EQ(gs[0]->name(), "a");
  EXPECT_EQ(gs[0]->capacity(), 500u);  // capped
  EXPECT_EQ(gs[1]->capacity(), 50u);
  EXPECT_TRUE(gs[0]->attributes().has(Attribute::Color));
  ctx.run(10);
  EXPECT_GT(gs[0]->size(), 0u);
  // Building twice into one context: the core refuses the duplicate, named by group.
  try {
    fx.build(ctx);
    FAIL();
  } catch (const EffectError& e) {
    EXPECT_EQ(e.path(), "groups[0]");
  }
}

namespace {
/// A scratch folder of this process (tests of several worktrees run side by side).
std::filesystem::path scratchDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("flurry_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

EffectError loadErrorOf(const std::filesystem::path& file, const EffectLoadOptions& opts = {}) {
  try {
    loadEffect(file, opts);
  } catch (const EffectError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for " << file;
  return EffectError("", "", "");
}

std::vector<std::string> warningsOf(const std::string& json) {
  std::vector<std::string> out;
  for (const EffectWarning& w : parseEffect(json, "w.json").warnings) out.push_back(w.message());
  return out;
}
}  // namespace

TEST(EffectLoader, AFolderIsNamedAsOne) {
  const auto dir = scratchDir("folder");
  const EffectError e = loadErrorOf(dir);
  EXPECT_EQ(std::string(e.what()), dir.string() + ": is a directory");
  std::filesystem::remove_all(dir);
}

TEST(EffectLoader, FilesAreReadUpToASizeBound) {
  const auto dir = scratchDir("size");
  const auto file = dir / "big.json";
  const std::string text = withGroup("");
  { std::ofstream(file) << text; }
  EffectLoadOptions small;
  small.maxFileBytes = text.size();
  EXPECT_EQ(loadEffect(file, small).name, "t");  // exactly at the bound: read
  small.maxFileBytes = text.size() - 1;
  EXPECT_EQ(loadErrorOf(file, small).why(), "larger than " + std::to_string(text.size() - 1) +
                                                " bytes, the limit for an effect file");
  std::filesystem::remove_all(dir);
  // A device has no size to check first: it is read up to the bound (64 MiB), not for ever.
  if (std::filesystem::exists("/dev/zero")) {
    const EffectError e = loadErrorOf("/dev/zero");
    EXPECT_EQ(std::string(e.what()), "/dev/zero: larger than 64 MiB, the limit for an effect file");
  }
}

TEST(EffectLoader, RenderCheckerErrorsNameTheFile) {
  EffectLoadOptions opts;
  std::string seen;
  opts.baseDir = "effects";
  opts.renderChecker = [&](std::string_view render, const std::filesystem::path& base) {
    seen = std::string(render) + " in " + base.string();
    if (render.find("ptich") != std::string_view::npos)
      throw InvalidArgument("render.camera.ptich", "unknown field");
    if (render.find("sprite") != std::string_view::npos) throw Error("cannot read the sprite");
  };
  const Effect ok = parseEffect(R"({"groups": [{"capacity": 1}], "render": {"blend": "additive"}})",
                                "ok.json", opts);
  EXPECT_EQ(seen, R"({"blend":"additive"} in effects)");
  EXPECT_EQ(ok.render, R"({"blend":"additive"})");
  const EffectError e =
      errorOf(R"({"groups": [{"capacity": 1}], "render": {"camera": {"ptich": 10}}})", opts);
  EXPECT_EQ(std::string(e.what()), "test.json: render.camera.ptich: unknown field");
  EXPECT_EQ(e.path(), "render.camera.ptich");
  EXPECT_EQ(
      std::string(
          errorOf(R"({"groups": [{"capacity": 1}], "render": {"sprite": "x.png"}})", opts).what()),
      "test.json: render: cannot read the sprite");
  // Without a checker the object is kept unchecked (the core does not read it).
  EXPECT_NO_THROW(
      parseEffect(R"({"groups": [{"capacity": 1}], "render": {"camera": {"ptich": 10}}})"));
}

TEST(EffectLoader, WarnsAboutListsThatCannotDoWhatTheyImply) {
  const std::string emitter = R"("emitters": [{"rate": 100}])";
  // No Move: nothing moves or ages, so KillOld never kills and gradients stay put.
  EXPECT_EQ(warningsOf(withGroup(emitter + R"(, "actions": [{"type": "Gravity"},
              {"type": "KillOld"}, {"type": "ColorOverLife"}])")),
            (std::vector<std::string>{
                "groups[0].actions: has no Move: particles never move or age",
                "groups[0].actions[1]: never kills: without a Move particles never age",
                "groups[0].actions[2]: stays at its first key: without a Move particles never "
                "age"}));
  // Move but nothing that removes particles, with an emitter that never stops.
  EXPECT_EQ(warningsOf(withGroup(emitter + R"(, "actions": [{"type": "Move"}])")),
            (std::vector<std::string>{
                "groups[0].actions: nothing removes particles (no KillOld, Sink or "
                "SinkVelocity): the group fills to its capacity of 100 and then drops every "
                "newborn"}));
  // ... which an emitter that stops, a Sink, or hair mode answers.
  EXPECT_TRUE(warningsOf(withGroup(R"("emitters": [{"rate": 100, "stop": 1}],
                                      "actions": [{"type": "Move"}])"))
                  .empty());
  EXPECT_TRUE(warningsOf(withGroup(emitter + R"(, "actions": [{"type": "Move"},
              {"type": "Sink", "region": {"type": "plane", "normal": [0, -1, 0]}}])"))
                  .empty());
  EXPECT_TRUE(
      warningsOf(withGroup(emitter + R"(, "hair": true, "actions": [{"type": "Move"}])")).empty());
  // A group nothing fills, and emitters that emit nothing.
  EXPECT_EQ(warningsOf(withGroup("")),
            (std::vector<std::string>{
                "groups[0]: has no emitters or prime emitters: the group stays empty"}));
  EXPECT_EQ(warningsOf(withGroup(R"("emitters": [{"rate": 0}, {"bursts": [{"count": 5}]}],
                                    "actions": [{"type": "Move"}, {"type": "KillOld"}])")),
            (std::vector<std::string>{"groups[0].emitters[0]: emits nothing: its rate is 0 and "
                                      "it has no bursts (nor a spacing while it moves)"}));
  // Prime emitters whose showers would outgrow their emitter capacity (maxEmitters).
  const std::string acts = R"(, "actions": [{"type": "Move"}, {"type": "KillOld"}])";
  EXPECT_EQ(warningsOf(withGroup(R"("primeEmitters": [{"rate": 1000, "maxEmitters": 100,
                "child": {"lifetime": 2, "deathChildren": 3, "emitter": {"rate": 10},
                          "next": {"lifetime": 0.5}}}])" +
                                 acts)),
            (std::vector<std::string>{
                "groups[0].primeEmitters[0]: keeps about 3500 emitters alive at once (rate and "
                "largest burst times each level's lifetime and deathChildren), more than its "
                "maxEmitters of 100: spawns past it are dropped"}));
  EXPECT_TRUE(warningsOf(withGroup(R"("primeEmitters": [{"rate": 10, "maxEmitters": 100,
                "child": {"lifetime": 2, "emitter": {"rate": 10}}}])" +
                                   acts))
                  .empty());
  // A 2-D group: the inserted constraint does not shift the actions' JSON indices.
  const auto w2d = warningsOf(withGroup(emitter + R"(, "mode2d": true, "actions": [
      {"type": "Gravity"}, {"type": "KillOld"}])"));
  ASSERT_EQ(w2d.size(), 2u);
  EXPECT_EQ(w2d[1], "groups[0].actions[1]: never kills: without a Move particles never age");
  // A complete list has none.
  EXPECT_TRUE(
      warningsOf(withGroup(emitter + R"(, "actions": [{"type": "Move"}, {"type": "KillOld"}])"))
          .empty());
}

namespace {

/// An emitter whose shape is `shape`, in a group of one emitter.
std::string emitterShape(const std::string& shape) {
  return withGroup(R"("emitters": [{"rate": 10, "shape": )" + shape + "}]");
}

}  // namespace

TEST(EffectLoader, MeshFromAnObjFileRelativeToTheEffect) {
  const auto dir = scratchDir("obj");
  // A unit square as one quad (fanned into two triangles), with the lines a modeller writes:
  // comments, normals, texture coordinates, groups, v/vt/vn corners, a negative index.
  {
    std::ofstream(dir / "square.obj") << "# a square\r\nmtllib x.mtl\no square\n"
                                         "v 0 0 0\nv 1 0 0\nv 1 0 -1  # trailing comment\n"
                                         "v 0 0 -1\nvn 0 1 0\nvt 0 0\ng top\ns off\n"
                                         "f 1/1/1 2//1 3 -1\n";
  }
  { std::ofstream(dir / "fx.json") << emitterShape(R"({"type": "mesh", "obj": "square.obj"})"); }
  const Effect fx = loadEffect(dir / "fx.json");
  const Domain& shape = fx.groups.at(0).emitters.at(0).shape;
  const auto* mesh = std::get_if<MeshDomain>(&shape.shape());
  ASSERT_NE(mesh, nullptr);
  ASSERT_EQ(mesh->mesh->vertices.size(), 4u);
  ASSERT_EQ(mesh->mesh->triangles.size(), 2u);
  EXPECT_EQ(mesh->mesh->triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh->mesh->triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(mesh->mesh->vertices[2], Vec3(1, 0, -1));
  EXPECT_NEAR(shape.measure(), 1.0, 1e-6);
  // Counter-clockwise seen from +y: the normal points up.
  EXPECT_EQ(shape.normal(Vec3(0.5f, 1.0f, -0.5f)), Vec3(0, 1, 0));
  // Saved inline: the saved effect needs no file.
  const Effect again = parseEffect(saveEffect(fx), "saved.json");
  const auto* saved = std::get_if<MeshDomain>(&again.groups.at(0).emitters.at(0).shape.shape());
  ASSERT_NE(saved, nullptr);
  EXPECT_EQ(saved->mesh->triangles.size(), 2u);
  std::filesystem::remove_all(dir);
}

TEST(EffectLoader, ObjErrorsNameTheFileAndTheLine) {
  const auto dir = scratchDir("objerr");
  EffectLoadOptions opts;
  opts.baseDir = dir;
  const std::string field = "groups[0].emitters[0].shape.obj";
  const std::string obj = (dir / "m.obj").string();
  auto errorFor = [&](const std::string& text) {
    { std::ofstream(dir / "m.obj") << text; }
    return errorOf(emitterShape(R"({"type": "mesh", "obj": "m.obj"})"), opts);
  };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const struct {
    std::string text, why;
  } cases[] = {
      {"v 0 0 0\nv 1 0\n", obj + ":2: a vertex needs x y z"},
      {"v 0 0 0\nv 1 nan 0\n", obj + ":2: vertex coordinate \"nan\" is not a finite number"},
      {"v 0 0 0\nv 1 0x 0\n", obj + ":2: vertex coordinate \"0x\" is not a finite number"},
      {tri + "f 1 2\n", obj + ":4: a face needs at least 3 corners, got 2"},
      {tri + "\nf 1 2 0\n", obj + ":5: face corner \"0\" is not a vertex index (1-based, or "
                                  "negative from the end)"},
      {tri + "f 1 2 a/1\n", obj + ":4: face corner \"a/1\" is not a vertex index (1-based, or "
                                  "negative from the end)"},
      {tri + "f 1 2 -4\n", obj + ":4: face corner -4 is before the first vertex (3 so far)"},
      {tri + "f 1 2 3\n# more\nf 1 2 7\n", obj + ":6: face corner 7 is past the last vertex (3 "
                                                 "in the file)"},
      {tri + "vn 0 0 1\n", obj + ":4: no faces ('f' lines) in the file"},
      // A zero-area face: the core's check, at the face's line.
      {tri + "v 2 0 0\nf 1 2 3\nf 1 2 4\n", obj + ":6: zero area"},
  };
  for (const auto& c : cases) {
    const EffectError e = errorFor(c.text);
    EXPECT_EQ(e.file(), "test.json") << c.text;
    EXPECT_EQ(e.path(), field) << c.text;
    EXPECT_EQ(e.why(), c.why) << c.text;
  }
  EXPECT_EQ(errorOf(emitterShape(R"({"type": "mesh", "obj": "none.obj"})"), opts).why(),
            (dir / "none.obj").string() + ": cannot open the file");
  EXPECT_EQ(errorOf(emitterShape(R"({"type": "mesh", "obj": "."})"), opts).why(),
            (dir / ".").string() + ": is a directory");
  EXPECT_EQ(
      errorOf(emitterShape(R"({"type": "mesh", "obj": "m.obj", "vertices": []})"), opts).why(),
      "give either \"obj\" or \"vertices\" and \"triangles\", not both");
  // A misspelt key suggests the file form too.
  EXPECT_NE(errorOf(emitterShape(R"({"type": "mesh", "ojb": "m.obj"})"), opts).why().find("obj"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}
