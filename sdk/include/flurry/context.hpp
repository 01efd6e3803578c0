// The Context: owns groups, the seed, the time step, the thread pool and the backend.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "flurry/group.hpp"
#include "flurry/scheduler.hpp"

namespace flurry {

namespace detail {
struct ContextAccess;  // the library's way in (sdk/src/context.cpp)
}  // namespace detail

enum class Backend { Cpu, OpenCL, Auto };

struct ContextOptions {
  std::uint64_t seed = 1;
  double dt = 1.0 / 30.0;  ///< seconds per step
  unsigned threads = 0;    ///< 0: one per hardware thread
  Backend backend = Backend::Cpu;
  /// OpenCL: a substring of the platform or device name to use; empty takes the first GPU,
  /// else the first device.
  std::string device;
  /// CPU fused pass: skips an action with a finite reach (a deflector on a finite piece, an
  /// absorber, a blocker, a force's falloff radius) for a block of particles that cannot
  /// reach it this step. Exact: results are bitwise the same either way; false is for
  /// comparisons.
  bool cull = true;
  /// A game's job system to run the parallel work on (TaskScheduler); null: the Context's
  /// own threads. With one, `threads` must be 0: its concurrency() says how many.
  std::shared_ptr<TaskScheduler> scheduler;
};

/// What a game shows in its performance overlay: the context's groups, instances and
/// particles now, what its last step cost and what was dropped (Context::stats).
struct ContextStats {
  std::size_t groups = 0;
  /// Effect instances: the distinct INSTANCE names of groups named "GROUP@INSTANCE".
  std::size_t instances = 0;
  std::size_t particles = 0;  ///< alive now, in all groups
  std::size_t capacity = 0;   ///< all groups' capacities together
  /// Wall-clock seconds of the last step() (its death emitters included).
  double lastStepSeconds = 0.0;
  /// The last step's parts over every group, as GroupStats::stepSeconds counts them (CPU
  /// seconds: groups stepped side by side on several threads add up).
  GroupStats::StepSeconds lastStepParts;
  /// Over the groups' lives, all groups together (see GroupStats).
  std::uint64_t emitted = 0;
  std::uint64_t droppedAtCapacity = 0;
  std::uint64_t droppedAtBudget = 0;
  std::uint64_t killedByBudget = 0;
  std::uint64_t deathEventsDropped = 0;
  std::uint64_t collisionEventsDropped = 0;
  std::uint64_t idleSteps = 0;
};

class Context {
 public:
  explicit Context(ContextOptions options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  /// The most particles all groups together should hold (0: no budget, the default). Before
  /// each step the room left under it is shared among the groups that emit, in proportion
  /// to what each asked for the step before (alike at first); a group's BudgetPolicy says
  /// what it gives up past its share. When the budget is lowered below the particles alive,
  /// DropOldest groups shrink at once (by their share of the excess), the others by not
  /// emitting until deaths bring the context under it. Deterministic: the same on any
  /// thread count. The CPU backend keeps it (a device context throws Error).
  void setParticleBudget(std::size_t particles);
  std::size_t particleBudget() const;

  /// Creates a group of fixed capacity (> 0; throws InvalidArgument "capacity").
  Group& createGroup(std::string name, std::size_t capacity);
  /// Destroys a group of this context, its particles and its emitters (on a device, after
  /// the work queued for it); references to it are invalid after. The others are untouched.
  /// A group created later takes the lowest free index, and with it the destroyed group's
  /// random streams. Throws InvalidArgument "group" for a group of another context.
  void destroyGroup(Group& group);
  /// The group of that name; throws Error if there is none.
  Group& group(std::string_view name);
  std::vector<Group*> groups();

  /// Advances every group by one step of timeStep() seconds: emitters create the step's
  /// newborns where and when each is born, the action list runs as one fused pass over
  /// every particle (a newborn for what is left of the step after its birth), and the dead
  /// are removed.
  void step();
  void run(std::size_t steps) {
    for (std::size_t i = 0; i < steps; ++i) step();
  }

  /// Starts `groups` (an effect instance's: EffectInstance::prewarm) as if they had been
  /// created `seconds` earlier and stepped with the context since: they alone take the fewest
  /// whole steps of timeStep() that cover `seconds`, nothing is drawn or read back, and the
  /// context's clock does not move. They then stay those steps ahead of it (their step index
  /// and time are the context's plus these), so they go on as they would have: the particles
  /// are bitwise those of stepping them by hand from the start. Returns the steps taken.
  /// Throws InvalidArgument "seconds" (negative, not finite) or "groups" (not this context's).
  std::uint64_t prewarm(std::span<Group* const> groups, double seconds);

  double time() const;
  /// The time on `group`'s own clock, where its next step starts: time() unless the group
  /// runs ahead (prewarm) or at another rate (Group::setTimeScale). Throws InvalidArgument
  /// "group" for a group of another context.
  double time(const Group& group) const;
  std::uint64_t stepIndex() const;
  double timeStep() const;
  /// Throws InvalidArgument "dt" unless 0 < dt <= 10 and finite.
  void setTimeStep(double dt);
  unsigned threads() const;
  std::uint64_t seed() const;
  /// The backend the context runs: with Backend::Auto, OpenCL or the CPU.
  Backend backend() const;
  /// Why Backend::Auto took the CPU backend (no OpenCL platform, no such device, ...);
  /// empty when it did not. The library reports it here rather than printing it.
  const std::string& backendFallback() const;
  const ContextOptions& options() const;
  /// Sums the groups' statistics now (a walk over the groups: call it once a frame, not per
  /// group). On a device backend the live counts are brought up to date first.
  ContextStats stats() const;

 private:
  friend struct detail::ContextAccess;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flurry
