// Kernel source generation and parameter packing: one program per distinct (action list
// structure, stored attributes), its numbers passed in buffers so that changing a value
// (gravity, a restitution) does not recompile.
#pragma once

#include <string>
#include <vector>

#include "../../../kernels/params.h"
#include "flurry/actions.hpp"
#include "flurry/attribute.hpp"
#include "flurry/emitter.hpp"

namespace flurry::detail::ocl {

/// One stored lane (one component of an attribute) as the kernels name it.
struct LaneRef {
  Attribute attribute;
  int component;
  const char* name;  ///< l_<name> in kernels
};

/// The lanes of `stored`, in the canonical order the kernels take them.
std::vector<LaneRef> lanesOf(AttributeSet stored);

struct GeneratedProgram {
  std::string source;
  std::string options;
  std::vector<LaneRef> actLanes;  ///< fl_act's lane parameters, in order
};

/// The program for this list over these stored attributes: the embedded kernels plus one
/// generated fused act kernel (fl_act) that runs exactly the list's actions, in order, and
/// loads and stores exactly the lanes they use.
/// The emission code is generated too: per emitter and particle type, a call with the domain
/// kinds and fuzzy modes as literals (its numbers travel in buffers).
GeneratedProgram generateProgram(const ActionList& actions, AttributeSet stored, bool fp64,
                                 const std::vector<Emitter>& emitters);

/// What of the emitters shapes the program (domain kinds, type counts, which fuzzy values
/// draw): a new program is needed when this changes.
std::string emitterSignature(const std::vector<Emitter>& emitters);

/// The actions' constants for a step of dt seconds (products with dt rounded as on the CPU).
void packActions(const ActionList& actions, float dt, std::vector<cl::FlActionParams>& out);

/// A domain as the sampling and containment code on the device reads it.
cl::FlDomain packDomain(const Domain& d);

/// Embedded kernels/ files by name ("emit.cl"); throws Error for an unknown name.
const char* embeddedKernel(const char* name);

}  // namespace flurry::detail::ocl
