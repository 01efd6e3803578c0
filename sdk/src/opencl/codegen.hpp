// Kernel source generation and parameter packing: one program per distinct (action list
// structure, stored attributes), its numbers passed in buffers so that changing a value
// (gravity, a restitution) does not recompile.
#pragma once

#include <cstring>
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
  std::vector<LaneRef> actLanes;    ///< fl_act's lane parameters, in order
  bool neighbours = false;          ///< fl_act reads the snapshot of p, v, rot
  bool substepsByDistance = false;  ///< fl_max_speed runs before fl_act
  bool small = false;               ///< has fl_small: a small group's whole step in one work-group
  bool culls = false;               ///< fl_act and fl_small cull per work-group (reachOff)
};

/// The program for this list over these stored attributes: the embedded kernels plus one
/// generated fused act kernel (fl_act) that runs exactly the list's actions, in order, and
/// loads and stores exactly the lanes they use. `emitSource` is the generated emission code
/// (emission.hpp emissionSource), placed before tail.cl. With `hair`, the program also has
/// fl_hair, which runs each newborn's whole life as a strand (hair mode). With `cull`,
/// fl_act and fl_small skip actions out of a work-group's reach (ContextOptions::cull). With
/// `collisions`, fl_act logs each Bounce's deflections into its last two arguments (fl_hits,
/// fl_hitRoom: surfaces.cl fl_log_collision), and there is no fl_small (fl_hair logs none,
/// as the CPU's hair mode records only its birth step's).
GeneratedProgram generateProgram(const ActionList& actions, AttributeSet stored, bool fp64,
                                 const std::string& emitSource, bool hair = false,
                                 bool cull = false, bool collisions = false);

/// The build options of every Flurry program.
inline constexpr const char* kProgramOptions =
    "-cl-std=CL1.2 -cl-fp32-correctly-rounded-divide-sqrt";

/// The trails' program (kernels/trail.cl: fl_trail_start, fl_trail_tail, fl_trail_record),
/// the same for every group; its options are generateProgram's.
std::string trailProgramSource(bool fp64);

/// What the generator of one action writes into the fused act kernel.
///
/// The act kernel holds each particle in registers named after its lanes (px py pz, vx vy vz,
/// r g b a, size, mass, age, life, id, prevx.., upx.., rotx.., charge, vis, user, pbx.. for
/// PositionB, vbx.. for VelocityB) and has in scope:
///   float dt              the (sub-)step's length
///   fl_real time          the (sub-)step's start time (double where the device has fp64)
///   uint seedLo, seedHi, step   the Philox key and counter parts, as on the CPU
///   uint streamBase       the group's stream base, without the sub-step (in.stream has it)
///   uint i, n             the particle's index and the live count at the start of the step
///   uint dead             0, or the first kill code of this step (set it only when 0)
///   __global const FlActionParams* ap   the list's constants (ap[k] is this action's)
///   __global const float* extra         the list's variable-length constants
///   __global const float* snap          neighbours: p, v, rot at the step's start:
///                                       FL_SNAP(a, c, j) (a: 0 p, 1 v, 2 rot; c: x y z)
///   uint snapN                          the particles in snap
/// The strings in `in` name this action's pieces; generators fill `out`.
struct ActionSource {
  struct In {
    std::size_t index = 0;  ///< k, the action's place in the list
    AttributeSet stored;    ///< what the group stores
    std::string params;     ///< "(ap + k)"
    std::string code;       ///< the kill code literal, "(k+1)u"
    std::string stream;     ///< the Philox stream expression of this action (CPU's
                            ///< streamBase + action, with the sub-step folded in)
  } in;
  AttributeSet reads, writes;  ///< lanes loaded before the list and stored after it
  std::string apply;           ///< statements: the action as its own update, in list order
  /// Forces only (isForce): statements adding this force's acceleration at the state
  /// (px..vz, t) to ax, ay, az, used by the integrators other than semi-implicit Euler.
  /// They must read the state through the names px py pz vx vy vz and fl_real t only.
  std::string accel;
};

// Each family's generator: false when the action is not the family's.
// actions_core.cpp: Move, KillOld, CopyVertexB, Restore, Callback.
bool generateCoreAction(const Action& a, ActionSource& s);
// actions_forces.cpp (kernels/forces.cl): forces, random and target actions, over-life curves.
bool generateForceAction(const Action& a, ActionSource& s);
// actions_surfaces.cpp (kernels/surfaces.cl): deflectors, absorbers, blockers, 2-D, and the
// actions that read neighbours.
bool generateSurfaceAction(const Action& a, ActionSource& s);
/// A planar Bounce's call when the next Move integrates with the acceleration held in the
/// variables `acc` + "x", "y", "z" (fl_bounce_planar_accel); "" for other surfaces.
std::string bounceOnCurve(const Bounce& b, const std::string& params, const std::string& acc);

/// Throws the Error that says an action (or a variant of one) does not run on the device.
[[noreturn]] void notOnDevice(const std::string& what);

/// The actions' constants for a step of dt seconds: each one's record, as the CPU's pass
/// makes it (actionParams), with what lives in the device's storage added (a domain's packed
/// form; a mesh's, a grid's or a curve's floats in `extra`). The list went through
/// generateProgram first, which refuses what does not run on the device.
void packActions(const ActionList& actions, float dt, std::vector<cl::FlActionParams>& out,
                 std::vector<float>& extra);

/// Sub-steps of a step of dt seconds by Substeps::maxStep (fused_pass.cpp makePlan).
std::uint32_t stepSubsteps(const ActionList& actions, double dt);

/// A double as the kernels receive it (params.h: doubles travel as their bit patterns).
inline std::uint64_t doubleBits(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

inline void putVec(float* v, int at, Vec3 x) {
  v[at] = x.x;
  v[at + 1] = x.y;
  v[at + 2] = x.z;
}

/// A domain as the sampling and containment code on the device reads it.
cl::FlDomain packDomain(const Domain& d);

/// Embedded kernels/ files by name ("emit.cl"); throws Error for an unknown name.
const char* embeddedKernel(const char* name);

}  // namespace flurry::detail::ocl
