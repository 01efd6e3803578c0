// The constants an action's kernel function reads, made once for both backends (the records
// are kernels/params.h's): the CPU backend's loops and the OpenCL packer call the same maker.
// Defined in actions.cpp, outside the instruction-set builds, so each of those calls one copy.
#pragma once

#include "../../kernels/params.h"
#include "flurry/actions.hpp"

namespace flurry::detail {

/// Which planar piece (FL_PIECE_*) a Bounce's surface is, or -1 for a solid (sphere, box).
int planarPiece(const Bounce& b);

/// Bounce's plane and piece (or a sphere's center and radii), as kernels/deflect.h reads them;
/// its reflection (restitution, 1 - friction, cutoff²) too.
cl::FlBounceParams bounceParams(const Bounce& b);

}  // namespace flurry::detail
