// Trilinear lookup in a sampled vector field: the one definition that VectorField::sample,
// the fused pass's SampledField action and the device's act kernel all use
// (kernels/forces.h fl_grid_sample, over the same floats).
#pragma once

#include <cstddef>

#include "flurry/field.hpp"
#include "forces_kernel.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

static_assert(sizeof(Vec3) == 3 * sizeof(float), "a field's vectors are read as floats");

inline Vec3 sampleTrilinear(const VectorField& f, Vec3 p) {
  return kernel::fl_grid_sample(reinterpret_cast<const float*>(f.data.data()), f.dims.x, f.dims.y,
                                f.dims.z, f.origin.x, f.origin.y, f.origin.z, f.voxelSize, p.x, p.y,
                                p.z);
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
