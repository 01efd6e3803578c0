// The game runtime benchmarks' effect and placement, shared by bench_runtime and
// instance_lines.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

#include "flurry/transform.hpp"

namespace flurry::bench {

// A puff of sparks: a sphere emitter firing `rate` a second that live `lifetime` (1 s: `rate`
// alive at steady state, a thirtieth born and dying every step), falling on a floor. The floor and
// the emitter are placed by the instance's transform.
inline std::string sparks(std::size_t rate, double lifetime = 1.0) {
  const std::string r = std::to_string(rate);
  return R"({"version": 1, "name": "sparks", "dt": 0.0333333333333, "seed": 7,
    "groups": [{"name": "sparks", "capacity": )" +
         std::to_string(std::size_t(double(rate) * lifetime * 1.25) + 16) + R"(,
      "emitters": [{"shape": {"type": "sphere", "center": [0, 1, 0], "outerRadius": 0.1},
        "rate": )" +
         r + R"(,
        "types": [{"velocity": {"type": "sphere", "center": [0, 2, 0], "outerRadius": 1},
                   "lifetime": )" +
         std::to_string(lifetime) + R"(}]}],
      "actions": [
        {"type": "Gravity", "acceleration": [0, -9.81, 0]},
        {"type": "Bounce", "surface": {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
         "restitution": 0.5},
        {"type": "Move"},
        {"type": "KillOld"}]}]})";
}

constexpr std::size_t kPerInstance = 100;

// Where instance k of `count` stands: a grid on the ground, each turned its own way.
inline Transform placeOf(std::size_t k, std::size_t count) {
  const auto side = std::size_t(std::ceil(std::sqrt(double(count))));
  Transform t;
  t.position = Vec3(float(k % side) * 4.0f, 0.0f, float(k / side) * 4.0f);
  t.rotation = glm::angleAxis(float(k) * 0.37f, Vec3(0.0f, 1.0f, 0.0f));
  return t;
}

}  // namespace flurry::bench
