#include "tick_clock.hpp"

#include <atomic>
#include <chrono>

#ifdef FLURRY_TICKS_TSC
#include <cpuid.h>
#endif

namespace flurry::detail {

namespace ticks {
std::uint64_t steadyNanoseconds() {
  return std::uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                           std::chrono::steady_clock::now().time_since_epoch())
                           .count());
}

namespace {
bool invariantCounter() {
#ifdef FLURRY_TICKS_TSC
  // CPUID 0x80000007, EDX bit 8: the invariant TSC. (Under a hypervisor CPUID traps and
  // costs microseconds: asked once.)
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __get_cpuid(0x80000007u, &a, &b, &c, &d) && (d >> 8 & 1u);
#else
  return false;
#endif
}
}  // namespace

const bool counterUsed = invariantCounter();
}  // namespace ticks

namespace {
struct Baseline {
  std::uint64_t steady, ticks;
};

// Both clocks read together when the library loads (after counterUsed, defined above it in
// this file): rates are measured from here on.
const Baseline baseline{ticks::steadyNanoseconds(), ticksNow()};

std::atomic<double> secondsPerTick{0.0};

// The rate over [baseline, now]; at least 50 µs of it, so the first figure is already
// within a fraction of a percent (waited for only if the first step comes sooner than that
// after the library loaded).
double measure() {
  const Baseline& b = baseline;
  if (!ticks::counterUsed) return 1e-9;
  std::uint64_t s = ticks::steadyNanoseconds(), t = ticksNow();
  while (s - b.steady < 50'000 || t == b.ticks) {
    s = ticks::steadyNanoseconds();
    t = ticksNow();
  }
  return double(s - b.steady) * 1e-9 / double(t - b.ticks);
}
}  // namespace

void recalibrateTicks() {
  secondsPerTick.store(measure(), std::memory_order_relaxed);
}

double ticksToSeconds(std::uint64_t ticks) {
  double rate = secondsPerTick.load(std::memory_order_relaxed);
  if (rate == 0.0) {
    rate = measure();
    secondsPerTick.store(rate, std::memory_order_relaxed);
  }
  return double(ticks) * rate;
}

}  // namespace flurry::detail
