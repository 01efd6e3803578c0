// Emission on the device. The host plans each step's births (which emitter, how many,
// when: emission.cpp's rules, run on a handful of emitters, prime and live emitters
// included) into runs and tables; the generated fl_emit (one case per distinct emitter
// code: domain kinds and fuzzy modes as literals) writes the newborns on the device, in
// fl_birth.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "../backend.hpp"
#include "../group_impl.hpp"
#include "codegen.hpp"

namespace flurry::detail::ocl {

/// One step's emission tables, read by fl_birth.
struct StepTables {
  std::vector<cl::FlBirthRun> runs;
  std::vector<cl::FlEmitter> emitters;
  std::vector<cl::FlParticleType> types;
  std::vector<cl::FlKeyframe> keys;
  /// Mesh and union domains' data (domain.cl: FL_MESH_STRIDE, FL_UNION_STRIDE); integers
  /// and doubles as bit patterns.
  std::vector<float> shapes;
};

/// Domains as the device reads them: packDomain's, and for meshes and unions an FlDomain
/// that points into `data`, where their data goes (domain.cl documents the layout), each
/// once per packer. The offsets are indices into `data`, which the kernels get as the table:
/// the step's shape table (emitters) or the action list's `extra` (actions' regions and
/// sampled domains).
struct ShapePacker {
  std::vector<float>& data;
  std::map<const void*, std::uint32_t> meshes;
  std::map<const void*, std::array<std::uint32_t, 3>> unions;  // parts, leaves, leaf count

  cl::FlDomain pack(const Domain& d);

 private:
  std::uint32_t mesh(const MeshData& m);
  static void leavesOf(const Domain& d, std::vector<const Domain*>& out);
  void put(std::size_t at, const cl::FlDomain& o);
};

/// Refuses, naming it, what of the group's emission the device does not run.
void checkEmissionSupported(const GroupImpl& g);

/// The distinct emitter codes of a group's program (one fl_emit case each), in order.
struct Variants {
  std::vector<std::string> code;
  std::map<std::string, std::uint32_t> index;

  void add(const Emitter& e);
  void addChain(const EmitterSpec* s);
  /// Throws Error when e's code is not in the program.
  std::uint32_t of(const Emitter& e) const;
};

/// What the backend derives from a group's emitters, kept between steps: rebuilt when
/// GroupImpl::emittersVersion moves (or a static emitter's kinds were edited through a
/// reference kept from before), so that a steady step builds no string and allocates
/// nothing. Also the planning's scratch.
struct EmitterCodes {
  std::uint64_t version = ~std::uint64_t(0);  ///< the emittersVersion it was built for
  Variants variants;                          ///< the program's emitter codes
  std::vector<std::uint32_t> staticVariant;   ///< per static emitter: its code's index
  std::vector<std::uint32_t> keys, scratch;   ///< the static emitters' kinds and modes
  // Per step: each emitter's entry in the tables, and live emitters' specs' codes.
  std::vector<std::uint32_t> entryOfStatic, entryOfLive;
  std::vector<std::pair<const EmitterSpec*, std::uint32_t>> specVariant;

  /// Brings the codes up to date with g; returns true when they changed (the program must
  /// then be rebuilt if emitterSignature changed).
  bool refresh(const GroupImpl& g);
};

/// This step's births into `t` (and the group's emitter state, live emitters and counts, as
/// the CPU's planning does: spawns, motion, deaths); returns how many. `codes` must be
/// those the program was built from (refresh()ed this step).
std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, StepTables& t, EmitterCodes& codes);

/// The generated emission code: fl_emit(), dispatching on the emitter (and type).
std::string emissionSource(const GroupImpl& g);
std::string emissionSource(const Variants& v);

/// What of the emitters shapes the program (domain kinds, type counts, which fuzzy values
/// draw): a new program is needed when this changes.
std::string emitterSignature(const Variants& v);

}  // namespace flurry::detail::ocl
