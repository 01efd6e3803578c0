// The action descriptors (sdk/src/effect/descriptors.hpp): their valid values agree with what
// ActionList::add accepts, every described field is read and written by the loader and
// saveEffect, and what a file cannot hold is refused by the writer.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "effect/descriptors.hpp"
#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "sample_values.hpp"

using namespace flurry;

namespace {

/// A valid action of type A: its defaults, with what has no valid default given.
template <class A>
A validAction() {
  A a{};
  // A segment: its planeNormal is validated only then.
  if constexpr (std::is_same_v<A, Bounce>) a.surface = Domain::line(Vec3(0.0f), Vec3(1.0f, 0, 0));
  if constexpr (std::is_same_v<A, SampledField>) {
    auto f = std::make_shared<VectorField>();
    f->dims = {1, 1, 1};
    f->data = {Vec3(1.0f)};
    a.field = f;
  }
  return a;
}

/// The InvalidArgument parameter ActionList::add throws for `a` (for an emitter part, its
/// validate("e")), or "" if it accepts it.
template <class A>
std::string rejected(const A& a) {
  try {
    if constexpr (requires { a.validate(std::string("e")); }) {
      a.validate("e");
    } else {
      ActionList list;
      list.add(a);
    }
  } catch (const InvalidArgument& e) {
    return e.parameter();
  }
  return "";
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// Values of a field with limit `l` that validation must refuse.
std::vector<float> badValues(const desc::Limit& l) {
  std::vector<float> v{kNaN};
  if (l.min > -desc::kInf) v.push_back(l.minOpen ? float(l.min) : float(l.min) - 1.0f);
  if (l.max < desc::kInf) v.push_back(float(l.max) + 1.0f);
  if (!l.infinite) v.push_back(kInfinity);
  return v;
}
/// Values it must accept (with the action's other fields at valid defaults).
std::vector<float> goodValues(const desc::Limit& l) {
  std::vector<float> v;
  if (l.min > -desc::kInf) v.push_back(l.minOpen ? float(l.min) + 0.5f : float(l.min));
  if (l.max < desc::kInf) v.push_back(float(l.max));
  if (l.infinite) v.push_back(kInfinity);
  if (v.empty()) v.push_back(-3.0f);
  return v;
}

/// Checks each checked field of `part` (reached from the action `base` through `at`) against
/// validation: bad values are refused naming the field, good ones accepted.
template <class A, class S, class At>
void checkLimits(const A& base, const std::string& root, const std::string& prefix, At at) {
  desc::forEachField<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    const std::string path = root + prefix + f.name;
    if constexpr (desc::Described<T>) {
      checkLimits<A, T>(base, root, prefix + f.name + ".",
                        [&](A& a) -> T& { return at(a).*f.member; });
    } else if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (!f.limit.checked) return;
      for (float bad : badValues(f.limit)) {
        if (std::is_integral_v<T> && !std::isfinite(bad)) continue;
        if (std::is_unsigned_v<T> && bad < 0) continue;
        A a = base;
        at(a).*f.member = T(bad);
        EXPECT_EQ(rejected(a), path) << "value " << bad;
      }
      for (float good : goodValues(f.limit)) {
        A a = base;
        at(a).*f.member = T(good);
        EXPECT_EQ(rejected(a), "") << path << " = " << good;
      }
    } else if constexpr (std::is_same_v<T, Vec3>) {
      if (!f.limit.checked) return;
      std::vector<Vec3> bad{Vec3(0.0f, kNaN, 0.0f), Vec3(kInfinity, 0.0f, 1.0f)};
      if (f.limit.nonZero) bad.push_back(Vec3(0.0f));
      if (f.limit.min > -desc::kInf) bad.push_back(Vec3(1.0f, float(f.limit.min) - 1.0f, 1.0f));
      for (Vec3 v : bad) {
        A a = base;
        at(a).*f.member = v;
        EXPECT_EQ(rejected(a), path) << v.x << " " << v.y << " " << v.z;
      }
      A a = base;
      at(a).*f.member = Vec3(0.5f, 2.0f, 0.0f);
      EXPECT_EQ(rejected(a), "") << path;
    }
  });
}

}  // namespace

TEST(EffectDescriptors, LimitsAgreeWithValidation) {
  int checked = 0;
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    SCOPED_TRACE(desc::Describe<A>::name);
    const A base = validAction<A>();
    ASSERT_EQ(rejected(base), "") << "the defaults are valid";
    checkLimits<A, A>(base, "actions[0]." + std::string(desc::Describe<A>::name) + ".", "",
                      [](A& a) -> A& { return a; });
    ++checked;
  });
  EXPECT_EQ(checked, int(std::variant_size_v<Action>) - 1);  // all but Callback
}

// The emitters' parts are validated from their descriptors too (a burst and a key of a path
// through their lists).
TEST(EffectDescriptors, EmitterLimitsAgreeWithValidation) {
  Emitter e;
  e.bursts.push_back(Burst{});
  e.path = {Keyframe{0.0f, Vec3(0.0f)}};
  e.types.push_back(ParticleType{});  // a weight of 0 leaves the other
  ASSERT_EQ(rejected(e), "");
  checkLimits<Emitter, Emitter>(e, "e.", "", [](Emitter& x) -> Emitter& { return x; });
  checkLimits<Emitter, Burst>(e, "e.bursts[0].", "",
                              [](Emitter& x) -> Burst& { return x.bursts[0]; });
  checkLimits<Emitter, Keyframe>(e, "e.path[0].", "",
                                 [](Emitter& x) -> Keyframe& { return x.path[0]; });
  checkLimits<Emitter, ParticleType>(e, "e.types[0].", "",
                                     [](Emitter& x) -> ParticleType& { return x.types[0]; });
  PrimeEmitter p;
  ASSERT_EQ(rejected(p), "");
  checkLimits<PrimeEmitter, PrimeEmitter>(p, "e.", "",
                                          [](PrimeEmitter& x) -> PrimeEmitter& { return x; });
  DeathEmitter d;
  d.source = "sparks";
  ASSERT_EQ(rejected(d), "");
  checkLimits<DeathEmitter, DeathEmitter>(d, "e.", "",
                                          [](DeathEmitter& x) -> DeathEmitter& { return x; });
}

namespace {

/// A valid, non-default JSON value for a field of type T with limit `l`.
template <class T>
std::string sampleValue(const desc::Limit& l, const T& def) {
  if constexpr (std::is_same_v<T, float>) {
    if (l.max < desc::kInf) return "0.25";
    return l.checked && l.min > -desc::kInf ? "2.5" : "-1.5";
  } else if constexpr (std::is_same_v<T, int>) {
    return "3";
  } else if constexpr (std::is_same_v<T, bool>) {
    return def ? "false" : "true";
  } else if constexpr (std::is_same_v<T, Vec3>) {
    if (l.nonZero) return "[0, 0.6, 0.8]";
    return l.min > -desc::kInf ? "[0.5, 1.5, 2]" : "[0.5, -1.5, 2]";
  } else if constexpr (desc::NamedEnum<T>) {
    return std::string("\"") + desc::EnumNames<T>::values[1].first + "\"";
  } else if constexpr (std::is_same_v<T, Domain>) {
    return R"({"type": "box", "min": [-1, -1, -1], "max": [1, 2, 1]})";
  } else if constexpr (std::is_same_v<T, Falloff>) {
    return R"({"center": [0, 1, 0], "radius": 4, "power": 2})";
  } else if constexpr (test::kListed<T>) {
    return test::listedSample<T>();
  } else {
    static_assert(!sizeof(T), "a field type the test does not know");
  }
}

/// An effect whose one group holds every action an effect file can, each with every field
/// it has set to a valid value other than its default.
std::string everyAction() {
  std::string actions;
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    const A def{};
    std::string a = std::string(R"({"type": ")") + desc::Describe<A>::name + "\"";
    desc::forEachField<A>([&](const auto& f) {
      const std::string v = sampleValue(f.limit, def.*f.member);
      if (!v.empty()) a += std::string(", \"") + f.name + "\": " + v;
    });
    actions += (actions.empty() ? "" : ",\n") + a + "}";
  });
  return R"({"name": "all", "seed": 5, "groups": [{"name": "g", "capacity": 200,
      "emitters": [{"rate": 300, "types": [{"velocity": {"type": "sphere", "outerRadius": 2},
                    "lifetime": [1, 0.5], "charge": 1}]}],
      "actions": [)" +
         actions + "]}]}";
}

std::vector<std::uint32_t> run(const Effect& fx) {
  Context ctx({.seed = fx.seed, .dt = fx.dt, .threads = 1, .backend = Backend::Cpu});
  fx.build(ctx);
  ctx.run(20);
  std::vector<std::uint32_t> bits;
  for (Group* g : ctx.groups()) {
    const GroupStats& st = g->stats();
    for (std::uint64_t n : {std::uint64_t(g->size()), st.emitted, st.killedByAge, st.absorbed})
      bits.push_back(std::uint32_t(n));
  }
  for (Group* g : ctx.groups())
    for (std::size_t i = 0; i < g->size(); ++i) {
      const Particle p = g->particle(i);
      for (int c = 0; c < 3; ++c) {
        bits.push_back(std::bit_cast<std::uint32_t>(p.position[c]));
        bits.push_back(std::bit_cast<std::uint32_t>(p.velocity[c]));
      }
      bits.push_back(std::bit_cast<std::uint32_t>(p.size));
    }
  return bits;
}

}  // namespace

TEST(EffectDescriptors, EveryActionAndFieldRoundTrips) {
  const std::string text = everyAction();
  Effect fx;
  try {
    fx = parseEffect(text, "all.json");  // also: every described field is a field the loader reads
  } catch (const EffectError& e) {
    FAIL() << e.what() << "\n" << text;
  }
  ASSERT_EQ(fx.groups.at(0).actions.size(), std::variant_size_v<Action> - 1);
  const std::string saved = saveEffect(fx);
  // Every field set above differs from its default, so the writer keeps each one.
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    desc::forEachField<A>([&](const auto& f) {
      EXPECT_NE(saved.find(std::string("\"") + f.name + "\""), std::string::npos) << f.name;
    });
  });
  const Effect back = parseEffect(saved, "saved.json");
  EXPECT_EQ(saveEffect(back), saved);
  const auto a = run(fx), b = run(back);
  EXPECT_GT(a.at(1), 0u) << "emitted";
  EXPECT_TRUE(a == b);
}

TEST(EffectDescriptors, SavingACallbackNamesIt) {
  Effect fx;
  fx.name = "cb";
  EffectGroup g;
  g.name = "g";
  g.capacity = 10;
  g.actions.add(Move{});
  g.actions.add(Callback{[](Particle&, const CallbackContext&) {}});
  fx.groups.push_back(g);
  try {
    saveEffect(fx);
    FAIL() << "a Callback was saved";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(e.parameter(), "groups[0].actions[1]") << e.what();
  }
}

TEST(EffectDescriptors, EveryActionHasANameAndDocAndUniqueFields) {
  std::vector<std::string> names;
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    const std::string name = desc::Describe<A>::name;
    EXPECT_EQ(actionName(A{}), name) << "the descriptor's name is the core's";
    EXPECT_FALSE(std::string(desc::Describe<A>::doc).empty()) << name;
    std::vector<std::string> fields;
    desc::forEachField<A>([&](const auto& f) {
      EXPECT_FALSE(std::string(f.doc).empty()) << name << "." << f.name;
      EXPECT_EQ(std::find(fields.begin(), fields.end(), f.name), fields.end())
          << name << "." << f.name << " twice";
      fields.emplace_back(f.name);
    });
    names.push_back(name);
  });
  EXPECT_EQ(names.size(), std::variant_size_v<Action> - 1);
}
