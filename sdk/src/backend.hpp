// The backend interface: how one step of one group is carried out.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "flurry/context.hpp"
#include "group_impl.hpp"
#include "thread_pool.hpp"

namespace flurry::detail {

struct StepParams {
  double time = 0.0;  ///< at the start of the step
  double dt = 0.0;
  /// Where the step ends: exactly where the group's next step starts, which `time + dt` is
  /// not always (the clock is base + steps·dt, and a sum rounds either side of it: a burst at
  /// 0.6 s with dt = 0.1 fell between two steps, one at 1.3 s fired in both). What ends the
  /// step (emission's window, events' time, deaths' time) reads this.
  double end = 0.0;
  std::uint64_t seed = 0;
  std::uint64_t step = 0;
  /// A group with a clock of its own (GroupImpl::ownsClock): the length of one of its units
  /// (scale·dt; dt spans skipped + 1 of them).
  double clockUnit = 0.0;
  std::size_t blockSize = 0;
  bool fused = true;
  bool cull = true;
  ThreadPool* pool = nullptr;
  /// The group this thread steps two after this one: Context::step asks for the first half
  /// of its data (GroupImpl::prefetchData) before this step, the CPU backend for the second
  /// between this step's phases. (In one burst the prefetches stall the core.)
  const GroupImpl* ahead = nullptr;
};

class BackendImpl {
 public:
  virtual ~BackendImpl() = default;
  virtual const char* name() const = 0;
  /// Emit the step's newborns, act on every particle (the newborns for what is left of the
  /// step after their birth), remove the dead.
  virtual void step(GroupImpl& group, const StepParams& params) = 0;
  /// step() in two parts, so that Context::step can run several groups' first parts and then
  /// their second parts (groups are independent): true when the second part is due.
  virtual bool stepFirstPart(GroupImpl& group, const StepParams& params) {
    step(group, params);
    return false;
  }
  virtual void stepSecondPart(GroupImpl&, const StepParams&) {}
};

std::unique_ptr<BackendImpl> makeCpuBackend();
#ifdef FLURRY_WITH_OPENCL
/// The OpenCL backend on the device `options` names (or the first one). Throws Error, saying
/// why, when there is no OpenCL platform or device.
std::unique_ptr<BackendImpl> makeOpenCLBackend(const ContextOptions& options);
#endif

/// Runs the group's action list over [0, size) as one fused pass, the newborns for what is
/// left of the step after their birth, and gathers the dead into group.holes (ascending)
/// with their kill counts tallied into group.stats.
void actFused(GroupImpl& group, const StepParams& params);
/// Hair mode: runs the group's newborns to their deaths through its action list, recording
/// their paths as strands; the group keeps no live particles.
void simulateHair(GroupImpl& group, const StepParams& params);
/// The instruction set the fused pass runs with here: "avx512", "avx2" or "baseline".
const char* fusedPassIsa();
/// Creates the step's newborns from the emitters at the end of the group, where they were
/// born, each with the part of the step it still has to live (group.bornFirst, bornCount,
/// bornRemaining): the act pass that follows runs them through the action list for it.
void emitNewborns(GroupImpl& group, const StepParams& params);
/// Whether the group's emitters (static, prime or live) could give birth, or change their
/// state, over this step: false only when a step would leave them as they are.
bool mayEmit(const GroupImpl& group, const StepParams& params);
/// Whether they could ever give birth again after time `at` (mayEmit over (at, infinity)).
bool mayEverEmit(const GroupImpl& group, double at);
/// Stops every emitter and prime emitter of the group at time `at` (the frame's own copies
/// too): nothing is born from `at` on, a burst due at `at` included. With `showers`, the live
/// emitters that prime emitters spawned go too; else they live out their lives.
void stopEmitting(GroupImpl& group, double at, bool showers);
/// Fills the act pass's holes with the live particles at the tail, so [0, size) is dense
/// again.
void compact(GroupImpl& group, const StepParams& params);

/// Every lane a particle has (its attributes' and its trail's), as words: what compaction
/// moves.
using StoredLanes = std::array<std::uint32_t*, std::size_t(Attribute::Count) * 4 +
                                                   3 * TrailOptions::kMaxLength + 1>;
/// Fills `stored` with the group's lanes; returns how many.
std::size_t storedLanes(GroupImpl& group, StoredLanes& stored);

}  // namespace flurry::detail
