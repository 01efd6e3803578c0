// What every step of an effect must leave, whatever the effect asked for: checked after each
// step by the tests that step effects drawn at random or found by the fuzzer.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "flurry/flurry.hpp"

namespace flurry::test {

/// Every group within its capacity, and each of its particles finite and inside the box the
/// group reports (Group::bounds, asked before the first step). Adds a failure naming the
/// group, the step and the particle, and returns false, at the first particle that is not.
inline bool stepLeftGroupsSound(const std::vector<Group*>& groups, int step) {
  for (const Group* g : groups) {
    EXPECT_LE(g->size(), g->capacity()) << g->name() << ", step " << step;
    const Bounds box = g->bounds();
    for (std::size_t i = 0; i < g->size(); ++i) {
      const Vec3 p = g->particle(i).position;
      if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
        ADD_FAILURE() << g->name() << ", step " << step << ": particle " << i << " not finite";
        return false;
      }
      if (!(p.x >= box.min.x && p.y >= box.min.y && p.z >= box.min.z && p.x <= box.max.x &&
            p.y <= box.max.y && p.z <= box.max.z)) {
        ADD_FAILURE() << g->name() << ", step " << step << ": particle " << i
                      << " outside the group's box";
        return false;
      }
    }
  }
  return true;
}

}  // namespace flurry::test
