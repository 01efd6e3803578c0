// Emission on the device. The host plans each step's births (which emitter, how many,
// when: emission.cpp's rules, run on a handful of emitters) into runs and tables; the
// generated fl_emit (one call per emitter and particle type, domain kinds and fuzzy modes
// as literals) writes the newborns on the device, in fl_tail.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "../backend.hpp"
#include "../group_impl.hpp"
#include "codegen.hpp"

namespace flurry::detail::ocl {

/// One step's emission tables, read by fl_tail.
struct StepTables {
  std::vector<cl::FlBirthRun> runs;
  std::vector<cl::FlEmitter> emitters;
  std::vector<cl::FlParticleType> types;
  std::vector<cl::FlKeyframe> keys;
};

/// Refuses, naming it, what of the group's emission the device does not run.
void checkEmissionSupported(const GroupImpl& g);

/// This step's births into `t` (and the group's emitter state and counts, as the CPU's
/// planning does); returns how many.
std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, StepTables& t);

/// The generated emission code: fl_emit(), dispatching on the emitter (and type).
std::string emissionSource(const GroupImpl& g);

/// What of the emitters shapes the program (domain kinds, type counts, which fuzzy values
/// draw): a new program is needed when this changes.
std::string emitterSignature(const GroupImpl& g);

}  // namespace flurry::detail::ocl
