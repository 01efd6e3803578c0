// A cheap clock for the phases of a group's step (GroupStats::stepSeconds). A game steps
// thousands of small groups, each timed four times a step: a steady_clock read costs ~24 ns
// (clock_gettime through the vDSO), the x86 time-stamp counter ~10 ns, on this project's
// machines 4-5 % of a 100-particle group's step.
#pragma once

#include <cstdint>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <x86intrin.h>
#define FLURRY_TICKS_TSC 1
#endif

namespace flurry::detail {

namespace ticks {
/// Whether ticksNow() reads the time-stamp counter (x86 with an invariant one: the same rate
/// on every core and in every power state; asked of CPUID once, when the library loads);
/// otherwise it reads steady_clock in nanoseconds.
extern const bool counterUsed;
std::uint64_t steadyNanoseconds();
}  // namespace ticks

/// Ticks of an unspecified unit; differences turn into seconds by ticksToSeconds.
inline std::uint64_t ticksNow() {
#ifdef FLURRY_TICKS_TSC
  if (ticks::counterUsed) return __rdtsc();
#endif
  return ticks::steadyNanoseconds();
}

/// Seconds of `ticks` (a difference of ticksNow()), at the counter's rate as measured against
/// steady_clock since the library loaded (recalibrateTicks refines it).
double ticksToSeconds(std::uint64_t ticks);

/// Measures the counter's rate again over the whole time since the library loaded (more
/// exact the longer it runs). Context::step calls it once a step, beside its own
/// steady_clock reads. Thread-safe.
void recalibrateTicks();

}  // namespace flurry::detail
