// The OpenCL backend's internals that tests and benchmarks reach (they include sdk/src).
#pragma once

#include "../backend.hpp"
#include "runtime.hpp"

namespace flurry::detail::ocl {

/// Waits until the device has finished every step queued for `group`, without reading any
/// particles back (the benchmarks' end of a timed run). No-op on the CPU backend.
void finishGroup(GroupImpl& group);

/// The source and options of the program the OpenCL backend builds for this list over
/// these attributes (tests, docs, and reproducing a build failure outside Flurry).
std::string programSource(const ActionList& actions, AttributeSet stored, bool fp64);

/// How a small group's one launch (fl_small) lays its particles over its work-items: by the
/// device (runs of FL_SMALL_RUN on a CPU, which vectorise there; strided on a GPU, side by
/// side in memory), or either one on any device (tests: both layouts on the device they
/// have). Programs built after the call follow it.
enum class SmallLayout { ByDevice, Runs, Strided };
void setSmallLayout(SmallLayout layout);

}  // namespace flurry::detail::ocl
