// Shared helpers of the accuracy and stress tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "flurry/flurry.hpp"

namespace flurry::test {

/// FLURRY_STRESS=full (set by the `stress`-labelled CTest entries) runs the full sizes;
/// otherwise the default suite runs the same tests with small ones.
inline bool fullStress() {
  const char* s = std::getenv("FLURRY_STRESS");
  return s && std::string(s) == "full";
}
/// `small` in the default suite, `full` under the stress label.
template <class T>
T stressSize(T small, T full) {
  return fullStress() ? full : small;
}

inline Context makeContext(double dt, unsigned threads = 2) {
  ContextOptions o;
  o.dt = dt;
  o.threads = threads;
  return Context(o);
}

inline Particle particleAt(Vec3 p, Vec3 v = Vec3(0.0f)) {
  Particle q;
  q.position = p;
  q.velocity = v;
  return q;
}

inline const Integrator kAllIntegrators[] = {Integrator::SemiImplicitEuler,
                                             Integrator::ExplicitEuler,
                                             Integrator::VelocityVerlet, Integrator::RK4,
                                             Integrator::Exact};
/// The integrators that accept any force (Exact takes Gravity, Damping, ElectricField only).
inline const Integrator kGeneralIntegrators[] = {Integrator::SemiImplicitEuler,
                                                 Integrator::ExplicitEuler,
                                                 Integrator::VelocityVerlet, Integrator::RK4};

inline ActionList withIntegrator(ActionList list, Integrator i) {
  list.setIntegrator(i);
  return list;
}

/// Every stored float lane of every live particle is finite. Returns the first offender
/// as a message (empty when all are finite).
inline std::string firstNonFinite(const Group& g) {
  for (int a = 0; a < int(Attribute::Count); ++a) {
    const Attribute at = Attribute(a);
    if (at == Attribute::Id || at == Attribute::Visible || !g.attributes().has(at)) continue;
    for (int c = 0; c < componentCount(at); ++c) {
      const auto lane = g.lane(at, c);
      for (std::size_t i = 0; i < lane.size(); ++i)
        if (!std::isfinite(lane[i]))
          return std::string(attributeName(at)) + "[" + std::to_string(c) + "] of particle " +
                 std::to_string(i) + " is " + std::to_string(lane[i]);
    }
  }
  return {};
}

/// emitted == alive + killedByAge + absorbed + droppedAtCapacity + killedNonFinite.
inline ::testing::AssertionResult countsAddUp(const Group& g) {
  const GroupStats& s = g.stats();
  const std::uint64_t sum =
      g.size() + s.killedByAge + s.absorbed + s.droppedAtCapacity + s.killedNonFinite;
  if (s.emitted == sum) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "emitted " << s.emitted << " != alive " << g.size() << " + killedByAge "
         << s.killedByAge << " + absorbed " << s.absorbed << " + droppedAtCapacity "
         << s.droppedAtCapacity << " + killedNonFinite " << s.killedNonFinite;
}

/// The group's state is sane: every float finite and the counts add up.
inline ::testing::AssertionResult sane(const Group& g) {
  const std::string bad = firstNonFinite(g);
  if (!bad.empty()) return ::testing::AssertionFailure() << bad;
  return countsAddUp(g);
}

}  // namespace flurry::test
