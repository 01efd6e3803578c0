#include "flurry/context.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include "backend.hpp"
#include "emission_plan.hpp"
#include "flurry/error.hpp"
#include "flurry/version.hpp"
#include "log.hpp"
#include "pass_options.hpp"
#include "tick_clock.hpp"

namespace flurry {

const char* versionString() {
  return "0.1.0";
}

const char* cpuInstructionSet() {
  return detail::fusedPassIsa();
}

struct Context::Impl {
  ContextOptions options;
  detail::PassOptions pass;
  std::vector<std::unique_ptr<Group>> groups;
  // A game creates and destroys thousands of groups (effect instances): finding one by name
  // and the lowest free index must not cost a walk over all of them.
  std::unordered_map<std::string_view, Group*> byName;  // views of the groups' own names
  std::vector<std::uint32_t> freeIndices;               // destroyed groups' indices: a min-heap
  std::uint32_t nextIndex = 0;                          // no group has held this one or above
  std::unique_ptr<detail::ThreadPool> pool;
  // Small groups (effect instances) are stepped many at once, one per thread, each inline.
  detail::ThreadPool inlinePool{1};
  // The groups as Context::step takes them, found again only when a group is created or
  // destroyed (groupsVersion): a large one steps on all threads, the small ones (effect
  // instances) many at once, one per thread, each inline.
  // Each with its update interval and phase, so that a step decides which groups sit it out
  // without reaching into them: a game's ten thousand instances out of sight, stepped once
  // every few frames, cost it no walk over their states.
  struct Scheduled {
    detail::GroupImpl* group;
    std::uint32_t interval, phase;
    bool due(std::uint64_t step) const { return interval <= 1 || (step + phase) % interval == 0; }
    /// It stepped since its last skip (or may have: the list is new): its next skip clears
    /// that step's events and times and starts its clock; the skips after only count.
    bool stepped;
  };
  std::vector<Scheduled> largeGroups, smallGroups;
  std::uint64_t splitVersion = ~std::uint64_t(0);
  // Bumped by Group::setUpdateInterval and by whatever steps groups outside Context::step
  // (prewarm): the lists above are made again.
  std::uint64_t scheduleVersion = 0, splitSchedule = ~std::uint64_t(0);
  void splitGroups();
  // Context::step or prewarm is running: a Callback may not create or destroy groups (the
  // step holds them) nor step again.
  bool stepping = false;
  void checkNotStepping(const char* what) const {
    if (stepping)
      throw Error(std::string("Context::") + what +
                  ": not while the context steps (called from a Callback?)");
  }
  struct Stepping {
    bool& flag;
    explicit Stepping(bool& f) : flag(f) { flag = true; }
    ~Stepping() { flag = false; }
  };
  std::unique_ptr<detail::BackendImpl> backend;
  Backend backendKind = Backend::Cpu;
  std::string backendFallback;  // why Backend::Auto took the CPU
  double time = 0.0;
  std::uint64_t step = 0;
  double timeAtDtChange = 0.0;  // time = timeAtDtChange + stepsSinceDtChange·dt: no drift
  std::uint64_t stepsSinceDtChange = 0;

  detail::StepParams params() const;

  // Death emitters (Group::addDeathEmitter) in all the groups: while there are none a step
  // spends nothing on them.
  double lastStepSeconds = 0.0;     // wall clock of the last step()
  std::uint64_t groupsVersion = 0;  // changes when a group is created or destroyed
  /// Death emitter k's source group, or null (found by name only when something changed).
  Group* sourceOf(detail::GroupImpl& gi, std::size_t k);
  std::size_t deathEmitters = 0;
  bool deathsFed = false;  // some group was told to record its deaths for them
  /// Tells every source group to record its deaths; throws, before anything steps, for a
  /// source no group is named.
  void feedDeathEmitters();
  /// After the step: the death emitters of `only` (all groups when empty) whose source is
  /// in `only` too emit, group by group in creation order.
  void runDeathEmitters(std::span<Group* const> only);
  std::size_t budget = 0;     // Context::setParticleBudget; 0: none
  bool budgetShared = false;  // the groups hold allowances from shareBudget
  std::vector<std::pair<double, std::size_t>> leftovers;  // shareBudget's scratch
  /// Before a step: shares the room under the budget among the groups that emit (see
  /// Context::setParticleBudget), or lifts the allowances when there is no budget.
  void shareBudget();
};

void Context::Impl::shareBudget() {
  if (budget == 0) {
    if (!budgetShared) return;
    for (auto& g : groups) {
      g->impl_->birthAllowance = ~std::uint64_t(0);
      g->impl_->keepAtMost = ~std::size_t(0);
    }
    budgetShared = false;
    return;
  }
  budgetShared = true;
  std::size_t live = 0;
  double asked = 0.0;
  auto emits = [](const detail::GroupImpl& gi) {
    return gi.timeScale != 0.0 &&  // paused: it asks for nothing
           (!gi.emitters.empty() || !gi.primes.empty() || !gi.live.empty() ||
            !gi.deathEmitters.empty());
  };
  for (auto& g : groups) {
    g->impl_->syncCount();  // a device's: its count after the last step
    live += g->impl_->size;
    if (emits(*g->impl_)) asked += double(g->impl_->lastDemand) + 1.0;
  }
  const std::size_t room = budget > live ? budget - live : 0;
  const std::size_t over = live > budget ? live - budget : 0;
  // Each group's exact share, rounded down; what the rounding left is handed out one by one
  // by the largest remainders (then creation order), so that no room is left unused.
  std::size_t given = 0;
  leftovers.clear();
  for (std::size_t k = 0; k < groups.size(); ++k) {
    auto& gi = *groups[k]->impl_;
    double exact = 0.0;
    if (emits(gi)) exact = double(room) * ((double(gi.lastDemand) + 1.0) / asked);
    // Compared as doubles first: a share of all the room may round past it.
    const std::size_t left = room - given;
    gi.birthAllowance = exact >= double(left) ? left : std::uint64_t(exact);
    given += std::size_t(gi.birthAllowance);
    if (emits(gi)) leftovers.emplace_back(exact - double(gi.birthAllowance), k);
  }
  std::stable_sort(leftovers.begin(), leftovers.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t r = 0; r < leftovers.size() && given < room; ++r, ++given)
    ++groups[leftovers[r].second]->impl_->birthAllowance;
  for (auto& g : groups) {
    auto& gi = *g->impl_;
    // Over the budget (it was lowered): a DropOldest group gives up its share of the excess.
    const std::size_t cut =
        over > 0 ? std::size_t(std::ceil(double(over) * double(gi.size) / double(live))) : 0;
    gi.keepAtMost = gi.budgetPolicy == BudgetPolicy::DropOldest
                        ? gi.size - std::min(cut, gi.size) + std::size_t(gi.birthAllowance)
                        : ~std::size_t(0);
  }
}

namespace {
// A group that can hold no more than this many particles steps inline (its act pass is one
// task below cpu fused_pass's 32768 particles): many such are stepped side by side.
constexpr std::size_t kSmallGroupCapacity = 32768;

void checkDt(double dt) {
  if (!std::isfinite(dt) || dt <= 0.0 || dt > 10.0)
    throw InvalidArgument("dt",
                          "must be finite, > 0 and <= 10 seconds (got " + std::to_string(dt) + ")");
}
}  // namespace

Context::Context(ContextOptions options) : impl_(std::make_unique<Impl>()) {
  checkDt(options.dt);
  if (options.scheduler) {
    if (options.threads != 0)
      throw InvalidArgument("threads",
                            "must be 0 with a scheduler (its concurrency() counts them)");
    impl_->pool = std::make_unique<detail::ThreadPool>(options.scheduler);  // threads stays 0
  } else {
    if (options.threads == 0) options.threads = std::max(1u, std::thread::hardware_concurrency());
    if (options.threads > 1024) throw InvalidArgument("threads", "must be <= 1024");
    impl_->pool = std::make_unique<detail::ThreadPool>(options.threads);
  }
  impl_->options = options;
  switch (options.backend) {
    case Backend::Cpu:
      break;
    case Backend::OpenCL:
#ifdef FLURRY_WITH_OPENCL
      impl_->backend = detail::makeOpenCLBackend(options);  // throws, saying why, if none
      impl_->backendKind = Backend::OpenCL;
#else
      throw Error("backend opencl: this build of Flurry has no OpenCL backend (FLURRY_OPENCL=OFF)");
#endif
      break;
    case Backend::Auto:
#ifdef FLURRY_WITH_OPENCL
      try {
        impl_->backend = detail::makeOpenCLBackend(options);
        impl_->backendKind = Backend::OpenCL;
      } catch (const Error& e) {
        impl_->backendFallback = e.what();
        detail::log(LogLevel::Info, "backend auto: running on the CPU, as OpenCL is not usable: " +
                                        impl_->backendFallback);
      }
#endif
      break;
  }
  if (!impl_->backend) {
    impl_->backend = detail::makeCpuBackend();
    impl_->backendKind = Backend::Cpu;
  }
}

Context::~Context() = default;

Group& Context::createGroup(std::string name, std::size_t capacity) {
  impl_->checkNotStepping("createGroup");
  if (capacity == 0) throw InvalidArgument("capacity", "a group needs a capacity > 0");
  if (capacity > std::size_t(0xFFFFFFF0u))
    throw InvalidArgument("capacity", "at most 4294967280 particles per group");
  if (impl_->byName.contains(name))
    throw InvalidArgument("name", "a group named '" + name + "' exists");
  auto gi = std::make_unique<detail::GroupImpl>();
  gi->name = std::move(name);
  gi->capacity = capacity;
  // The lowest index no group holds: a group created where one was destroyed draws that
  // one's random streams, so the same sequence of calls gives the same particles.
  auto& freed = impl_->freeIndices;
  const bool reuse = !freed.empty();
  gi->index = reuse ? freed.front() : impl_->nextIndex;
  gi->updatePhase = gi->index;  // Group::setUpdateInterval's stagger
  gi->onDevice = impl_->backendKind != Backend::Cpu;
  gi->contextDeathEmitters = &impl_->deathEmitters;
  gi->contextSchedule = &impl_->scheduleVersion;
  gi->ensureStorage();
  impl_->groups.reserve(impl_->groups.size() + 1);  // nothing below throws
  impl_->byName.reserve(impl_->byName.size() + 1);
  auto group = std::unique_ptr<Group>(new Group(std::move(gi)));
  Group& g = *group;
  if (reuse) {
    std::pop_heap(freed.begin(), freed.end(), std::greater<>());
    freed.pop_back();
  } else {
    ++impl_->nextIndex;
  }
  impl_->groups.push_back(std::move(group));
  impl_->byName.emplace(g.name(), &g);
  ++impl_->groupsVersion;
  return g;
}

void Context::destroyGroup(Group& group) {
  impl_->checkNotStepping("destroyGroup");
  auto& all = impl_->groups;
  const auto it =
      std::find_if(all.begin(), all.end(), [&](const auto& g) { return g.get() == &group; });
  if (it == all.end())
    throw InvalidArgument("group", "'" + group.name() + "' is not a group of this context");
  impl_->byName.erase(group.name());
  ++impl_->groupsVersion;
  impl_->deathEmitters -= group.impl_->deathEmitters.size();
  impl_->freeIndices.push_back(group.impl_->index);
  std::push_heap(impl_->freeIndices.begin(), impl_->freeIndices.end(), std::greater<>());
  all.erase(it);  // its device buffers go after the work queued on them (the mirror waits)
}

Group& Context::group(std::string_view name) {
  if (const auto it = impl_->byName.find(name); it != impl_->byName.end()) return *it->second;
  throw Error("no group named '" + std::string(name) + "'");
}

std::vector<Group*> Context::groups() {
  std::vector<Group*> r;
  for (auto& g : impl_->groups) r.push_back(g.get());
  return r;
}

namespace {

// Where a group `ahead` steps ahead of the context's clock (Context::prewarm) starts its step:
// from the last change of dt, or from where the group's next step started then.
double aheadTime(const detail::GroupImpl& gi, double timeAtDtChange,
                 std::uint64_t stepsSinceDtChange, std::uint64_t ahead, double dt) {
  if (std::isnan(gi.aheadFrom)) return timeAtDtChange + double(stepsSinceDtChange + ahead) * dt;
  return gi.aheadFrom + double(stepsSinceDtChange + (ahead - gi.aheadStepsThen)) * dt;
}

// The step a group takes now, `extra` steps past its own clock: the context's, or with
// Context::prewarm's steps ahead of it. Kept in the context's form (base + steps·dt) so that
// a prewarmed group reads the very times a group stepped by hand would.
detail::StepParams groupStep(const detail::StepParams& sp, const detail::GroupImpl& gi,
                             double timeAtDtChange, std::uint64_t stepsSinceDtChange,
                             std::uint64_t extra) {
  const std::uint64_t ahead = gi.stepsAhead + extra;
  detail::StepParams r = sp;
  if (gi.ownSeed) r.seed = gi.seed;
  // Each step's end (StepParams::end) is where the next starts, in the same form.
  if (ahead > 0) {
    r.step = sp.step + ahead;
    r.time = aheadTime(gi, timeAtDtChange, stepsSinceDtChange, ahead, sp.dt);
    r.end = aheadTime(gi, timeAtDtChange, stepsSinceDtChange, ahead + 1, sp.dt);
  }
  // Group::setTimeScale, setUpdateInterval: from where its clock stood when it left the
  // context's, over the steps it skipped and this one. A clock not started yet starts at
  // this step's time (beginGroupStep).
  if (gi.ownsClock()) {
    const double unit = sp.dt * gi.timeScale;
    const std::uint64_t units = gi.skippedSteps + 1;
    if (gi.clockStarted()) {
      r.time = gi.clockAt(unit, extra);
      r.end = gi.clockAt(unit, extra + units);
    } else {
      r.end = r.time + double(units) * unit;
    }
    r.dt = unit * double(gi.skippedSteps + 1);
    r.clockUnit = unit;
  }
  // A seeded group's draws are keyed by its own steps: alike whenever it was made.
  if (gi.ownSeed) r.step = gi.ownSteps + extra;
  return r;
}

// A step a group at an update interval sits out (Group::setUpdateInterval): its clock waits
// for the next step it takes, and it leaves no events of its last one.
void skipGroup(detail::GroupImpl& gi, const detail::StepParams& sp) {
  if (!gi.clockStarted()) gi.startClock(sp.time);
  ++gi.skippedSteps;
  gi.lastStepParts = {};
  if (!gi.deathEvents.empty()) gi.deathEvents.clear();  // (each a line not to write)
  if (!gi.collisionEvents.empty()) gi.collisionEvents.clear();
  if (!gi.birthEvents.empty()) gi.birthEvents.clear();
}

// What a group's step does before its backend's part; false when it is paused (nothing
// moves, ages or is born).
bool beginGroupStep(detail::GroupImpl& gi, const detail::StepParams& sp) {
  gi.deathEvents.clear();
  gi.collisionEvents.clear();
  gi.birthEvents.clear();
  if (gi.ownsClock()) {
    if (!gi.clockStarted()) gi.startClock(sp.time);
    gi.advanceClock(sp.clockUnit, gi.skippedSteps + 1);
  }
  gi.skippedSteps = 0;
  ++gi.ownSteps;
  if (sp.dt == 0.0) {  // paused (Group::setTimeScale(0)): nothing moves, ages or is born
    gi.lastStepParts = {};
    return false;
  }
  gi.placeEmitters();
  gi.ensureStorage();
  gi.boundsValid = false;  // the CPU pass takes them again
  if (gi.stats.killedByAction.size() != gi.actions.size())
    gi.stats.killedByAction.assign(gi.actions.size(), 0);
  return true;
}

// What a group's step does after its backend's part.
void endGroupStep(detail::GroupImpl& gi, const detail::StepParams& sp) {
  if (gi.mirror) gi.trimToBudget(sp);  // (the CPU's step trims in its own pass)
}

void stepGroup(detail::BackendImpl& backend, detail::GroupImpl& gi, const detail::StepParams& sp) {
  if (!beginGroupStep(gi, sp)) return;
  backend.step(gi, sp);
  endGroupStep(gi, sp);
}

}  // namespace

void Context::Impl::splitGroups() {
  if (splitVersion == groupsVersion && splitSchedule == scheduleVersion) return;
  // On the CPU a group is independent of every other and its result does not depend on the
  // thread that steps it: a group too small to share out its own pass steps inline on one
  // thread while others step theirs, a large one on all.
  const bool spread = backendKind == Backend::Cpu && pool->size() > 1;
  largeGroups.clear();
  smallGroups.clear();
  for (const auto& g : groups) {
    detail::GroupImpl* gi = g->impl_.get();
    (spread && gi->capacity <= kSmallGroupCapacity ? smallGroups : largeGroups)
        .push_back({gi, gi->updateInterval, gi->updatePhase, true});
  }
  splitVersion = groupsVersion;
  splitSchedule = scheduleVersion;
}

detail::StepParams Context::Impl::params() const {
  detail::StepParams sp;
  sp.time = time;
  sp.dt = options.dt;
  sp.end = timeAtDtChange + double(stepsSinceDtChange + 1) * options.dt;  // (step(): time)
  sp.seed = options.seed;
  sp.step = step;
  sp.blockSize = pass.blockSize;
  sp.fused = pass.fused;
  sp.cull = options.cull;
  sp.pool = pool.get();
  return sp;
}

Group* Context::Impl::sourceOf(detail::GroupImpl& gi, std::size_t k) {
  if (gi.deathSources.size() != gi.deathEmitters.size())
    gi.deathSources.resize(gi.deathEmitters.size());  // a removal shifts them: names tell
  auto& found = gi.deathSources[k];
  const std::string& name = gi.deathEmitters[k].source;
  if (found.version == groupsVersion && found.name == name) return found.group;
  const auto it = byName.find(name);
  found.group = it == byName.end() ? nullptr : it->second;
  found.name = name;
  found.version = groupsVersion;
  return found.group;
}

void Context::Impl::feedDeathEmitters() {
  if (deathEmitters == 0 && !deathsFed) return;
  for (auto& g : groups)
    g->impl_->deathsFeed = g->impl_->collisionsFeed = g->impl_->birthsFeed = false;
  deathsFed = false;
  if (deathEmitters == 0) return;
  for (auto& g : groups) {
    auto& gi = *g->impl_;
    for (std::size_t k = 0; k < gi.deathEmitters.size(); ++k) {
      Group* source = sourceOf(gi, k);
      if (!source)
        throw Error("group '" + gi.name + "': deathEmitters[" + std::to_string(k) +
                    "].source: no group named '" + gi.deathEmitters[k].source + "' in the context");
      if (gi.deathEmitters[k].on == DeathEmitter::Trigger::Collision) {
        source->impl_->collisionsFeed = true;  // records them all for it
      } else if (gi.deathEmitters[k].on == DeathEmitter::Trigger::Birth) {
        source->impl_->birthsFeed = true;
      } else
        source->impl_->feedDeaths();
      deathsFed = true;
    }
  }
}

void Context::Impl::runDeathEmitters(std::span<Group* const> only) {
  if (deathEmitters == 0) return;
  const auto in = [&](const Group* g) {
    return only.empty() || std::find(only.begin(), only.end(), g) != only.end();
  };
  for (auto& g : groups) {
    auto& gi = *g->impl_;
    if (gi.deathEmitters.empty() || !in(g.get())) continue;
    for (std::size_t k = 0; k < gi.deathEmitters.size(); ++k) {
      // feedDeathEmitters found it; a step's Callback may have destroyed it since.
      const Group* source = sourceOf(gi, k);
      if (source && in(source) && gi.timeScale != 0.0)  // a paused group is not fed
        detail::emitFromDeaths(gi, k, *source->impl_, gi.ownSeed ? gi.seed : options.seed);
    }
    // Under a budget, a DropOldest group makes room for these newborns too.
    gi.trimToBudget(params());
  }
}

void Context::setParticleBudget(std::size_t particles) {
  impl_->budget = particles;
}
std::size_t Context::particleBudget() const {
  return impl_->budget;
}

void Context::step() {
  impl_->checkNotStepping("step");
  const Impl::Stepping stepping(impl_->stepping);
  const auto started = std::chrono::steady_clock::now();
  impl_->feedDeathEmitters();
  impl_->shareBudget();
  const detail::StepParams sp = impl_->params();
  impl_->splitGroups();
  // Steps `list[from, to)` in order, asking the memory for a group's state three groups
  // before its step, for what that points to two groups before (half before that step, half
  // during it: StepParams::ahead), and for what those point to one before: a game's
  // thousands of groups are each out of cache by their next step, and would otherwise wait
  // on one miss after another. (A group that sits this step out needs only its count of
  // skipped steps, and after a step of its own a few more lines of its state.)
  //
  // A few groups' first parts (on the CPU their newborns) run before their second parts (act
  // pass and compaction): BackendImpl::stepFirstPart. (Other backends' first part is the
  // whole step.)
  const bool inParts = impl_->backendKind == Backend::Cpu;
  // How many groups ahead a group's state, and then its data, is asked for: further when the
  // act passes wait for a few emissions (10,000 instances on 1 thread: 4 ahead 1.02x faster
  // than 2, alternated with the parts).
  const std::size_t dataAhead = inParts ? 4 : 2, selfAhead = dataAhead + 1;
  auto stepInOrder = [&](std::vector<Impl::Scheduled>& list, std::size_t from, std::size_t to,
                         const detail::StepParams& params) {
    constexpr std::size_t kMany = 16;
    detail::GroupImpl* due[kMany];
    detail::StepParams dueParams[kMany];
    std::size_t dueCount = 0;
    // Every due group's second part, even after one threw (a user's callback): the first
    // exception is thrown again after them, and no group is left between its parts.
    auto flush = [&] {
      std::exception_ptr failed;
      for (std::size_t j = 0; j < dueCount; ++j) {
        try {
          impl_->backend->stepSecondPart(*due[j], dueParams[j]);
          endGroupStep(*due[j], dueParams[j]);
        } catch (...) {
          if (!failed) failed = std::current_exception();
        }
      }
      dueCount = 0;
      if (failed) std::rethrow_exception(failed);
    };
    try {
      for (std::size_t i = from; i < to; ++i) {
        if (i + selfAhead < to) {
          const Impl::Scheduled& next = list[i + selfAhead];
          if (next.due(params.step) || next.stepped)
            next.group->prefetchSelf();
          else
            next.group->prefetchSkip();
        }
        const detail::GroupImpl* ahead = i + dataAhead < to && list[i + dataAhead].due(params.step)
                                             ? list[i + dataAhead].group
                                             : nullptr;
        if (ahead) ahead->prefetchData(0, 2);
        if (i + 1 < to && list[i + 1].due(params.step)) list[i + 1].group->prefetchDeep();
        Impl::Scheduled& at = list[i];
        detail::GroupImpl& gi = *at.group;
        if (!at.due(params.step)) {
          if (at.stepped)
            skipGroup(gi,
                      groupStep(params, gi, impl_->timeAtDtChange, impl_->stepsSinceDtChange, 0));
          else
            ++gi.skippedSteps;  // (its clock started at its first skip; no events are left)
          at.stepped = false;
          continue;
        }
        detail::StepParams own =
            groupStep(params, gi, impl_->timeAtDtChange, impl_->stepsSinceDtChange, 0);
        own.ahead = ahead;
        if (!beginGroupStep(gi, own)) {  // paused
          at.stepped = true;
          continue;
        }
        const bool second = impl_->backend->stepFirstPart(gi, own);
        at.stepped = true;
        if (!second) {
          endGroupStep(gi, own);
          continue;
        }
        due[dueCount] = &gi;
        dueParams[dueCount] = own;
        if (++dueCount == kMany) flush();
      }
    } catch (...) {
      try {
        flush();
      } catch (...) {  // (the first is the one to report)
      }
      throw;
    }
    flush();
  };
  stepInOrder(impl_->largeGroups, 0, impl_->largeGroups.size(), sp);
  auto& small = impl_->smallGroups;
  if (!small.empty()) {
    detail::StepParams alone = sp;
    alone.pool = &impl_->inlinePool;
    // Groups a task takes: fewer hand-outs, and fewer groups at a task's start, which nothing
    // asked the memory for (with 16 a task, 10,000 instances on 2 threads were 1.1x slower).
    constexpr std::size_t kPerTask = 64;
    impl_->pool->parallelFor((small.size() + kPerTask - 1) / kPerTask, [&](std::size_t t) {
      stepInOrder(small, t * kPerTask, std::min(small.size(), (t + 1) * kPerTask), alone);
    });
  }
  impl_->runDeathEmitters({});
  impl_->lastStepSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  detail::recalibrateTicks();  // the groups' phases' clock, against this one
  ++impl_->step;
  ++impl_->stepsSinceDtChange;
  impl_->time = impl_->timeAtDtChange + double(impl_->stepsSinceDtChange) * impl_->options.dt;
}

std::uint64_t Context::prewarm(std::span<Group* const> groups, double seconds) {
  impl_->checkNotStepping("prewarm");
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
    throw InvalidArgument("seconds", "must be finite and >= 0");
  for (Group* g : groups) {
    const auto& all = impl_->groups;
    if (!g || std::none_of(all.begin(), all.end(), [&](const auto& o) { return o.get() == g; }))
      throw InvalidArgument("groups", "not a group of this context");
  }
  const Impl::Stepping stepping(impl_->stepping);
  const double dt = impl_->options.dt;
  // The fewest whole steps that cover `seconds` (a hair's rounding of seconds/dt forgiven).
  const double q = seconds / dt;
  std::uint64_t n = std::uint64_t(std::ceil(q));
  if (n > 0 && double(n - 1) >= q * (1.0 - 1e-9)) --n;
  const detail::StepParams sp = impl_->params();
  if (n > 0) impl_->feedDeathEmitters();
  if (n > 0) ++impl_->scheduleVersion;  // its steps leave events and times to clear
  for (std::uint64_t i = 0; i < n; ++i) {
    impl_->shareBudget();
    for (Group* g : groups) {
      auto& gi = *g->impl_;
      stepGroup(*impl_->backend, gi,
                groupStep(sp, gi, impl_->timeAtDtChange, impl_->stepsSinceDtChange, 0));
      ++gi.stepsAhead;
    }
    // Their death emitters fed by these groups' deaths (one of both sides alone would
    // leave the other side's clock: skipped).
    if (!groups.empty()) impl_->runDeathEmitters(groups);
  }
  return n;
}

double Context::time() const {
  return impl_->time;
}

double Context::time(const Group& group) const {
  // Every group of this context, and only those, points at its death emitter count.
  if (group.impl_->contextDeathEmitters != &impl_->deathEmitters)
    throw InvalidArgument("group", "not a group of this context");
  return groupStep(impl_->params(), *group.impl_, impl_->timeAtDtChange, impl_->stepsSinceDtChange,
                   0)
      .time;
}
std::uint64_t Context::stepIndex() const {
  return impl_->step;
}
double Context::timeStep() const {
  return impl_->options.dt;
}
void Context::setTimeStep(double dt) {
  checkDt(dt);
  // Groups ahead of the clock go on from where their next step starts now: their steps so far
  // were of the old dt.
  for (auto& g : impl_->groups) {
    auto& gi = *g->impl_;
    if (gi.stepsAhead == 0) continue;
    gi.aheadFrom = aheadTime(gi, impl_->timeAtDtChange, impl_->stepsSinceDtChange, gi.stepsAhead,
                             impl_->options.dt);
    gi.aheadStepsThen = gi.stepsAhead;
  }
  impl_->timeAtDtChange = impl_->time;
  impl_->stepsSinceDtChange = 0;
  impl_->options.dt = dt;
}
ContextStats Context::stats() const {
  ContextStats s;
  s.groups = impl_->groups.size();
  s.lastStepSeconds = impl_->lastStepSeconds;
  std::unordered_set<std::string_view> instances;
  for (const auto& g : impl_->groups) {
    const std::string& name = g->name();
    if (const auto at = name.rfind('@'); at != std::string::npos)
      instances.insert(std::string_view(name).substr(at + 1));
    s.particles += g->size();
    s.capacity += g->capacity();
    const GroupStats& gs = g->stats();
    s.emitted += gs.emitted;
    s.droppedAtCapacity += gs.droppedAtCapacity;
    s.droppedAtBudget += gs.droppedAtBudget;
    s.killedByBudget += gs.killedByBudget;
    s.deathEventsDropped += gs.deathEventsDropped;
    s.collisionEventsDropped += gs.collisionEventsDropped;
    s.idleSteps += gs.idleSteps;
    const auto& parts = g->impl_->lastStepParts;
    s.lastStepParts.emit += parts.emit;
    s.lastStepParts.act += parts.act;
    s.lastStepParts.compact += parts.compact;
  }
  s.instances = instances.size();
  return s;
}

unsigned Context::threads() const {
  return impl_->pool->size();
}
std::uint64_t Context::seed() const {
  return impl_->options.seed;
}
Backend Context::backend() const {
  return impl_->backendKind;
}
const std::string& Context::backendFallback() const {
  return impl_->backendFallback;
}
const ContextOptions& Context::options() const {
  return impl_->options;
}

namespace detail {
struct ContextAccess {
  static Context::Impl& of(Context& c) { return *c.impl_; }
  static const Context::Impl& of(const Context& c) { return *c.impl_; }
};

void setPassOptions(Context& context, const PassOptions& options) {
  ContextAccess::of(context).pass = options;
}
PassOptions passOptions(const Context& context) {
  return ContextAccess::of(context).pass;
}
}  // namespace detail

}  // namespace flurry
