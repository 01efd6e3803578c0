// Effects drawn at random, as effect-file text: from the action descriptors, every field of
// every action anywhere in its documented range (its ends, zero, huge and tiny values,
// infinity where the field takes it), with random domains, integrators and step lengths
// (randomEffect); emission of every kind (randomEmission); either in an instance's own space
// (randomPlacedEffect); in hair mode or with trails (randomLookEffect). The same seed draws
// the same text wherever the same compiler and standard library built the tests (the
// distributions, and the order of draws inside one expression, are theirs to choose).
// Shared by the tests that step them on the CPU (tests/effect/test_random_effects.cpp) and
// on the device (tests/opencl/test_opencl_random.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "effect/descriptors.hpp"
#include "flurry/effect.hpp"
#include "flurry/transform.hpp"
#include "sample_values.hpp"

namespace flurry::test {

/// Random choices from one seed (std::mt19937), as effect-file text.
class Draw {
 public:
  explicit Draw(std::uint32_t seed) : rng_(seed) {}
  int below(int n) { return int(std::uniform_int_distribution<int>(0, n - 1)(rng_)); }
  double between(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  /// v as JSON, to `digits` significant digits.
  static std::string text(double v, int digits = 6) {
    char out[32];
    std::snprintf(out, sizeof out, "%.*g", digits, v);
    return out;
  }

  /// A JSON number (or "inf") inside limit `l`: an end, zero, huge, tiny or anywhere.
  std::string number(const desc::Limit& l) {
    const double lo = l.min > -desc::kInf ? l.min : -1e6, hi = l.max < desc::kInf ? l.max : 1e6;
    double v = between(lo, hi);
    switch (below(9)) {
      case 0:
        v = lo;
        break;
      case 1:
        v = hi;
        break;
      case 2:
        v = 0.0;
        break;
      case 3:
        v = 1e30;
        break;
      case 4:
        v = 1e-30;
        break;
      case 5:
        v = -1e30;
        break;
      case 6:
        if (l.infinite) return "\"inf\"";
        break;
      default:
        break;
    }
    if (l.checked) {
      if (v < l.min || v > l.max) v = between(lo, hi);
      if (l.minOpen && v <= l.min) v = l.min + (hi - l.min) * 0.5;
    }
    if (l.nonZero && v == 0.0) v = 0.5;
    return text(v, 9);
  }
  std::string vec3(const desc::Limit& l) {
    return "[" + number(l) + ", " + number(l) + ", " + number(l) + "]";
  }
  /// A small coordinate, or now and then a far one.
  std::string coord() { return text(below(8) == 0 ? between(-1e6, 1e6) : between(-3.0, 3.0)); }
  std::string point() { return "[" + coord() + ", " + coord() + ", " + coord() + "]"; }
  std::string size() { return text(below(6) == 0 ? (below(2) ? 1e-6 : 1e5) : between(0.01, 3.0)); }
  std::string domain() {
    switch (below(11)) {
      case 0:
        return R"({"type": "point", "point": )" + point() + "}";
      case 1:
        return R"({"type": "line", "p0": )" + point() + R"(, "p1": )" + point() + "}";
      case 2:
        return R"({"type": "plane", "point": )" + point() + R"(, "normal": [0, 1, 0.5]})";
      case 3:
        return R"({"type": "disc", "center": )" + point() +
               R"(, "normal": [0.3, 1, 0], "outerRadius": )" + size() + "}";
      case 4:
        return R"({"type": "sphere", "center": )" + point() + R"(, "outerRadius": )" + size() + "}";
      case 5:
        return R"({"type": "box", "min": [-1, -1, -1], "max": [)" + size() + ", " + size() + ", " +
               size() + "]}";
      case 6:
        return R"({"type": "cylinder", "p0": [0, 0, 0], "p1": )" + point() +
               R"(, "outerRadius": )" + size() + "}";
      case 7:
        return R"({"type": "cone", "apex": [0, 0, 0], "base": [0, 2, 0], "outerRadius": )" +
               size() + "}";
      case 8:
        return R"({"type": "blob", "center": )" + point() + R"(, "stddev": )" + size() + "}";
      case 9:
        return R"({"type": "rectangle", "origin": )" + point() +
               R"(, "u": [2, 0, 0], "v": [0, 0, 2]})";
      default:
        return R"({"type": "triangle", "p0": [0, 0, 0], "p1": [1, 0, 0], "p2": [0, 0, 1]})";
    }
  }

  /// How the list's Move integrates, as the group's "integrator" key.
  std::string integrator() {
    const char* names[] = {"SemiImplicitEuler", "ExplicitEuler", "VelocityVerlet", "RK4", "Exact"};
    return std::string(R"("integrator": ")") + names[below(5)] + "\"";
  }
  std::string fuzzy() {
    switch (below(4)) {
      case 0:
        return size();
      case 1:
        return "[" + size() + ", " + size() + "]";
      case 2:
        return R"({"center": )" + size() + R"(, "percent": 40})";
      default:
        return R"({"center": )" + size() + R"(, "spread": 0.3, "distribution": "normal"})";
    }
  }
  std::string time() { return text(below(5) == 0 ? between(-2.0, 0.0) : between(0.0, 3.0)); }
  /// 1 to 3 particle types, weighed.
  std::string types() {
    std::string out;
    const int n = 1 + below(3);
    for (int k = 0; k < n; ++k) {
      out += std::string(k ? ", " : "") + R"({"weight": )" + (k == 0 || below(4) ? size() : "0") +
             R"(, "velocity": )" + domain() + R"(, "lifetime": )" + fuzzy();
      if (below(2)) out += R"(, "size": )" + fuzzy() + R"(, "mass": )" + fuzzy();
      if (below(3) == 0) out += R"(, "charge": )" + fuzzy() + R"(, "rotVelocity": )" + domain();
      out += "}";
    }
    return "[" + out + "]";
  }
  /// Where, when and how many: a shape and a rate, and at random bursts, a path, a motion,
  /// a start and a stop.
  std::string counting(int most) {
    std::string out = R"("shape": )" + domain() + R"(, "rate": )" + std::to_string(below(most));
    if (below(3) == 0) {
      out += R"(, "bursts": [)";
      const int n = 1 + below(3);
      for (int k = 0; k < n; ++k)
        out += std::string(k ? ", " : "") + R"({"time": )" + time() + R"(, "count": )" +
               std::to_string(below(most / 10 + 2)) + R"(, "interval": )" + size() +
               R"(, "repeat": )" + std::to_string(1 + below(4)) + "}";
      out += "]";
    }
    if (below(3) == 0) {
      out += R"(, "path": [)";
      const int n = 1 + below(4);
      for (int k = 0; k < n; ++k) {
        const std::string t = text(0.4 * k + between(0.0, 0.3));  // (drawn before the place)
        out +=
            std::string(k ? ", " : "") + R"({"time": )" + t + R"(, "position": )" + point() + "}";
      }
      out += std::string("], \"pathLoop\": ") + (n > 1 && below(2) ? "true" : "false");
    } else if (below(2)) {
      out += R"(, "position": )" + point() + R"(, "velocity": )" + point();
    }
    if (below(3) == 0) {
      const double start = below(5) == 0 ? between(-2.0, 0.0) : between(0.0, 1.0);
      const std::string stop = text(start + between(0.0, 2.0));
      out += below(2) ? R"(, "start": )" + text(start) + R"(, "stop": )" + stop
                      : std::string(R"(, "stop": "inf")");
    }
    return out;
  }
  std::string emitter(int most) {
    std::string out = "{" + counting(most) + R"(, "types": )" + types();
    if (below(4) == 0) out += R"(, "spacing": )" + size();
    if (below(4) == 0) out += R"(, "normalSpeed": )" + fuzzy();
    return out + "}";
  }
  /// A prime emitter's emitters, `levels` deep.
  std::string spec(int levels) {
    std::string out = R"({"emitter": )" + emitter(300) + R"(, "velocity": )" + domain() +
                      R"(, "lifetime": )" + fuzzy();
    if (below(2)) out += R"(, "acceleration": [0, -9.8, 0], "drag": )" + size();
    if (below(2)) out += R"(, "deathBurst": )" + std::to_string(below(20));
    if (levels > 1 && below(2))
      out +=
          R"(, "deathChildren": )" + std::to_string(below(4)) + R"(, "next": )" + spec(levels - 1);
    return out + "}";
  }

  template <class T>
  std::string value(const desc::Limit& l) {
    if constexpr (std::is_same_v<T, float>) {
      return number(l);
    } else if constexpr (std::is_same_v<T, int>) {
      return std::to_string(l.min > -desc::kInf ? int(l.min) + below(4) : below(4));
    } else if constexpr (std::is_same_v<T, bool>) {
      return below(2) ? "true" : "false";
    } else if constexpr (std::is_same_v<T, Vec3>) {
      return vec3(l);
    } else if constexpr (desc::NamedEnum<T>) {
      const auto& names = desc::EnumNames<T>::values;
      return std::string("\"") + names[std::size_t(below(int(std::size(names))))].first + "\"";
    } else if constexpr (std::is_same_v<T, Domain>) {
      return domain();
    } else if constexpr (std::is_same_v<T, Falloff>) {
      return R"({"center": )" + point() + R"(, "radius": )" + size() + R"(, "power": 2})";
    } else if constexpr (test::kListed<T>) {
      return test::listedSample<T>();
    } else {
      static_assert(!sizeof(T), "a field type the test does not know");
    }
  }

 private:
  std::mt19937 rng_;
};

/// An effect of one group (small, or large enough for threads to share): a random emitter, 1 to 6
/// actions drawn from every kind an effect file can hold, each field set (or left at its default)
/// at random, most often a Move among them, and a random integrator and sub-stepping.
inline std::string randomEffect(std::uint32_t seed) {
  Draw d(seed);
  std::vector<std::string> all;
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    std::string a = std::string(R"({"type": ")") + desc::Describe<A>::name + "\"";
    desc::forEachField<A>([&](const auto& f) {
      using T = std::decay_t<decltype(A{}.*f.member)>;
      if (d.below(3) == 0 && !f.required) return;  // its default
      a += std::string(", \"") + f.name + "\": " + d.value<T>(f.limit);
    });
    all.push_back(a + "}");
  });
  std::string actions;
  const int count = 1 + d.below(6), move = d.below(10) < 7 ? d.below(count + 1) : -1;
  for (int k = 0; k <= count; ++k) {
    if (k == move) actions += std::string(actions.empty() ? "" : ",\n") + R"({"type": "Move"})";
    if (k < count)
      actions += (actions.empty() ? "" : ",\n") + all[std::size_t(d.below(int(all.size())))];
  }
  std::string list = d.integrator();
  if (d.below(3) == 0)
    list += R"(, "substeps": {"maxStep": )" + d.size() + R"(, "maxSubsteps": )" +
            std::to_string(1 + d.below(8)) + "}";

  // A third large enough that two threads share its passes (a small group steps on one; the
  // blocks are of 256), at most ~2,000 alive (some actions read every pair of particles).
  const bool large = d.below(3) == 0;
  const std::string dt = Draw::text(!large && d.below(4) == 0 ? 5.0 : d.between(0.001, 0.2));
  std::string fx = R"({"name": "random", "seed": )" + std::to_string(seed) + R"(, "dt": )" + dt;
  fx += R"(, "groups": [{"name": "g", "capacity": )" + std::string(large ? "40000" : "300");
  fx += R"(, "emitters": [{"shape": )" + d.domain();
  fx += R"(, "rate": )" + std::to_string(d.below(large ? 400 : 3000));
  fx += R"(, "types": [{"velocity": )" + d.domain() + R"(, "lifetime": [)" + d.size();
  fx += R"(, 0.5]}]}], )" + list + R"(, "actions": [)" + actions + "]}]}";
  return fx;
}

/// Two groups whose emission is drawn at random: "a" with 1 or 2 emitters (bursts, paths,
/// motion, start and stop, several weighed particle types, births by distance, speeds along
/// the shape's normal) and at times a prime emitter of up to three levels; "b" fed by "a"'s
/// deaths, collisions or births (a sub-emitter). Simple action lists, a random integrator.
inline std::string randomEmission(std::uint32_t seed) {
  Draw d(seed);
  const std::string dt = Draw::text(d.below(5) == 0 ? 1.0 : d.between(0.001, 0.1));
  std::string fx = R"({"name": "emission", "seed": )" + std::to_string(seed) + R"(, "dt": )" + dt;
  fx += R"(, "groups": [{"name": "a", "capacity": )" + std::to_string(50 + d.below(2000));
  fx += R"(, "emitters": [)" + d.emitter(2000);
  if (d.below(2)) fx += ", " + d.emitter(2000);
  fx += "]";
  if (d.below(3) == 0)
    fx += R"(, "primeEmitters": [{)" + d.counting(20) + R"(, "child": )" + d.spec(3) +
          R"(, "maxEmitters": )" + std::to_string(1 + d.below(30)) + "}]";
  fx += ", " + d.integrator();
  fx += R"(, "actions": [{"type": "Gravity", "acceleration": [0, -9.8, 0]},
      {"type": "Bounce", "surface": {"type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0]},
       "restitution": 0.6}, {"type": "Move"}, {"type": "KillOld"}]},
    {"name": "b", "capacity": )" +
        std::to_string(50 + d.below(2000));
  const char* on[] = {"death", "collision", "birth"};
  fx += R"(, "deathEmitters": [{"source": "a", "on": ")" + std::string(on[d.below(3)]) +
        R"(", "count": )" + d.fuzzy() + R"(, "inheritVelocity": 0.5, "shape": )" + d.domain() +
        R"(, "types": )" + d.types() + "}]";
  fx += R"(, "actions": [{"type": "Move"}, {"type": "KillOld"}]}]})";
  return fx;
}

/// randomEffect in the world's space or, every other seed, in the instance's own (its
/// particles carried with it when it moves).
inline std::string randomPlacedEffect(std::uint32_t seed) {
  std::string fx = randomEffect(seed);
  if (seed % 2 == 0) fx.insert(1, R"("space": "local", )");
  return fx;
}

/// randomEffect drawn for a renderer: in hair mode (a strand every 1-3 steps, of at most
/// 2-41 vertices) or with a trail of 1-20 positions, one or the other at random.
inline std::string randomLookEffect(std::uint32_t seed) {
  std::string fx = randomEffect(seed);
  Draw d(seed * 131u + 7u);  // (its own draws: the effect is randomEffect's)
  const std::string look =
      d.below(2) ? R"("hair": {"every": )" + std::to_string(1 + d.below(3)) +
                       R"(, "maxVertices": )" + std::to_string(2 + d.below(40)) + "}, "
                 : R"("trail": {"length": )" + std::to_string(1 + d.below(20)) + "}, ";
  const std::string group = R"({"name": "g", )";
  fx.insert(fx.find(group) + group.size(), look);
  return fx;
}

/// Where an instance of the effect drawn from `seed` stands before step `step`, placed anew
/// before each as a game moves an effect with its owner: anywhere within 100 units, turned
/// any way, scaled 0.5-2 (the same on every run).
inline Transform randomPlacement(std::uint64_t seed, int step) {
  Draw d(std::uint32_t(seed) * 977u + std::uint32_t(step));
  const Vec3 axis(float(d.between(-1, 1)), float(d.between(0.1, 1)), float(d.between(-1, 1)));
  return {
      Vec3(float(d.between(-100, 100)), float(d.between(-100, 100)), float(d.between(-100, 100))),
      glm::angleAxis(float(d.between(-3.2, 3.2)), glm::normalize(axis)),
      float(d.between(0.5, 2.0))};
}

/// The seeds a test draws: [1, count], or FLURRY_RANDOM_EFFECTS="FIRST-LAST" for a wider
/// sweep run by hand (the loaded and stepped counts then checked in proportion).
inline std::pair<std::uint32_t, std::uint32_t> seeds(std::uint32_t count) {
  const char* v = std::getenv("FLURRY_RANDOM_EFFECTS");
  unsigned first = 0, last = 0;
  if (v && std::sscanf(v, "%u-%u", &first, &last) == 2 && first >= 1 && last >= first)
    return {first, last};
  return {1u, count};
}

/// A drawing function: randomEffect, randomEmission, randomPlacedEffect, randomLookEffect.
using DrawEffect = std::string (*)(std::uint32_t);

/// Calls fn(seed, draw, effect) for each seed of seeds(count), of each drawing function in
/// `kinds`, whose effect loads (a combination the loader refuses is skipped: its tests check
/// that), under a trace naming the seed and the text; returns at the first failure.
template <class Fn>
void forEachDrawnEffect(std::initializer_list<DrawEffect> kinds, std::uint32_t count, Fn fn) {
  const auto [first, last] = seeds(count);
  for (DrawEffect draw : kinds)
    for (std::uint32_t seed = first; seed <= last; ++seed) {
      const std::string text = draw(seed);
      SCOPED_TRACE("seed " + std::to_string(seed) + ":\n" + text);
      Effect fx;
      try {
        fx = parseEffect(text, "random.json");
      } catch (const EffectError&) {
        continue;
      }
      fn(seed, draw, fx);
      if (::testing::Test::HasFailure()) return;
    }
}

/// How many seeds a test draws of each kind: seeds(count)'s.
inline double seedCount(std::uint32_t count) {
  const auto [first, last] = seeds(count);
  return double(last - first + 1);
}

}  // namespace flurry::test
