// kernels/forces.h on the CPU: the forces' per-particle math and the functions that read each
// force's record (kernels/params.h), compiled as C++ in each instruction-set build
// (kernel_compat.hpp), as the device compiles the same file.
#pragma once

#include "../../kernels/params.h"
#include "isa_namespace.hpp"
#include "kernel_compat.hpp"
#include "noise.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp
namespace kernel {
// The records forces.h and deflect.h read.
using cl::FlAvoidParams;
using cl::FlBounceParams;
using cl::FlConstrain2DParams;
using cl::FlDampingParams;
using cl::FlElectricParams;
using cl::FlExplosionParams;
using cl::FlFalloffParams;
using cl::FlGravityParams;
using cl::FlJetParams;
using cl::FlMagneticParams;
using cl::FlMatchParams;
using cl::FlOrbitLineParams;
using cl::FlOrbitPointParams;
using cl::FlPullParams;
using cl::FlRestoreParams;
using cl::FlSampledFieldParams;
using cl::FlSpeedClampParams;
using cl::FlTargetParams;
using cl::FlTurbulenceParams;
using cl::FlVortexParams;
using cl::FlXyz;
inline double fl_real_from_bits(ulong b) {  // params.h: doubles travel as their bits
  return std::bit_cast<double>(b);
}
#include "../../kernels/forces.h"
}  // namespace kernel
}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
