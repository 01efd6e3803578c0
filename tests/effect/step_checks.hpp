// What every step of an effect must leave, whatever the effect asked for: checked after each
// step by the tests that step effects drawn at random or found by the fuzzer.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "flurry/flurry.hpp"

namespace flurry::test {

/// Every group within its capacity, and each of its particles finite and inside the box the
/// group reports (Group::bounds, asked before the first step). Adds a failure naming the
/// group, the step and the particle, and returns false, at the first particle that is not.
inline bool stepLeftGroupsSound(const std::vector<Group*>& groups, int step) {
  for (const Group* g : groups) {
    EXPECT_LE(g->size(), g->capacity()) << g->name() << ", step " << step;
    if (g->attributes().has(Attribute::Id)) {
      std::vector<std::uint32_t> ids(g->ids().begin(), g->ids().end());
      std::sort(ids.begin(), ids.end());
      if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) {
        ADD_FAILURE() << g->name() << ", step " << step << ": two particles share an id";
        return false;
      }
    }
    const Bounds box = g->bounds();
    std::vector<Vec3> trail(g->trail().length);
    for (std::size_t i = 0; i < g->size(); ++i) {
      const Vec3 p = g->particle(i).position;
      // A trail starts where the particle stands at the end of the step.
      if (!trail.empty() && (g->trail(i, trail) == 0 || trail[0] != p)) {
        ADD_FAILURE() << g->name() << ", step " << step << ": particle " << i
                      << "'s trail does not start where it stands";
        return false;
      }
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

/// The groups' particles (id, position, velocity, trail), then their strands, as words: what
/// the tests compare bit for bit.
inline std::vector<std::uint32_t> bitsOf(const std::vector<Group*>& groups) {
  std::vector<std::uint32_t> bits;
  auto put = [&](Vec3 v) {
    for (int c = 0; c < 3; ++c) bits.push_back(std::bit_cast<std::uint32_t>(v[c]));
  };
  for (const Group* g : groups) {
    std::vector<Vec3> trail(g->trail().length);
    for (std::size_t i = 0; i < g->size(); ++i) {
      const Particle p = g->particle(i);
      bits.push_back(p.id);
      put(p.position);
      put(p.velocity);
      if (!trail.empty())
        for (std::size_t j = 0, n = g->trail(i, trail); j < n; ++j) put(trail[j]);
    }
    for (const Vec3& v : g->strands().position) put(v);  // (hair mode)
    bits.insert(bits.end(), g->strands().start.begin(), g->strands().start.end());
  }
  return bits;
}

}  // namespace flurry::test
