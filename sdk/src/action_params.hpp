// The constants an action's kernel functions read, made once for both backends (the records
// are kernels/params.h's): the CPU backend's pass and the OpenCL packer call the same maker,
// and the shared kernel functions (kernels/forces.h, deflect.h, ...) read what it made.
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

/// An action's record (FlActionParams::own) and its falloff, for steps of length dt (the
/// exponentials of -rate·dt it holds are for that dt). What lives in the device's own storage
/// (a domain's packed form, a grid's or a curve's floats and where they are) its packer adds.
/// Zero for an action without constants.
cl::FlActionParams actionParams(const Action& a, float dt);

}  // namespace flurry::detail
