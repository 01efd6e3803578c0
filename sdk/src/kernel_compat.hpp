// The CPU side of the kernels' shared C subset: the files in kernels/ that hold math written
// once for both backends (noise.h, ...) compile here as C++ with OpenCL C's names for what
// they use (kernels/compat_opencl.h is the device's side), as Blender Cycles' kernels do.
// Include a shared file with #include "../../kernels/file.h" inside namespace
// flurry::detail::kernel: the namespace is inline-nested in the instruction set's
// (isa_namespace.hpp), so each build keeps its own copy of every function.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "flurry/math.hpp"
#include "isa_namespace.hpp"

#ifndef FL_INLINE
#define FL_INLINE inline
#endif
#ifndef FL_MATH_INLINE
// The elementary functions (fl_expf, fl_powf) always inline, as on the device: GCC left
// fl_powf out of line where a loop called several kernel functions, a call per particle that
// kept the loop scalar. (Every kernel function forced inline lost more loops than it won.)
#define FL_MATH_INLINE inline __attribute__((always_inline))
#endif
#ifndef FL_FP64
#define FL_FP64 1  // fl_real is double here, as on a device with cl_khr_fp64
#endif
#ifndef FL_GLOBAL
#define FL_GLOBAL  // the device's __global: one address space here
#endif
#ifndef FL_UNROLL
// The device's unroll pragma: a short loop of constant count unrolled whole (the noise's eight
// corners: a loop over particles around it then vectorises).
#if defined(__clang__)
#define FL_UNROLL _Pragma("unroll")
#else
#define FL_UNROLL _Pragma("GCC unroll 16")
#endif
#endif

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {
namespace kernel {

using uint = std::uint32_t;
using ulong = std::uint64_t;
using fl_real = double;  // the device's too where it has doubles (domain.cl)
using float3 = Vec3;
inline float3 make_float3(float x, float y, float z) {
  return Vec3(x, y, z);
}
inline uint as_uint(float f) {
  return std::bit_cast<uint>(f);
}
inline float as_float(uint u) {
  return std::bit_cast<float>(u);
}
using std::copysign;
using std::cos;
using std::exp;
using std::fabs;
using std::floor;
using std::fmod;
using std::log;
using std::pow;
using std::sin;
using std::sqrt;

#include "../../kernels/math.h"
#include "../../kernels/newborn.h"
#include "../../kernels/path.h"
#include "../../kernels/philox.h"

}  // namespace kernel
}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
