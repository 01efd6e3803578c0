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

}  // namespace flurry::detail::ocl
