// Curl noise for Turbulence: its math is kernels/noise.h, the same source the OpenCL backend
// compiles (kernel_compat.hpp).
#pragma once

#include "kernel_compat.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp
namespace kernel {
#include "../../kernels/noise.h"
}  // namespace kernel

/// The curl of a vector potential of three gradient-noise fields: divergence-free by
/// construction. Octaves double the frequency and halve the amplitude.
inline Vec3 curlNoise(Vec3 p, int octaves = 1) {
  return kernel::fl_curl_noise(p.x, p.y, p.z, kernel::uint(octaves));
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
