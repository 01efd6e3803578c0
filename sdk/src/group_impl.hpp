// The inside of a Group: lane storage and the per-step scratch the backends share.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "../../kernels/params.h"
#include "flurry/group.hpp"
#include "flurry/strands.hpp"
#include "flurry/transform.hpp"

namespace flurry::detail {

class ThreadPool;
struct StepParams;

/// One 64-byte aligned array of 32-bit values. Large arrays ask for transparent huge pages:
/// the update is bandwidth-bound, and huge pages measurably raise the bandwidth reached.
class LaneBuffer {
 public:
  LaneBuffer() = default;
  explicit LaneBuffer(std::size_t count);
  ~LaneBuffer();
  LaneBuffer(LaneBuffer&& o) noexcept : data_(o.data_), count_(o.count_) {
    o.data_ = nullptr;
    o.count_ = 0;
  }
  LaneBuffer& operator=(LaneBuffer&& o) noexcept;
  LaneBuffer(const LaneBuffer&) = delete;
  LaneBuffer& operator=(const LaneBuffer&) = delete;

  void* data() const { return data_; }
  float* f() const { return static_cast<float*>(data_); }
  std::uint32_t* u() const { return static_cast<std::uint32_t*>(data_); }
  explicit operator bool() const { return data_ != nullptr; }

 private:
  void* data_ = nullptr;
  std::size_t count_ = 0;
};

/// Raw pointers to every stored lane (nullptr where not stored), offset by a base index.
struct Lanes {
  float* p[3] = {};
  float* v[3] = {};
  float* color[4] = {};
  float* size = nullptr;
  float* mass = nullptr;
  float* age = nullptr;
  float* lifetime = nullptr;
  std::uint32_t* id = nullptr;
  float* prev[3] = {};
  float* up[3] = {};
  float* rot[3] = {};
  float* charge = nullptr;
  std::uint32_t* visible = nullptr;
  float* user = nullptr;
  float* posB[3] = {};
  float* velB[3] = {};
  float* birthColor[4] = {};
  float* birthSize = nullptr;

  /// The lanes from particle b on (a small group's one block starts at 0: no call).
  Lanes offset(std::size_t b) const { return b == 0 ? *this : offsetBy(b); }
  Lanes offsetBy(std::size_t b) const;

  /// The members are nothing but lane pointers, of 32-bit elements: slot k is the k-th in
  /// memory order. Loops that need not know which lane is which (moving, prefetching) read
  /// them as slots, not member by member.
  static constexpr int kSlots = 38;
  /// Slot k (null where not stored).
  std::uint32_t* slot(int k) const {
    std::uint32_t* lane;
    std::memcpy(&lane, reinterpret_cast<const char*>(this) + k * sizeof(lane), sizeof(lane));
    return lane;
  }
  /// Bit k set where slot k is stored.
  std::uint64_t storedSlots() const {
    std::uint64_t mask = 0;
    for (int k = 0; k < kSlots; ++k) mask |= std::uint64_t(slot(k) != nullptr) << k;
    return mask;
  }
};
static_assert(sizeof(Lanes) == Lanes::kSlots * sizeof(float*) &&
              std::is_trivially_copyable_v<Lanes>);

/// Calls f(lane) for each slot of `mask` (Lanes::storedSlots) in slot order.
template <class F>
void forEachSlot(const Lanes& l, std::uint64_t mask, F&& f) {
  for (; mask != 0; mask &= mask - 1) f(l.slot(std::countr_zero(mask)));
}

/// Calls f(pointer) with a reference to each of `l`'s lane pointers, null or not, in a fixed
/// order: the one list of a Lanes' members by name (Lanes::offset; loops that need not know
/// which lane is which walk them as slots, Lanes::slot).
template <class L, class F>
void forEachLanePointer(L& l, F&& f) {
  for (int c = 0; c < 3; ++c) {
    f(l.p[c]);
    f(l.v[c]);
    f(l.prev[c]);
    f(l.up[c]);
    f(l.rot[c]);
    f(l.posB[c]);
    f(l.velB[c]);
  }
  for (int c = 0; c < 4; ++c) {
    f(l.color[c]);
    f(l.birthColor[c]);
  }
  f(l.size);
  f(l.birthSize);
  f(l.mass);
  f(l.age);
  f(l.lifetime);
  f(l.id);
  f(l.charge);
  f(l.visible);
  f(l.user);
}

/// Gathers / scatters one particle's stored attributes (others read as Particle's defaults).
Particle readParticle(const Lanes& L, std::size_t i);
void writeParticle(const Lanes& L, std::size_t i, const Particle& p);

/// Per-emitter progress.
struct EmitterState {
  std::uint64_t emittedByRate = 0;  ///< particles the rate has produced so far
  double travelled = 0.0;           ///< distance since the last birth by spacing
};

/// An emitter spawned by a prime emitter (or at another one's death): it moves under its
/// spec's acceleration and drag, emits like an Emitter, and dies at `death`.
struct LiveEmitter {
  Emitter emitter;  ///< start = birth, stop = death; its path is set to this step's motion
  EmitterState state;
  const EmitterSpec* spec = nullptr;
  std::shared_ptr<const EmitterSpec> keepAlive;  ///< holds spec when it is a `next` level
  Vec3 position{0.0f}, velocity{0.0f};           ///< at the start of the current step
  double birth = 0.0, death = 0.0;
  std::uint32_t generation = 1;
  std::uint32_t id = 0;     ///< keys its random numbers
  std::uint32_t prime = 0;  ///< the prime emitter whose limit it counts against
};

struct GroupImpl;

/// Set by a backend that keeps a group's particles on its device between steps (OpenCL):
/// the host lanes are then brought up to date only when someone reads them.
class DeviceMirror {
 public:
  virtual ~DeviceMirror() = default;
  /// Brings the live count and the host lanes of `attributes` (those stored) up to date
  /// with the device's, reading back only lanes the device changed since the host last read
  /// them.
  virtual void pullToHost(GroupImpl& group, AttributeSet attributes) = 0;
  /// The host changed the particles or the storage: the device must take the host's copy.
  virtual void hostChanged(GroupImpl& group) = 0;
  /// Brings the group's statistics up to date (without reading particles back).
  virtual void syncStats(GroupImpl& /*group*/) {}
  /// The host appends particles (a death emitter's newborns): beginAppend brings the live
  /// count and the next id up to date, the host writes its lanes from there on, and
  /// endAppend(group, from) takes [from, size) to the device. By default the whole group
  /// goes both ways.
  virtual void beginAppend(GroupImpl& group) { pullToHost(group, AttributeSet::all()); }
  virtual void endAppend(GroupImpl& group, std::size_t /*from*/) { hostChanged(group); }
};

/// What the CPU fused pass derives from the action list alone. Built when the list changes
/// (GroupImpl::actionsVersion), not every step: a small group's step is short enough that
/// rebuilding it (and its allocations) would be a good part of the step.
struct ActionPlan {
  // First what a step reads; from coldStart on what only the planning reads.
  std::uint64_t version = ~std::uint64_t(0);  ///< the actionsVersion it was built for
  /// Per action: its record (actionParams), as the device gets it, made for steps of
  /// `recordsDt` (actionRecords): made again only for a new list or a new step length.
  std::vector<cl::FlActionParams> records;
  std::uint64_t recordsVersion = ~std::uint64_t(0);
  float recordsDt = 0.0f;
  Integrator integrator = Integrator::SemiImplicitEuler;
  /// Every action is time-free or takes own step lengths, and none takes a factor once for
  /// a block's step (factorPerStep): a block's newborns run the list with the block's other
  /// particles in one pass (each of those with the whole sub-step as its own).
  bool newbornsWithBlock = false;
  bool guarded = false;  ///< some Move guards against Bounces
  /// The NaN guard must scan velocities too: not when an explicit-Euler Move follows every
  /// action that changes them, as p + v·dt is then not finite wherever v is not.
  bool guardVelocity = true;
  bool readsNeighbours = false;        ///< the pass reads a snapshot of the step's start
  bool cullable = false;               ///< some action has a finite reach
  std::uint32_t firstBlocker = ~0u;    ///< index of the list's first Block action
  std::vector<std::uint8_t> gathered;  // a force an integrating Move evaluates
  // Per planar Bounce before a Move that integrates forces with Exact, Verlet or RK4: 1 +
  // that Move's index (it bounces on the curve the Move takes); else 0.
  std::vector<std::uint32_t> curvedBy;
  // Per action: its result does not depend on the step's length or time (a sink by region,
  // KillOld, colour over life, ...), so it runs over a block of newborns as over any block.
  std::vector<std::uint8_t> timeFree;
  /// Per action: where it can act (planActions: actionReach). A block whose swept bounds
  /// stay out of `lo`..`hi`, widened by the margin, is left bitwise as it was by the action.
  struct Reach {
    bool cullable = false;
    float lo[3] = {}, hi[3] = {};
    float scale = 0.0f;      ///< max |coordinate| of the box, for the rounding margin
    float quadratic = 0.0f;  ///< margin term in scale² (a sphere's grazing roots)
  };
  std::vector<Reach> reach;
  /// Per action: it may change positions or velocities (the bounds must be taken again).
  std::vector<std::uint8_t> moves;

  char coldStart = 0;  ///< GroupImpl::prefetchSelf() asks for the plan up to here
  /// The actionsStructure its fields other than the reach were built for (a move changes
  /// only the actions' constants, and of the plan only where they can act).
  std::uint64_t structure = ~std::uint64_t(0);
  std::vector<std::vector<std::uint32_t>> forcesOf;  // per Move: its forces
  std::vector<std::vector<std::uint32_t>> guardsOf;  // per Move: the Bounces before it
  // Per action: over a batch of newborns it runs with each one's own step length
  // (BlockContext::ownDt) in one call, as over a block; 0 where it reads the time itself
  // (it runs per newborn, at the newborn's own time).
  std::vector<std::uint8_t> ownDt;
  std::vector<float> fastest;  ///< scratch: per chunk, the fastest squared speed
};

/// A group placed in the world (Group::setTransform): its emitters and action list as the
/// user gave them, in the group's own frame. GroupImpl::emitters, primes and actions are their
/// images in the world, which the backends run. Absent until a transform is set, so a group
/// never placed runs exactly as before.
struct Frame {
  // First what every step reads (GroupImpl::placeEmitters): one cache line of it.
  /// GroupImpl::emittersVersion when the world emitters were last derived from these.
  std::uint64_t emittersDerived = ~std::uint64_t(0);
  /// The world's actions and emitters are the images of these at `transform`: false after a
  /// move left them to the group's next step (GroupImpl::placeEmitters), which the threads
  /// take in parallel, where Group::setTransform runs on the game's one.
  bool placed = true;
  Space space = Space::World;
  Transform transform;
  std::vector<Emitter> emitters;
  std::vector<PrimeEmitter> primes;
  ActionList actions;
  /// Whether these lists refuse some transform (a box turns only by quarter turns), as last
  /// found for the actionsStructure and emittersVersion in `probed`: a move of a group that
  /// may refuse it is placed at once, where the refusal can leave the group as it was. Found
  /// only once the lists stood still from one move to the next (`moved`: the versions at the
  /// last move), as a game's that edits them every frame are placed at once every time.
  bool mayRefuse = true;
  std::uint64_t probed[2] = {~std::uint64_t(0), ~std::uint64_t(0)};
  std::uint64_t moved[2] = {~std::uint64_t(0), ~std::uint64_t(0)};
};

/// What Effect::build gave a group, for EffectInstance::restart: its emitters, prime
/// emitters and action list as the effect has them (in the group's frame, their times from
/// the effect's start).
struct GroupOrigin {
  std::vector<Emitter> emitters;
  std::vector<PrimeEmitter> primes;
  ActionList actions;
};

/// Removes every emitter and prime emitter, and the emitters they spawned (the frame's copies
/// too): EffectInstance::restart then adds them anew.
void clearEmitters(GroupImpl& g);

/// v = n copies of `value`. Out of line in a baseline translation unit (group.cpp) for the
/// code built once per instruction set (cpu/fused_pass.cpp): a std::vector member it
/// instantiated itself would be a weak symbol, compiled with that set's instructions, which
/// the linker may keep for every build (tests/isa/check_variant_symbols.py).
void assignFill(std::vector<std::uint32_t>& v, std::size_t n, std::uint32_t value);
void assignFill(std::vector<float>& v, std::size_t n, float value);

/// What one step of the CPU pass writes and reads again before it returns: its dead (index
/// and cause, per block) and per-block tallies and bounds. A small group's (capacity up to
/// 32,768) is held by the thread that steps it: a game's thousands of small groups share
/// their thread's, in cache, where each of its own would be cold by its next step. A large
/// group keeps its own, freed with it. Grows, never shrinks.
struct PassScratch {
  std::vector<std::uint32_t> deadIndex;    ///< per block: [block*B, block*B + deadCount[block])
  std::vector<std::uint8_t> deadCode;      ///< 1 + index of the action that killed
  std::vector<std::uint32_t> deadCount;    ///< per block
  std::vector<std::uint32_t> culledCount;  ///< per block: actions the fused pass skipped
  /// Per block, the dead each action killed and, last, the non-finite ones: counted while
  /// the block is in cache, by its own thread, and summed after the pass.
  std::vector<std::uint32_t> blockKills;
  std::vector<float> blockBounds;       ///< per block: min xyz, max xyz of its live particles
  std::vector<std::size_t> deathStart;  ///< each block's first death event
  std::vector<float> stepStart;  ///< the unfused pass: positions at the step's start, for the guard
  /// A pass that fills holes as it goes: the fillers of the block being filled (room for a
  /// block), and per block whether it has run (set by the worker that ran it, read through
  /// std::atomic_ref by the one that fills from it).
  std::vector<std::uint32_t> spare;
  std::vector<std::uint32_t> blockDone;
  bool busy = false;  ///< a step on this thread is using it
};

struct GroupImpl;
/// The calling thread's PassScratch for one step of `group` (the group's own when it is
/// large, or while the thread's is in use). Out of line in group.cpp for the reason of
/// assignFill.
class PassScratchUse {
 public:
  explicit PassScratchUse(GroupImpl& group);
  ~PassScratchUse();
  PassScratchUse(const PassScratchUse&) = delete;
  PassScratchUse& operator=(const PassScratchUse&) = delete;
  PassScratch& operator*() const { return *scratch_; }
  PassScratch* operator->() const { return scratch_; }

 private:
  PassScratch* scratch_;
  bool threads_;  ///< the thread's (to release), not the group's
};

/// Brings group.plan up to date with its action list (when actionsVersion changed) and
/// returns it (cpu/cpu_backend.cpp).
const ActionPlan& planActions(GroupImpl& group);
/// The records of the group's actions for steps of dt (ActionPlan::records).
const cl::FlActionParams* actionRecords(GroupImpl& group, float dt);

struct GroupImpl {
  /// From the arena's huge pages, as its lanes (page_arena.hpp): a small group's step then
  /// walks no page table for it.
  static void* operator new(std::size_t bytes);
  static void operator delete(void* group, std::size_t bytes) noexcept;

  // The first cache line: what every step and a game's every frame read (a reader of the
  // box reads this line alone); the lane pointers fill the next five.
  std::size_t capacity = 0;
  std::size_t size = 0;
  /// Group::setSeed: the seed and stream its draws take (ownSeed) instead of the context's
  /// seed and `index`.
  std::uint64_t seed = 0;
  std::uint32_t index = 0;  ///< creation order in the context: keeps groups' random streams apart
  std::uint32_t stream = 0;
  Bounds stepBounds;  ///< of the last step's pass, when boundsValid
  bool ownSeed = false;
  /// Group::bounds() was asked: from then on the CPU pass takes the live particles' box
  /// every step, each block while it is in cache (no pass of its own).
  bool boundsWanted = false;
  bool boundsValid = false;  ///< stepBounds is the live particles' box now
  /// What keeps its random streams apart from other groups': `index`, or Group::setSeed's.
  std::uint32_t streamKey() const { return ownSeed ? stream : index; }

  /// The stored lanes' pointers (lanePointers()), taken again whenever `lanes` changes
  /// (ensureStorage): a step reads these 5 cache lines, not the 18 of the table.
  Lanes laneCache;
  std::uint64_t laneSlots = 0;  ///< laneCache.storedSlots()
  AttributeSet required{Attribute::Position, Attribute::Id};
  AttributeSet stored;  ///< what the lanes hold now
  ActionList actions;   ///< replace through Group::setActions, which bumps actionsVersion
  std::uint64_t actionsVersion = 0;
  /// Bumped by Group::setActions only: a move (Group::setTransform) changes the actions'
  /// constants (actionsVersion), never their kinds or order, so that a device backend keeps
  /// its program without generating it again.
  std::uint64_t actionsStructure = 0;
  std::vector<Emitter> emitters;
  /// Bumped wherever the emitters or prime emitters may change (addEmitter, emitters(),
  /// addPrimeEmitter): the OpenCL backend rebuilds what it derives from them only then.
  std::uint64_t emittersVersion = 0;
  std::vector<EmitterState> emitterState;
  std::vector<PrimeEmitter> primes;
  /// primes[k].child, shared with the live emitters spawned from it (a move rewrites one
  /// no live emitter holds in place).
  std::vector<std::shared_ptr<EmitterSpec>> primeSpecs;
  std::vector<LiveEmitter> live;  ///< grown only up to the primes' maxEmitters together
  HairOptions hair;
  TrailOptions trail;
  BudgetPolicy budgetPolicy = BudgetPolicy::DropNewest;
  /// Set by Context::step under a particle budget (Context::Impl::shareBudget), else
  /// unlimited: the births this step may still make, and (DropOldest) the most particles
  /// the group keeps after it.
  std::uint64_t birthAllowance = ~std::uint64_t(0);
  std::size_t keepAtMost = ~std::size_t(0);
  std::uint64_t lastDemand = 0;  ///< births the emitters planned in the last step
  /// Kills the `excess` first-born particles (smallest ids) and closes their holes.
  void dropOldest(std::size_t excess, const StepParams& params);
  /// Under a DropOldest budget, after a step or a sub-emitter's newborns: drops the first-born
  /// past keepAtMost. A device's group comes to the host for it and goes back whole (seldom:
  /// only past its share).
  void trimToBudget(const StepParams& params);
  /// The trails' ring (Group::setTrail): x, y, z lanes of slot k at 3k .. 3k + 2, length
  /// slots; slot trailHead holds the positions at the end of the last step, the slots before
  /// it (cyclically) the steps before. Moved with the particles by compaction.
  std::vector<LaneBuffer> trailLanes;
  LaneBuffer trailCount;  ///< per particle: the slots its trail fills, from trailHead back
  std::uint32_t trailHead = 0;
  /// The CPU fused pass wrote this step's positions into the ring's next slot itself.
  bool trailRecorded = false;
  /// Particles [from, to) start a trail where they are (newborns, added, alive when the
  /// trail began): one point, in slot trailHead.
  void startTrails(std::size_t from, std::size_t to);
  /// After a step: the ring turns and every live particle's position goes into the new head.
  void recordTrails(ThreadPool& pool);
  /// For the fused pass: the ring's next slot (x, y, z into `slot`) and the counts, or null
  /// without a trail; marks the step's positions as recorded by the pass. Out of line for
  /// the reason of assignFill.
  std::uint32_t* nextTrailSlot(float** slot);
  GroupStats stats;
  std::uint32_t nextId = 0;

  std::size_t deathsPerStep = 0;  ///< Group::recordDeaths; 0: not recording
  /// A death emitter names this group (set by Context::step): it records every death.
  bool deathsFeed = false;
  /// The deaths a step records: deathsPerStep, or the capacity while deathsFeed.
  std::size_t deathRoom() const { return deathsFeed ? capacity : deathsPerStep; }
  /// Of `total` events a step had, those the game's room (`perStep`; 0: not recording) left
  /// out: GroupStats' dropped counts are the game's, whatever a death or collision emitter
  /// fed by the group records beyond them (Group::deaths and collisions give the first
  /// `perStep`).
  static std::size_t leftOut(std::size_t total, std::size_t perStep) {
    return perStep > 0 && total > perStep ? total - perStep : 0;
  }
  GroupStats::StepSeconds lastStepParts;  ///< the last step's (the CPU backend's clock)
  std::size_t collisionsPerStep = 0;      ///< Group::recordCollisions; 0: not recording
  /// A collision emitter names this group (set by Context::step): it records every collision.
  bool collisionsFeed = false;
  std::size_t collisionRoom() const { return collisionsFeed ? ~std::size_t(0) : collisionsPerStep; }
  std::vector<CollisionEvent> collisionEvents;  ///< the last step's, reserved up to the room
  /// Out of line here (see assignFill): the pass clears `blocks` blocks' lists, adds to one,
  /// and takes the first collisionsPerStep of them in block order after.
  void beginCollisions(std::size_t blocks);
  void addCollision(std::size_t block, std::uint64_t key, const CollisionEvent& e);
  void endCollisions(std::size_t blocks);
  std::vector<DeathEvent> deathEvents;  ///< the last step's, reserved by recordDeaths
  /// A birth emitter names this group (set by Context::step): each step's newborns are kept
  /// as events (where and when born, the velocity then, the id; action 0) in birthEvents.
  bool birthsFeed = false;
  std::vector<DeathEvent> birthEvents;  ///< the last step's, reserved up to the capacity
  /// Keeps the step's newborns [bornFirst, bornFirst + bornCount) as birthEvents, before the
  /// pass moves them (t1: the step's end; each was born bornRemaining[r] before it).
  void recordBirths(double t1);
  bool onDevice = false;             ///< its context runs a device backend
  std::vector<std::uint32_t> holes;  ///< sorted dead indices of this step
  /// The first `holesFilled` of them the act pass has already filled, each with the live
  /// particle compact() would have moved there, the last from index `filledFrom`: compact()
  /// goes on from there (the same moves, in the same order, as if it made them all).
  std::uint32_t holesFilled = 0, filledFrom = 0;
  /// This step's newborns, written before the act pass: [bornFirst, bornFirst + bornCount),
  /// each with the part of the step it still has to live (seconds, bornRemaining[r]), which
  /// the pass runs it through the action list for.
  std::size_t bornFirst = 0, bornCount = 0;
  std::vector<float> bornRemaining;  ///< grows, never shrinks

  std::unique_ptr<DeviceMirror> mirror;  ///< null on the CPU backend
  std::unique_ptr<Frame> frame;          ///< null until Group::setTransform
  /// Steps this group runs ahead of its context's clock (Context::prewarm): its step index
  /// and time are the context's plus these steps.
  std::uint64_t stepsAhead = 0;
  /// Group::setTimeScale. Once it is not 1 (or an update interval is set) the group keeps a
  /// clock of its own, where its next step starts: clockBase + clockUnits·clockUnit, as the
  /// context keeps its own (no drift from adding a step at a time), based anew when the
  /// length of a unit (scale·dt) changes. clockBase is NaN until it starts.
  double timeScale = 1.0;
  double clockBase = std::numeric_limits<double>::quiet_NaN();
  /// Group::setUpdateInterval: it steps when (context step + updatePhase) % updateInterval
  /// is 0, over its skippedSteps + 1 steps' time.
  std::uint32_t updateInterval = 1, skippedSteps = 0;  // (updatePhase: with the cold part)
  std::uint64_t ownSteps = 0;  ///< steps taken: a seeded group's random step key
  bool clockStarted() const { return !std::isnan(clockBase); }
  bool ownsClock() const {
    return timeScale != 1.0 || updateInterval != 1 || clockStarted();  // (a skip starts it)
  }
  void startClock(double at) {
    clockBase = at;
    clockUnits = 0;
  }
  /// The clock `extra` units of `unit` past where it stands.
  double clockAt(double unit, std::uint64_t extra) const {
    if (unit != clockUnit) return clockBase + double(clockUnits) * clockUnit + double(extra) * unit;
    return clockBase + double(clockUnits + extra) * unit;
  }
  void advanceClock(double unit, std::uint64_t units) {
    if (unit != clockUnit) {
      clockBase = clockAt(clockUnit, 0);
      clockUnits = 0;
      clockUnit = unit;
    }
    clockUnits += units;
  }

  /// Brings the live count and `attributes` (default: all; before the host writes, all) up
  /// to date on the host.
  void syncHost(AttributeSet attributes = AttributeSet::all()) {
    if (mirror) mirror->pullToHost(*this, attributes);
  }
  /// The live count only.
  void syncCount() {
    if (mirror) mirror->pullToHost(*this, AttributeSet());
  }
  void hostChanged() {
    boundsValid = false;
    if (mirror) mirror->hostChanged(*this);
  }
  void syncStats() {
    if (mirror) mirror->syncStats(*this);
  }

  /// Derives the world actions and emitters from the frame's where a move left them to the
  /// step (Frame::placed), and the emitters where they may have changed (a step calls it
  /// first; no-op without a frame).
  void placeEmitters();

  /// Asks the memory for what a step of this group reads, a few groups ahead of stepping it
  /// (Context::step): a game's thousands of small groups are each out of cache by the next
  /// step, and their step would otherwise wait on one miss after another. prefetchSelf()
  /// first (this object), then, a group later, prefetchData() (its lanes and vectors, up to a
  /// small group's worth), then prefetchDeep() (what those vectors point to: the emitters'
  /// particle types, bursts and paths). Each reads only what the one before asked for.
  void prefetchSelf() const;
  /// Part `part` of `parts` of it (every parts-th lane; the vectors with part 0): asked for
  /// at once, a group's ~100 lines hold the L1's miss buffers until they arrive and stall
  /// the core, so the CPU backend asks for the rest between its phases (StepParams::ahead).
  void prefetchData(int part = 0, int parts = 1) const;
  void prefetchDeep() const;
  /// What a step it sits out touches after its first (skippedSteps).
  void prefetchSkip() const { __builtin_prefetch(&skippedSteps); }

  /// The attributes the group must store now. The action list's share is kept for its
  /// actionsVersion by ensureStorage: every step asks, and an idle group's step is little
  /// more than that question.
  AttributeSet wanted() const {
    return required |
           (actionAttributesVersion == actionsVersion ? actionAttributes : actions.attributes());
  }
  AttributeSet actionAttributes;
  std::uint64_t actionAttributesVersion = ~std::uint64_t(0);
  /// Allocates the lanes of wanted() not yet stored (existing particles get defaults) and
  /// frees lanes nobody uses any more.
  void ensureStorage();
  Lanes lanePointers() const { return laneCache; }
  /// Takes laneCache again from `lanes`.
  void cacheLanes();
  /// The step's dead (deadIndex/deadCode of `blocks` blocks of B, their lanes not yet
  /// compacted) as DeathEvents at time t1, in particle order up to deathRoom(); the rest
  /// counted. Out of line in group.cpp for the reason of assignFill.
  void recordDeaths(PassScratch& pass, std::size_t B, std::size_t blocks, double t1,
                    ThreadPool& pool);
  /// Records every death from now on (a death emitter names this group); the room is taken
  /// here, once.
  void feedDeaths();
  /// Writes particle p's stored attributes at index i.
  void write(std::size_t i, const Particle& p) { writeParticle(lanePointers(), i, p); }
  Particle read(std::size_t i) const { return readParticle(lanePointers(), i); }

  /// The fused pass's, for actionsVersion. Last of what a step reads, as its own cold part
  /// (from ActionPlan::coldStart on) then joins the group's.
  ActionPlan plan;

  // From here on what a step does not read (found by tracing the loads of a step of small
  // effect instances), kept apart so that what it does read spans fewer cache lines: a
  // game's thousands of small groups are each out of cache by their next step
  // (bench_runtime's Instances). prefetchSelf() asks for the object up to plan.coldStart.
  std::string name;
  std::vector<EmitterState> primeState;
  std::vector<std::uint32_t> primeLive;  ///< live emitters of each prime emitter
  std::uint32_t nextEmitterId = 0;
  std::shared_ptr<const GroupOrigin> origin;  ///< null unless Effect::build made it
  Strands strands;
  /// The pass's scratch of a large group, or of any while the thread's is in use: see
  /// PassScratchUse.
  std::unique_ptr<PassScratch> ownScratch;
  std::vector<DeathEmitter> deathEmitters;
  /// Each death emitter's source as Context::step last found it: the group, the name it was
  /// found by and the context's groups' version then. Found again when either changed
  /// (DeathEmitter::source is the caller's to edit), not by name every step.
  struct FoundSource {
    Group* group = nullptr;
    std::string name;
    std::uint64_t version = ~std::uint64_t(0);
  };
  std::vector<FoundSource> deathSources;
  /// The context's count of death emitters in all its groups (0: Context::step skips them).
  std::size_t* contextDeathEmitters = nullptr;
  /// The context's schedule version: Group::setUpdateInterval bumps it.
  std::uint64_t* contextSchedule = nullptr;
  /// Each block's collisions as the pass finds them (a block's in its own order), merged in
  /// block order after it: the same on any thread count. They only grow.
  struct KeyedCollision {
    std::uint64_t key;  ///< particle index, sub-step, action: the order they are kept in
    CollisionEvent event;
  };
  std::vector<std::vector<KeyedCollision>> blockCollisions;
  std::uint64_t filledByPass = 0;        ///< holes the act pass ever filled (for the tests)
  std::vector<std::uint32_t> deadFlags;  ///< the unfused baseline's per-particle kill codes
  std::vector<float> snapshot;           ///< positions/velocities at the step's start
  /// NaN while the context's dt is the one the steps ahead were taken with; after a change of
  /// dt, where the group's next step started then (exactly where its last one ended), and
  /// stepsAhead then: its steps go on from there, the context's and the prewarm's alike.
  double aheadFrom = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t aheadStepsThen = 0;
  /// The group's own clock past clockBase (see timeScale).
  double clockUnit = 0.0;
  std::uint64_t clockUnits = 0;
  std::uint32_t updatePhase = 0;  ///< see updateInterval

  /// The lanes, by attribute and component (null where not stored). Last: a step reads
  /// laneCache.
  std::array<std::array<LaneBuffer, 4>, std::size_t(Attribute::Count)> lanes;
};

/// A group's internals, for the library's own code: the public Group does not expose them.
struct GroupAccess {
  static GroupImpl& of(Group& g) { return *g.impl_; }
  static const GroupImpl& of(const Group& g) { return *g.impl_; }
};
inline GroupImpl& implOf(Group& g) {
  return GroupAccess::of(g);
}
inline const GroupImpl& implOf(const Group& g) {
  return GroupAccess::of(g);
}

/// Group::bounds(): the live particles' box, the pass's when it kept one (and the passes
/// keep it from now on).
Bounds liveBox(GroupImpl& g);

}  // namespace flurry::detail
