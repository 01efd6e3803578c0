// Planning a step's births: which emitter gives birth, how many and when, prime emitters'
// spawning, the live emitters' flight and deaths. Shared by the CPU backend (emission.cpp)
// and the OpenCL backend (opencl/emission.cpp), so both plan the same births in the same
// order (ids and random streams follow from it).
#pragma once

#include <cstdint>
#include <vector>

#include "backend.hpp"
#include "isa_namespace.hpp"
#include "kernel_compat.hpp"

namespace flurry::detail {

/// One run of births of one emitter: by rate (birth times first/rate apart), a burst, or by
/// distance travelled (births `spacing` apart along the step's path; also a rate past 2^53
/// births, as evenly spaced times). Runs past the group's capacity are merged into the last:
/// their births are never written, only counted.
struct BirthRun {
  enum Kind { Rate, Burst, Distance } kind;
  bool live;  ///< the emitter is g.live[index], else g.emitters[index]
  std::uint32_t index;
  std::uint64_t first;  ///< Rate: index of the first birth since the emitter's start
  double time;          ///< Burst: its time; Distance: the step's start
  std::uint64_t count;
  double s0 = 0, spacing = 0, span = 0, dt = 0;  ///< Distance: first birth at s0 of span
};

/// This step's runs, in birth order (emitters, then live emitters with their death bursts);
/// advances the emitters' state, spawns (up to each prime's maxEmitters) and moves live
/// emitters, counts generations. Returns the births planned: at most 2^40, and the runs
/// hold at most `capacity` of them one by one, so a step costs the same whatever the
/// bursts' `repeat`, rates and spacings.
std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, std::vector<BirthRun>& runs);
/// Of `total` planned births, those the step makes: at most the room left (capacity - size),
/// and under a particle budget the group's share (BudgetPolicy: DropNewest drops the rest,
/// ScaleEmission thins every run of `runs` alike, DropOldest makes them all and is trimmed
/// after the step). Counts what it gives up in the stats; the host must know the live count.
std::size_t fitBirths(GroupImpl& g, std::uint64_t total, std::vector<BirthRun>& runs);

/// Where an emitter (or a prime emitter) is at time t: Emitter::positionAt's definition, with
/// the search for the path's keys starting from `key`, the one found by the last call (0:
/// none), and updated. A step's births come in increasing time, close together, so along a
/// path of many keys each costs a step of a walk instead of a binary search. Bitwise the same
/// position whatever `key` is.
Vec3 pathPositionAt(Vec3 position, Vec3 velocity, double start, const std::vector<Keyframe>& path,
                    bool loop, double t, std::size_t& key);
inline Vec3 pathPositionAt(const Emitter& e, double t, std::size_t& key) {
  return pathPositionAt(e.position, e.velocity, e.start, e.path, e.pathLoop, t, key);
}

/// The newborns of g's death emitter k from the deaths `source` recorded in the step that
/// ended at t1, appended to g (its bounds grown to hold them when they are kept), in the
/// order of the deaths; counted in g's statistics like any emission.
void emitFromDeaths(GroupImpl& g, std::size_t k, const GroupImpl& source, std::uint64_t seed);

/// Drops the live emitters that died by t1 (after their last births are written).
void retireDead(GroupImpl& g, double t1);

/// Writes newborns [0, accepted) of this step's runs (runStart[r]: the first of run r;
/// runCount runs) at the end of the group, each with the time it has left of the step in
/// g.bornRemaining, in parallel. Compiled per instruction set (newborns.cpp).
void writeNewborns(GroupImpl& g, const StepParams& sp, const BirthRun* runs,
                   const std::uint64_t* runStart, std::size_t runCount, std::size_t accepted);

inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp
/// A Rate run's birth of `index` since the emitter's start (1 the first), and a Distance
/// run's birth q: their times, the indices in double (exact below 2^53, as the integers were),
/// so that a batch's loop over them vectorises (newborns.cpp birthTimes).
inline double rateBirthTime(const Emitter& em, double index) {
  return em.start + index / em.rate;
}
inline double distanceBirthTime(const BirthRun& run, double q) {
  return run.time + run.dt * (run.s0 + q * run.spacing) / run.span;
}
inline double birthTime(const BirthRun& run, const Emitter& em, std::uint64_t q) {
  switch (run.kind) {
    case BirthRun::Rate:
      return rateBirthTime(em, double(run.first + q + 1));
    case BirthRun::Burst:
      return run.time;
    default:
      return distanceBirthTime(run, double(q));
  }
}

inline const Emitter& emitterOf(const GroupImpl& g, const BirthRun& run) {
  return run.live ? g.live[run.index].emitter : g.emitters[run.index];
}

/// The type a newborn takes, by the types' weights, from the uniform u (kernels/newborn.h
/// FL_CHOOSE_TYPE, the device's walk too; the total summed in order, as its host does).
inline std::size_t chooseType(const std::vector<ParticleType>& types, float u) {
  float total = 0;
  for (const auto& t : types) total += t.weight;
  const auto weightOf = [&](kernel::uint k) { return types[k].weight; };
  kernel::uint type;
  FL_CHOOSE_TYPE(type, kernel::uint(types.size()), weightOf, u * total);
  return type;
}
/// The same from rng's next draw, when there are several (one type draws nothing).
inline std::size_t chooseType(const std::vector<ParticleType>& types, Random& rng) {
  return types.size() == 1 ? 0 : chooseType(types, rng.uniform());
}
}  // namespace FLURRY_ISA_NAMESPACE

}  // namespace flurry::detail
