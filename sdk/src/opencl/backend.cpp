// The OpenCL backend: each group's particles live on the device between steps, and a step
// is a handful of kernel launches that the host never waits for (PoCL: 5-6 us per launch
// queued back to back, 44-87 us if the host waits every step).
//
//   fl_birth     writes the newborns behind the live particles, where they were born, with
//                the part of the step each still has to live (issue #11)
//   fl_act       the action list as one generated, fused kernel, over the live particles and
//                the newborns (each for its own time); leaves a kill code each
//   fl_count     dead per tile                \  only when the list can kill;
//   fl_scan      prefix over tiles, counts     > one launch (fl_scan_list) for groups of
//   fl_list      hole and tail lists           /  a few tiles
//   fl_deaths    the dead as events (Group::recordDeaths), before fl_tail
//   fl_tail      closes holes from the tail
// A small group's step is one launch: fl_small does all of it in one work-group.
//
// The host does not know the live count while steps are in flight: every kernel reads it
// from the device's state buffer, and the host sizes launches by an upper bound (the last
// count it read back asynchronously plus the births queued since).
#include "backend.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>

#include "codegen.hpp"
#include "emission.hpp"
#include "log.hpp"

namespace flurry::detail::ocl {

static_assert(sizeof(cl::FlDomain) == 72 && alignof(cl::FlDomain) == 4);
static_assert(sizeof(cl::FlFuzzy) == 16);
static_assert(sizeof(cl::FlParticleType) == 4 * 72 + 5 * 16 + 8);
static_assert(sizeof(cl::FlEmitter) == 72 + 16 + 32 + 16 + 32 &&
              offsetof(cl::FlEmitter, start) == 72);
static_assert(sizeof(cl::FlKeyframe) == 24 && offsetof(cl::FlKeyframe, position) == 8);
static_assert(sizeof(cl::FlBirthRun) == 64 && offsetof(cl::FlBirthRun, emitter) == 56);
static_assert(sizeof(cl::FlActionParams) == 72 + 24 * 4 + 6 * 4 &&
              offsetof(cl::FlActionParams, own) == 72 &&
              offsetof(cl::FlActionParams, falloff) == 168 && alignof(cl::FlActionParams) == 8);
static_assert(FL_TILE % 16 == 0);

namespace {

// fl_act's and fl_small's work-group, fixed: PoCL compiles once per (kernel, local size).
constexpr std::size_t kActLocal = FL_ACT_LOCAL;
constexpr std::size_t kSmallLocal = 64;         // count, list and tail
constexpr std::size_t kMaxInFlight = 4;         // steps queued before the host waits for the oldest
constexpr std::size_t kMaxFillItems = 1 << 12;  // PoCL pays ~1 us per work-group, even an idle one
constexpr std::size_t kSmallTiles = 4;          // up to 4096 particles: count-scan-list in one item
// fl_small's one work-group reaches every particle of a group it steps.
static_assert(kActLocal * FL_SMALL_RUN >= kSmallTiles * FL_TILE);
constexpr std::size_t kDeathEventBytes = 8 * 4;  // fl_deaths: position, velocity, id, code

// An event's position and velocity from its first six words (compact.cl fl_event_motion).
void motionFromWords(const std::uint32_t* w, DeathEvent& e) {
  for (int c = 0; c < 3; ++c) {
    e.position[c] = std::bit_cast<float>(w[c]);
    e.velocity[c] = std::bit_cast<float>(w[3 + c]);
  }
}

std::size_t roundUp(std::size_t x, std::size_t m) {
  return (x + m - 1) / m * m;
}

template <class T>
void setArg(cl_kernel k, cl_uint i, const T& v) {
  check(clSetKernelArg(k, i, sizeof(T), &v), "clSetKernelArg");
}

// The values of an action list that a move (Group::setTransform) may change and that the
// program's text depends on (codegen.cpp): the sub-step distance, written as a literal, and
// whether a Gravity's or Damping's falloff radius is finite (a large one scaled up may
// overflow). Everything else the text reads is a kind, which a move keeps. Allocates nothing
// once `out` has grown to the list's length.
void moveKey(const ActionList& list, std::vector<std::uint32_t>& out) {
  out.clear();
  std::uint32_t d;
  std::memcpy(&d, &list.substeps().maxDistance, sizeof d);
  out.push_back(d);
  for (const Action& a : list.actions()) {
    if (const auto* g = std::get_if<Gravity>(&a))
      out.push_back(g->falloff.radius < kInfinity);
    else if (const auto* dm = std::get_if<Damping>(&a))
      out.push_back(dm->falloff.radius < kInfinity);
    else
      out.push_back(2u);
  }
}

std::atomic<SmallLayout> gSmallLayout{SmallLayout::ByDevice};  // setSmallLayout

}  // namespace

void setSmallLayout(SmallLayout layout) {
  gSmallLayout = layout;
}

/// What every group of one Context shares: the device's runtime and a few in-order queues.
/// A group's commands all go to one queue, in order; groups on different queues run side by
/// side (a small group's step is one work-group: on one queue, a game's hundreds of them
/// would run one after another on one compute unit).
struct Shared {
  std::shared_ptr<Runtime> runtime;
  std::vector<Queue> queues;
  std::uint64_t groupsMade = 0;
  /// The queue of the next group made: by a hash of the count, not round robin, so that a
  /// scene whose busy groups come at a regular stride (every other one, every tenth) still
  /// spreads them over the queues.
  cl_command_queue nextQueue() {
    std::uint64_t h = groupsMade++ * 0x9E3779B97F4A7C15ull;  // Fibonacci hashing
    h ^= h >> 29;
    return queues[std::size_t(h % queues.size())].get();
  }
  bool profile = false;  // FLURRY_OPENCL_PROFILE=1: per-kernel device times, logged
  cl_device_id device() const { return runtime->device().id; }
  bool cpu() const { return runtime->device().cpu; }
  bool fp64() const { return runtime->device().info.fp64; }
};

namespace {

// A step queued on the device: its state is read back into `state` when `done` fires.
// Slots are reused (a ring): their vectors keep their capacity, so a steady step allocates
// nothing; a slot's blob and state stay untouched until its step retires, as the queued
// non-blocking transfers read and write them.
struct InFlight {
  Event done;
  std::vector<std::uint32_t> state;
  std::uint64_t births = 0;
  StepTables tables;
  std::vector<std::uint64_t> blob;          // the tables back to back: the step's writes read it
  std::vector<std::uint8_t> params, extra;  // the actions' constants the step wrote, if new
};

// Steps in flight, oldest first, in slots that are reused.
class InFlightRing {
 public:
  explicit InFlightRing(std::size_t slots) : slots_(slots) {}
  bool empty() const { return count_ == 0; }
  std::size_t size() const { return count_; }
  InFlight& front() { return slots_[head_]; }
  InFlight& operator[](std::size_t k) { return slots_[(head_ + k) % slots_.size()]; }
  /// The next free slot; push() makes it the newest step.
  InFlight& next() { return slots_[(head_ + count_) % slots_.size()]; }
  void push() { ++count_; }
  void pop() {
    slots_[head_].done = Event();
    head_ = (head_ + 1) % slots_.size();
    --count_;
  }
  void clear() {
    while (!empty()) pop();
  }

 private:
  std::vector<InFlight> slots_;
  std::size_t head_ = 0, count_ = 0;
};

struct DeviceLane {
  LaneRef ref;
  LaneBuffer host;  // CPU devices: the buffer's memory (aligned, huge pages), used in place
  Mem mem;
};

// A device buffer that only grows.
struct GrowBuffer {
  Mem mem;
  std::size_t bytes = 0;
  bool reserve(cl_context ctx, std::size_t want, cl_mem_flags flags = CL_MEM_READ_WRITE) {
    if (want <= bytes && mem) return false;
    const std::size_t n = std::max<std::size_t>(want, 2 * bytes);
    cl_int err = CL_SUCCESS;
    Mem m(clCreateBuffer(ctx, flags, std::max<std::size_t>(n, 64), nullptr, &err));
    check(err, "clCreateBuffer");
    mem = std::move(m);
    bytes = n;
    return true;
  }
};

class ClGroup final : public DeviceMirror {
 public:
  explicit ClGroup(std::shared_ptr<Shared> shared)
      : shared_(std::move(shared)), queue_(shared_->nextQueue()) {}
  ~ClGroup() override {
    if (!shared_) return;
    clFinish(queue_);  // buffers must outlive queued work
    if (shared_->profile) {
      collectProfile();
      for (const auto& [name, t] : profile_) {
        char line[160];
        std::snprintf(line, sizeof line,
                      "opencl profile: %-14s %8llu launches %10.3f ms total %9.1f us each",
                      name.c_str(), static_cast<unsigned long long>(t.second), t.first * 1e3,
                      t.first * 1e6 / double(std::max<std::uint64_t>(t.second, 1)));
        detail::log(LogLevel::Info, line);
      }
    }
  }

  void collectProfile() {
    for (auto& [name, e] : profiled_) {
      cl_ulong a = 0, b = 0;
      clGetEventProfilingInfo(e.get(), CL_PROFILING_COMMAND_START, sizeof a, &a, nullptr);
      clGetEventProfilingInfo(e.get(), CL_PROFILING_COMMAND_END, sizeof b, &b, nullptr);
      auto& t = profile_[name];
      t.first += double(b - a) * 1e-9;
      ++t.second;
    }
    profiled_.clear();
  }

  void pullToHost(GroupImpl& g, AttributeSet want) override {
    if (!deviceNewer_) return;
    drain(g);
    g.size = size_;
    g.nextId = nextId_;
    bool read = false;
    for (auto& lane : lanes_) {
      if (size_ == 0) break;
      if (!want.has(lane.ref.attribute) || fresh_.has(lane.ref.attribute)) continue;
      void* dst = g.lanes[std::size_t(lane.ref.attribute)][lane.ref.component].data();
      check(clEnqueueReadBuffer(queue(), lane.mem.get(), CL_FALSE, 0, size_ * 4, dst, 0, nullptr,
                                nullptr),
            "clEnqueueReadBuffer (particles)");
      g.stats.bytesReadBack += size_ * 4;
      read = true;
    }
    // The trails come with the positions (Group::trail reads them so).
    if (trailSlots_ > 0 && want.has(Attribute::Position) && !trailFresh_ && size_ > 0) {
      for (std::size_t k = 0; k < 3 * std::size_t(trailSlots_); ++k)
        check(clEnqueueReadBuffer(queue(), trail_.get(), CL_FALSE, k * g.capacity * 4, size_ * 4,
                                  g.trailLanes[k].data(), 0, nullptr, nullptr),
              "clEnqueueReadBuffer (trails)");
      check(clEnqueueReadBuffer(queue(), trailCount_.get(), CL_FALSE, 0, size_ * 4,
                                g.trailCount.data(), 0, nullptr, nullptr),
            "clEnqueueReadBuffer (trails)");
      g.stats.bytesReadBack += (3 * std::size_t(trailSlots_) + 1) * size_ * 4;
      read = true;
    }
    if (read) check(clFinish(queue()), "clFinish");
    for (auto& lane : lanes_)
      if (want.has(lane.ref.attribute)) fresh_.insert(lane.ref.attribute);
    if (want.has(Attribute::Position)) trailFresh_ = true;
    // Every stored lane is the device's now (an empty group: nothing to read).
    if (size_ == 0 || (fresh_.contains(laneSet_) && (trailSlots_ == 0 || trailFresh_)))
      deviceNewer_ = false;
  }

  void hostChanged(GroupImpl&) override { hostDirty_ = true; }

  // A death emitter's newborns: the device's count and next id, and then only the newborns
  // go up (the particles before them stay where they are, on the device).
  void beginAppend(GroupImpl& g) override {
    if (hostDirty_ || !allocated_) return;  // the host's copy is the group's: it goes up whole
    drain(g);
    g.size = size_;
    g.nextId = nextId_;
  }
  void endAppend(GroupImpl& g, std::size_t from) override {
    if (hostDirty_ || !allocated_) {
      hostDirty_ = true;
      return;
    }
    const std::size_t n = g.size - from;
    for (auto& lane : lanes_) {
      if (n == 0) break;
      const auto* src = static_cast<const char*>(
          g.lanes[std::size_t(lane.ref.attribute)][lane.ref.component].data());
      check(clEnqueueWriteBuffer(queue(), lane.mem.get(), CL_FALSE, from * 4, n * 4, src + from * 4,
                                 0, nullptr, nullptr),
            "clEnqueueWriteBuffer (newborns)");
    }
    if (trailSlots_ > 0) queueTrails(g, from, g.size);  // where the host started them
    // Blocking, after the lanes in the same in-order queue: the host's lanes are free again.
    const std::uint32_t head[2] = {std::uint32_t(g.size), g.nextId};
    static_assert(FL_STATE_SIZE == 0 && FL_STATE_NEXT_ID == 1);
    check(clEnqueueWriteBuffer(queue(), state_.mem.get(), CL_TRUE, 0, sizeof head, head, 0, nullptr,
                               nullptr),
          "clEnqueueWriteBuffer (state)");
    size_ = g.size;
    nextId_ = g.nextId;
  }
  // Steps in flight report their counts when they finish: wait for them, read no particles.
  void syncStats(GroupImpl& g) override { finish(g); }

  void finish(GroupImpl& g) {
    // Nothing of this group's in flight (an idle group): no wait for the others' work.
    if (inFlight_.empty() && !shared_->profile) return;
    check(clFinish(queue()), "clFinish");
    drain(g);
    if (shared_->profile) collectProfile();
  }

  void step(GroupImpl& g, const StepParams& sp);

 private:
  cl_command_queue queue() const { return queue_; }
  cl_context context() const { return shared_->runtime->context(); }

  void allocate(GroupImpl& g);
  void buildProgram(GroupImpl& g, bool cull, bool hits);
  void upload(GroupImpl& g);
  void retire(GroupImpl& g, bool wait);
  void drain(GroupImpl& g) {
    while (!inFlight_.empty()) retire(g, true);
  }
  void apply(GroupImpl& g, const std::vector<std::uint32_t>& state);
  void queueHair(GroupImpl& g, const StepParams& sp, std::size_t births);
  void readStrands(GroupImpl& g, std::size_t births);
  void readDeaths(GroupImpl& g, std::size_t room, double t1);
  void readCollisions(GroupImpl& g);
  // The most collision events one buffer holds on this device.
  std::size_t mostHits() const { return shared_->runtime->device().info.maxAllocation / 64 - 1; }
  void readBirths(GroupImpl& g, double t1);

  std::shared_ptr<Shared> shared_;
  cl_command_queue queue_;  ///< one of shared_'s, for all of this group's commands
  std::vector<DeviceLane> lanes_;
  AttributeSet laneSet_;
  bool allocated_ = false;
  Mem codes_, tileDead_, tileOff_, holes_, tailList_;
  Mem tau_;  // per newborn of the step, by slot: the part of the step it still has to live
  GrowBuffer state_, params_, extra_, snap_, tables_;
  std::size_t tiles_ = 0;

  Program program_;
  ActionList programActions_;
  bool programValid_ = false;
  // The program's source and options, and the action list structure it was last checked for
  // (GroupImpl::actionsStructure): a new list may need another program (other kinds of
  // actions or domains), or only new constants (a parameter), which go up without a
  // rebuild. A move keeps the structure: only its moveKey is compared (no text generated).
  std::string programSource_, programOptions_;
  std::uint64_t programCheckedStructure_ = ~std::uint64_t(0);
  std::uint64_t programCheckedVersion_ = ~std::uint64_t(0);  // actionsVersion, likewise
  std::vector<std::uint32_t> programMoveKey_, moveKeyScratch_;
  std::string emitterSignature_;
  EmitterCodes emitterCodes_;  // the program's emitter codes, and the planning's scratch
  // The action constants as last packed: for actionsVersion and the step's dt (its bits).
  std::uint64_t packedVersion_ = ~std::uint64_t(0);
  std::uint32_t packedDt_ = 0;
  // The emission tables' blob: runs first, in room for runsRoom_ runs, then the emitters'
  // part, which is written only when it differs from what the device holds (staticUploaded_).
  std::size_t runsRoom_ = 0;
  std::vector<std::uint64_t> staticUploaded_;
  bool hairProgram_ = false;  // the program has fl_hair
  bool cullProgram_ = false;  // the program was generated for ContextOptions::cull
  bool hitsProgram_ = false;  // ... to log collisions (Group::recordCollisions)
  GrowBuffer hits_;           // fl_log_collision's count and events
  std::size_t hitRoom_ = 0;   // the events hits_ holds; grows to the most a step had
  std::vector<std::uint32_t> hitWords_;
  std::vector<std::pair<std::uint64_t, CollisionEvent>> hitsSorted_;
  Kernel hair_, small_;
  GrowBuffer strandP_, strandC_, strandR_, strandCount_;
  std::uint32_t lastHairAlive_ = 0;
  std::uint32_t lastCulled_ = 0;
  std::uint32_t reachOff_ = 0;  // where the actions' reach boxes start in extra_host_
  std::vector<LaneRef> actLanes_;
  bool neighbours_ = false, substepsByDistance_ = false;
  Kernel act_, count_, scan_, list_, scanList_, tailKernel_, maxSpeed_, birth_, deaths_,
      birthEvents_;
  std::vector<cl::FlActionParams> params_host_, params_uploaded_;
  std::vector<float> extra_host_, extra_uploaded_;
  bool paramsStale_ = false, extraStale_ = false;  // the device's differ from the host's
  bool unpushedWrite_ = false;  // a write reads the next slot's copies, not yet a step's

  std::vector<std::pair<std::string, Event>> profiled_;
  std::map<std::string, std::pair<double, std::uint64_t>> profile_;
  InFlightRing inFlight_{kMaxInFlight + 1};
  std::size_t size_ = 0;  // the device's live count at the last completed step
  std::uint32_t nextId_ = 0;
  std::uint32_t lastDropped_ = 0;
  std::uint32_t lastDead_ = 0;  // the last retired step's dead
  GrowBuffer events_;           // fl_deaths' events, kDeathEventBytes each
  GrowBuffer births_;           // fl_births' count and events
  std::vector<std::uint32_t> deathWords_;
  std::vector<std::uint32_t> lastKills_;
  // Group::setTrail: the ring on the device (trail.cl), trailSlots_ positions a particle, and
  // whether the host's copy of it is the device's (as fresh_ for the lanes).
  Program trailProgram_;
  Kernel trailStart_, trailTail_, trailRecord_;
  Mem trail_, trailCount_;
  std::uint32_t trailSlots_ = 0;
  bool trailFresh_ = false;
  void allocateTrails(GroupImpl& g);
  void queueTrails(GroupImpl& g, std::size_t from, std::size_t to);  // host -> device
  cl_mem positionLane(int c) const {
    for (const auto& l : lanes_)
      if (l.ref.attribute == Attribute::Position && l.ref.component == c) return l.mem.get();
    return nullptr;
  }
  bool hostDirty_ = true;
  bool deviceNewer_ = false;
  // While deviceNewer_: the attributes whose host lanes already hold the device's particles.
  AttributeSet fresh_;
};

void ClGroup::allocate(GroupImpl& g) {
  const auto& dev = shared_->runtime->device();
  // As long as the act kernels' launches (whole work-groups): their work-items past the live
  // particles load and store their slots too (codegen.cpp).
  const std::size_t laneBytes = roundUp(g.capacity, kActLocal) * 4;
  if (laneBytes > dev.info.maxAllocation)
    throw OpenCLError(CL_INVALID_BUFFER_SIZE,
                      "OpenCL: group '" + g.name + "' of capacity " + std::to_string(g.capacity) +
                          " needs " + std::to_string(laneBytes) + " bytes per attribute lane; " +
                          dev.info.name + " allows " + std::to_string(dev.info.maxAllocation) +
                          " bytes per buffer (use a smaller capacity or the CPU backend)");
  // Build the new set aside, so a failure (out of device memory) leaves the group as it was.
  std::vector<DeviceLane> lanes;
  cl_int err = CL_SUCCESS;
  for (const LaneRef& ref : lanesOf(g.stored)) {
    DeviceLane l{ref, LaneBuffer(), Mem()};
    if (shared_->cpu()) {
      // PoCL on the CPU: buffers over memory we allocate (aligned, huge pages) run ~30 %
      // faster than ALLOC_HOST_PTR ones (PERF-NOTES); the device uses it in place.
      l.host = LaneBuffer(laneBytes / 4);
      l.mem = Mem(clCreateBuffer(context(), CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, laneBytes,
                                 l.host.data(), &err));
    } else {
      l.mem = Mem(clCreateBuffer(context(), CL_MEM_READ_WRITE, laneBytes, nullptr, &err));
    }
    check(err, "clCreateBuffer (particles)");
    lanes.push_back(std::move(l));
  }
  if (!allocated_) {
    tiles_ = roundUp((g.capacity + FL_TILE - 1) / FL_TILE, kSmallLocal);
    auto make = [&](std::size_t bytes) {
      Mem m(clCreateBuffer(context(), CL_MEM_READ_WRITE, bytes, nullptr, &err));
      check(err, "clCreateBuffer (scratch)");
      return m;
    };
    codes_ = make(std::max(roundUp(g.capacity, FL_TILE), roundUp(g.capacity, kActLocal)));
    tileDead_ = make(tiles_ * 4);
    tileOff_ = make(tiles_ * 4);
    holes_ = make(g.capacity * 4);
    tailList_ = make(g.capacity * 4);
    // By slot, and as long as the act kernels' launches: a CPU driver's vector of work-items
    // reads it whole (masked), past the live ones too. Written once whole, so that no such
    // read meets a page not yet there (a masked-off lane on one costs an assist per vector).
    const std::size_t tauBytes = roundUp(g.capacity, kActLocal) * 4;
    tau_ = make(tauBytes);
    const float zero = 0.0f;
    check(clEnqueueFillBuffer(queue(), tau_.get(), &zero, 4, 0, tauBytes, 0, nullptr, nullptr),
          "clEnqueueFillBuffer (scratch)");
  }
  lanes_ = std::move(lanes);
  laneSet_ = g.stored;
  allocated_ = true;
  programValid_ = false;
}

void ClGroup::allocateTrails(GroupImpl& g) {
  const std::size_t rows = 3 * std::size_t(g.trail.length);
  if (rows == 0) {
    trail_ = Mem();
    trailCount_ = Mem();
    trailSlots_ = 0;
    return;
  }
  const auto& dev = shared_->runtime->device();
  const std::size_t floats = rows * g.capacity;
  if (floats * 4 > dev.info.maxAllocation || floats > std::size_t(0xFFFFFFFFu))
    throw OpenCLError(CL_INVALID_BUFFER_SIZE,
                      "OpenCL: group '" + g.name + "': a trail of " +
                          std::to_string(g.trail.length) + " positions for a capacity of " +
                          std::to_string(g.capacity) + " needs " + std::to_string(floats * 4) +
                          " bytes in one buffer; " + dev.info.name + " allows " +
                          std::to_string(dev.info.maxAllocation) +
                          " (a shorter trail, a smaller capacity or the CPU backend)");
  cl_int err = CL_SUCCESS;
  Mem trail(clCreateBuffer(context(), CL_MEM_READ_WRITE, floats * 4, nullptr, &err));
  check(err, "clCreateBuffer (trails)");
  Mem count(clCreateBuffer(context(), CL_MEM_READ_WRITE, g.capacity * 4, nullptr, &err));
  check(err, "clCreateBuffer (trails)");
  if (!trailProgram_) {
    Program p(shared_->runtime->program(trailProgramSource(shared_->fp64()), kProgramOptions));
    auto kernel = [&](const char* name) {
      Kernel k(clCreateKernel(p.get(), name, &err));
      check(err, "clCreateKernel");
      return k;
    };
    trailStart_ = kernel("fl_trail_start");
    trailTail_ = kernel("fl_trail_tail");
    trailRecord_ = kernel("fl_trail_record");
    trailProgram_ = std::move(p);
  }
  // Zeroed, as on the CPU: no slot ever holds what the device's memory had.
  const cl_uint zero = 0;
  check(clEnqueueFillBuffer(queue(), trail.get(), &zero, 4, 0, floats * 4, 0, nullptr, nullptr),
        "clEnqueueFillBuffer (trails)");
  check(clEnqueueFillBuffer(queue(), count.get(), &zero, 4, 0, g.capacity * 4, 0, nullptr, nullptr),
        "clEnqueueFillBuffer (trails)");
  trail_ = std::move(trail);
  trailCount_ = std::move(count);
  trailSlots_ = g.trail.length;
  trailFresh_ = false;
}

void ClGroup::queueTrails(GroupImpl& g, std::size_t from, std::size_t to) {
  if (to <= from) return;
  const std::size_t n = to - from;
  for (std::size_t k = 0; k < 3 * std::size_t(trailSlots_); ++k)
    check(clEnqueueWriteBuffer(queue(), trail_.get(), CL_FALSE, (k * g.capacity + from) * 4, n * 4,
                               g.trailLanes[k].f() + from, 0, nullptr, nullptr),
          "clEnqueueWriteBuffer (trails)");
  check(clEnqueueWriteBuffer(queue(), trailCount_.get(), CL_FALSE, from * 4, n * 4,
                             g.trailCount.u() + from, 0, nullptr, nullptr),
        "clEnqueueWriteBuffer (trails)");
}

void ClGroup::buildProgram(GroupImpl& g, bool cull, bool hits) {
  // The emitter codes this step refreshed: the program and the planning agree on them.
  const GeneratedProgram gen =
      generateProgram(g.actions, g.stored, shared_->fp64(), emissionSource(emitterCodes_.variants),
                      g.hair.enabled, cull, hits);
  emitterSignature_ = emitterSignature(emitterCodes_.variants);
  const SmallLayout layout = gSmallLayout;
  const bool runs = layout == SmallLayout::Runs ||
                    (layout == SmallLayout::ByDevice && shared_->runtime->device().cpu);
  const std::string options = gen.options + (runs ? " -DFL_SMALL_RUNS" : "");
  Program p(shared_->runtime->program(gen.source, options));
  cl_int err = CL_SUCCESS;
  auto kernel = [&](const char* name) {
    Kernel k(clCreateKernel(p.get(), name, &err));
    check(err, "clCreateKernel");
    return k;
  };
  Kernel act = kernel("fl_act"), count = kernel("fl_count"), scan = kernel("fl_scan"),
         list = kernel("fl_list"), scanList = kernel("fl_scan_list"), tail = kernel("fl_tail"),
         maxSpeed = kernel("fl_max_speed"), birth = kernel("fl_birth"),
         deaths = kernel("fl_deaths"), birthEvents = kernel("fl_births");
  Kernel hair = g.hair.enabled ? kernel("fl_hair") : Kernel();
  Kernel small = gen.small ? kernel("fl_small") : Kernel();
  program_ = std::move(p);
  act_ = std::move(act);
  count_ = std::move(count);
  scan_ = std::move(scan);
  list_ = std::move(list);
  scanList_ = std::move(scanList);
  tailKernel_ = std::move(tail);
  maxSpeed_ = std::move(maxSpeed);
  birth_ = std::move(birth);
  deaths_ = std::move(deaths);
  birthEvents_ = std::move(birthEvents);
  hair_ = std::move(hair);
  small_ = std::move(small);
  hairProgram_ = g.hair.enabled;
  cullProgram_ = cull;
  hitsProgram_ = hits;
  actLanes_ = gen.actLanes;
  neighbours_ = gen.neighbours;
  substepsByDistance_ = gen.substepsByDistance;
  programActions_ = g.actions;
  programSource_ = gen.source;
  programOptions_ = options;
  programCheckedStructure_ = g.actionsStructure;
  programCheckedVersion_ = g.actionsVersion;
  moveKey(g.actions, programMoveKey_);
  programValid_ = true;

  // The buffer arguments; scalars are set per step.
  auto laneMem = [&](const LaneRef& r) {
    for (auto& l : lanes_)
      if (l.ref.attribute == r.attribute && l.ref.component == r.component) return l.mem.get();
    return cl_mem(nullptr);
  };
  cl_uint i = 0;
  for (const auto& r : actLanes_) setArg(act_.get(), i++, laneMem(r));
  setArg(act_.get(), i++, codes_.get());
  i = 0;
  for (const auto& l : lanes_) setArg(tailKernel_.get(), i++, l.mem.get());
  setArg(tailKernel_.get(), i++, holes_.get());
  setArg(tailKernel_.get(), i++, tailList_.get());
  i = 0;
  for (const auto& l : lanes_) setArg(birth_.get(), i++, l.mem.get());
  setArg(birth_.get(), i++, tau_.get());
  setArg(count_.get(), 0, codes_.get());
  setArg(count_.get(), 1, tileDead_.get());
  setArg(scan_.get(), 0, codes_.get());
  setArg(scan_.get(), 1, tileDead_.get());
  setArg(scan_.get(), 2, tileOff_.get());
  setArg(list_.get(), 0, codes_.get());
  setArg(list_.get(), 1, tileOff_.get());
  setArg(list_.get(), 2, tileDead_.get());
  setArg(list_.get(), 3, holes_.get());
  setArg(list_.get(), 4, tailList_.get());
  setArg(scanList_.get(), 0, codes_.get());
  setArg(scanList_.get(), 1, tileDead_.get());
  setArg(scanList_.get(), 2, tileOff_.get());
  setArg(scanList_.get(), 3, holes_.get());
  setArg(scanList_.get(), 4, tailList_.get());
  if (substepsByDistance_) {
    for (int c = 0; c < 3; ++c)
      setArg(maxSpeed_.get(), cl_uint(c), laneMem({Attribute::Velocity, c, ""}));
  }
  // fl_deaths: its lanes (velocity aliases the position where not stored; the id is stored
  // by every group that records deaths, Group::recordDeaths requires it).
  setArg(deaths_.get(), 0, codes_.get());
  setArg(deaths_.get(), 1, tileOff_.get());
  const bool velocity = g.stored.has(Attribute::Velocity);
  for (int c = 0; c < 3; ++c) {
    setArg(deaths_.get(), cl_uint(3 + c), laneMem({Attribute::Position, c, ""}));
    setArg(deaths_.get(), cl_uint(6 + c),
           laneMem({velocity ? Attribute::Velocity : Attribute::Position, c, ""}));
  }
  setArg(deaths_.get(), 9, cl_uint(velocity));
  const cl_mem id = laneMem({Attribute::Id, 0, ""});
  setArg(deaths_.get(), 10, id ? id : laneMem({Attribute::Position, 0, ""}));
  // fl_births: the same lanes, and the newborns' time left.
  for (int c = 0; c < 3; ++c) {
    setArg(birthEvents_.get(), cl_uint(3 + c), laneMem({Attribute::Position, c, ""}));
    setArg(birthEvents_.get(), cl_uint(6 + c),
           laneMem({velocity ? Attribute::Velocity : Attribute::Position, c, ""}));
  }
  setArg(birthEvents_.get(), 9, cl_uint(velocity));
  setArg(birthEvents_.get(), 10, id ? id : laneMem({Attribute::Position, 0, ""}));
  setArg(birthEvents_.get(), 11, tau_.get());
  params_uploaded_.clear();
  extra_uploaded_.clear();
  packedVersion_ = ~std::uint64_t(0);
}

void ClGroup::upload(GroupImpl& g) {
  drain(g);
  const std::size_t nActions = std::max<std::size_t>(g.actions.size(), 1);
  if (state_.reserve(context(), (FL_STATE_HEADER + FL_KILL_CODES) * 4)) programValid_ = false;
  for (auto& lane : lanes_) {
    if (g.size == 0) break;
    const void* src = g.lanes[std::size_t(lane.ref.attribute)][lane.ref.component].data();
    check(clEnqueueWriteBuffer(queue(), lane.mem.get(), CL_FALSE, 0, g.size * 4, src, 0, nullptr,
                               nullptr),
          "clEnqueueWriteBuffer (particles)");
  }
  if (trailSlots_ > 0) queueTrails(g, 0, g.size);
  std::vector<std::uint32_t> state(FL_STATE_HEADER + FL_KILL_CODES, 0u);
  state[FL_STATE_SIZE] = std::uint32_t(g.size);
  state[FL_STATE_NEXT_ID] = g.nextId;
  check(clEnqueueWriteBuffer(queue(), state_.mem.get(), CL_TRUE, 0, state.size() * 4, state.data(),
                             0, nullptr, nullptr),
        "clEnqueueWriteBuffer (state)");
  check(clFinish(queue()), "clFinish");
  size_ = g.size;
  nextId_ = g.nextId;
  lastDropped_ = 0;
  lastHairAlive_ = 0;
  lastCulled_ = 0;
  lastKills_.assign(FL_KILL_CODES, 0u);
  (void)nActions;
  hostDirty_ = false;
  deviceNewer_ = false;
}

void ClGroup::apply(GroupImpl& g, const std::vector<std::uint32_t>& s) {
  size_ = s[FL_STATE_SIZE];
  nextId_ = s[FL_STATE_NEXT_ID];
  lastDead_ = s[FL_STATE_DEAD];
  // The device's counters are 32-bit and wrap; the host sums their deltas in 64 bits.
  g.stats.droppedAtCapacity += std::uint32_t(s[FL_STATE_DROPPED] - lastDropped_);
  lastDropped_ = s[FL_STATE_DROPPED];
  g.stats.killedByAge += std::uint32_t(s[FL_STATE_HAIR_ALIVE] - lastHairAlive_);
  lastHairAlive_ = s[FL_STATE_HAIR_ALIVE];
  g.stats.blockActionsCulled += std::uint32_t(s[FL_STATE_CULLED] - lastCulled_);
  lastCulled_ = s[FL_STATE_CULLED];
  const auto& acts = programActions_.actions();
  {
    const std::size_t k = FL_NON_FINITE_CODE - 1;
    const std::uint32_t now = s[FL_STATE_KILLS + k];
    g.stats.killedNonFinite += std::uint32_t(now - lastKills_[k]);
    lastKills_[k] = now;
  }
  for (std::size_t k = 0; k < acts.size() && k + 1 < FL_NON_FINITE_CODE; ++k) {
    const std::uint32_t now = s[FL_STATE_KILLS + k];
    const std::uint32_t d = now - lastKills_[k];
    lastKills_[k] = now;
    if (d == 0) continue;
    if (k < g.stats.killedByAction.size()) g.stats.killedByAction[k] += d;
    if (std::holds_alternative<KillOld>(acts[k]))
      g.stats.killedByAge += d;
    else
      g.stats.absorbed += d;
  }
}

void ClGroup::retire(GroupImpl& g, bool wait) {
  if (inFlight_.empty()) return;
  InFlight& f = inFlight_.front();
  cl_int status = CL_COMPLETE;
  if (wait) {
    const cl_event e = f.done.get();
    const cl_int err = clWaitForEvents(1, &e);
    if (err != CL_SUCCESS && err != CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
      check(err, "clWaitForEvents");
  }
  check(clGetEventInfo(f.done.get(), CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status,
                       nullptr),
        "clGetEventInfo");
  if (status < 0) {
    inFlight_.clear();
    hostDirty_ = true;  // the device's copy is lost; the group keeps its last host copy
    deviceNewer_ = false;
    check(status, "a queued step");
  }
  if (status != CL_COMPLETE) return;
  apply(g, f.state);
  inFlight_.pop();
}

void ClGroup::queueHair(GroupImpl& g, const StepParams& sp, std::size_t births) {
  const std::size_t vertices = births * g.hair.maxVertices;
  strandP_.reserve(context(), vertices * 3 * 4);
  strandC_.reserve(context(), vertices * 4 * 4);
  strandR_.reserve(context(), vertices * 4);
  strandCount_.reserve(context(), births * 4);
  // Newborns that died in their birth step make no strand: their counts stay zero.
  const cl_uint zero = 0;
  check(clEnqueueFillBuffer(queue(), strandCount_.mem.get(), &zero, 4, 0, births * 4, 0, nullptr,
                            nullptr),
        "clEnqueueFillBuffer (strands)");
  cl_kernel k = hair_.get();
  cl_uint i = 0;
  for (const auto& l : lanes_) setArg(k, i++, l.mem.get());
  setArg(k, i++, params_.mem.get());
  setArg(k, i++, state_.mem.get());
  setArg(k, i++, extra_.mem.get());
  setArg(k, i++, extra_.mem.get());  // no snapshot: hair refuses neighbour actions
  setArg(k, i++, cl_ulong(doubleBits(sp.dt)));
  setArg(k, i++, cl_ulong(doubleBits(sp.end)));  // hair.cpp: hs.time
  setArg(k, i++, cl_uint(sp.seed));
  setArg(k, i++, cl_uint(sp.seed >> 32));
  setArg(k, i++, cl_uint(sp.step));
  setArg(k, i++, cl_uint(g.streamKey() << 16));
  setArg(k, i++, cl_uint(stepSubsteps(g.actions, sp.dt)));
  setArg(k, i++, cl_uint(0));
  setArg(k, i++, cl_uint(g.hair.every));
  setArg(k, i++, cl_uint(g.hair.maxVertices));
  setArg(k, i++, strandP_.mem.get());
  setArg(k, i++, strandC_.mem.get());
  setArg(k, i++, strandR_.mem.get());
  setArg(k, i++, strandCount_.mem.get());
  const std::size_t global = roundUp(births, kSmallLocal), local = kSmallLocal;
  check(clEnqueueNDRangeKernel(queue(), k, 1, nullptr, &global, &local, 0, nullptr, nullptr),
        "fl_hair");
}

void ClGroup::readStrands(GroupImpl& g, std::size_t births) {
  // Newborns beyond capacity were dropped: the device wrote strands for those born.
  const std::size_t born = std::min(births, g.capacity);
  const std::size_t maxV = g.hair.maxVertices;
  std::vector<std::uint32_t> count(born);
  std::vector<float> P(born * maxV * 3), C(born * maxV * 4), R(born * maxV);
  cl_command_queue q = queue();
  check(clEnqueueReadBuffer(q, strandCount_.mem.get(), CL_FALSE, 0, born * 4, count.data(), 0,
                            nullptr, nullptr),
        "clEnqueueReadBuffer (strands)");
  check(clEnqueueReadBuffer(q, strandP_.mem.get(), CL_FALSE, 0, P.size() * 4, P.data(), 0, nullptr,
                            nullptr),
        "clEnqueueReadBuffer (strands)");
  check(clEnqueueReadBuffer(q, strandC_.mem.get(), CL_FALSE, 0, C.size() * 4, C.data(), 0, nullptr,
                            nullptr),
        "clEnqueueReadBuffer (strands)");
  check(clEnqueueReadBuffer(q, strandR_.mem.get(), CL_FALSE, 0, R.size() * 4, R.data(), 0, nullptr,
                            nullptr),
        "clEnqueueReadBuffer (strands)");
  check(clFinish(q), "clFinish");
  std::vector<Vec3> p;
  std::vector<Vec4> c;
  std::vector<float> r;
  for (std::size_t s = 0; s < born; ++s) {
    const std::size_t m = std::min<std::size_t>(count[s], maxV);
    if (m < 2) continue;  // hair.cpp: a strand needs two vertices
    p.resize(m);
    c.resize(m);
    r.resize(m);
    for (std::size_t v = 0; v < m; ++v) {
      const std::size_t o = s * maxV + v;
      p[v] = Vec3(P[3 * o], P[3 * o + 1], P[3 * o + 2]);
      c[v] = Vec4(C[4 * o], C[4 * o + 1], C[4 * o + 2], C[4 * o + 3]);
      r[v] = R[o];
    }
    g.strands.add(p, c, r);
  }
  size_ = 0;
  g.size = 0;
  deviceNewer_ = false;
}

void ClGroup::step(GroupImpl& g, const StepParams& sp) {
  if (unpushedWrite_) {
    // The last step threw after writing from its slot's copy and before taking the slot:
    // that write must end before the slot is written again.
    clFinish(queue());
    unpushedWrite_ = false;
  }
  checkEmissionSupported(g);
  // Idle, as on the CPU: nothing alive (at most: the last count read plus the births queued
  // since; the host's own count if it changed the particles) and no emitter that will fire.
  // Such a step changes nothing: no planning, no upload, no launch.
  {
    std::size_t live = size_;
    for (std::size_t k = 0; k < inFlight_.size(); ++k) live += inFlight_[k].births;
    if (hostDirty_) live = g.size;
    if (live == 0 && !g.hair.enabled && !mayEmit(g, sp)) {
      if (!g.emitters.empty() && g.stats.emittedByGeneration.empty())
        g.stats.emittedByGeneration.assign(1, 0);
      ++g.stats.idleSteps;
      return;
    }
  }
  if (!allocated_ || laneSet_ != g.stored) {
    drain(g);
    allocate(g);
    hostDirty_ = true;
  }
  if (g.trail.length != trailSlots_) {
    if (g.trail.length > 0 && g.hair.enabled)
      throw Error("group '" + g.name + "': a trail in hair mode does not run on the device");
    drain(g);
    allocateTrails(g);
    hostDirty_ = true;  // Group::setTrail started the trails on the host
  }
  // The host's particles go up; the program's buffers stay the same (no rebuild).
  if (hostDirty_) upload(g);
  // Emitters may be edited at any time (Group::emitters()); the program follows their kinds.
  // Their codes are rebuilt only when the group says its emitters may have changed.
  if (emitterCodes_.refresh(g) && programValid_ &&
      emitterSignature(emitterCodes_.variants) != emitterSignature_)
    programValid_ = false;
  // A group that records collisions runs a program that logs them (and only then).
  const bool hits = g.collisionRoom() > 0;
  if (g.hair.enabled != hairProgram_ || sp.cull != cullProgram_ || hits != hitsProgram_)
    programValid_ = false;
  if (programValid_ && programCheckedVersion_ != g.actionsVersion) {
    if (programCheckedStructure_ == g.actionsStructure) {
      moveKey(g.actions, moveKeyScratch_);
      if (moveKeyScratch_ != programMoveKey_) programCheckedStructure_ = ~std::uint64_t(0);
    }
    if (programCheckedStructure_ != g.actionsStructure) {
      const GeneratedProgram gen =
          generateProgram(g.actions, g.stored, shared_->fp64(),
                          emissionSource(emitterCodes_.variants), g.hair.enabled, sp.cull, hits);
      if (gen.source != programSource_ || gen.options != programOptions_) programValid_ = false;
      programActions_ = g.actions;
      programCheckedStructure_ = g.actionsStructure;
      moveKey(g.actions, programMoveKey_);
    }
    programCheckedVersion_ = g.actionsVersion;
  }
  if (!programValid_) buildProgram(g, sp.cull, hits);

  // The actions' constants: packed again only for a new list or a new dt (they hold
  // products with dt), and uploaded only when their bytes changed.
  const float dtf = float(sp.dt);
  std::uint32_t dtBitsF;
  std::memcpy(&dtBitsF, &dtf, sizeof dtBitsF);
  if (packedVersion_ != g.actionsVersion || packedDt_ != dtBitsF) {
    packActions(g.actions, dtf, params_host_, extra_host_);
    // The actions' reach boxes (the CPU's, cpu_backend.cpp actionReach: both backends cull
    // alike) after the actions' own data, with what lets the bounds follow an action
    // (codegen.cpp followCode).
    const ActionPlan& plan = planActions(g);
    reachOff_ = std::uint32_t(extra_host_.size());
    const auto& acts = g.actions.actions();
    for (std::size_t k = 0; k < acts.size(); ++k) {
      const ActionPlan::Reach& r = plan.reach[k];
      float follows = 0.0f, gain = 0.0f;
      if (const auto* b = std::get_if<Bounce>(&acts[k])) {
        // |v'| <= |v|: restitution and 1 - friction at most 1 in size.
        follows = std::abs(b->restitution) <= 1.0f && b->friction >= 0.0f && b->friction <= 2.0f;
      } else if (const auto* d = std::get_if<Damping>(&acts[k])) {
        follows = d->rate.x >= 0.0f && d->rate.y >= 0.0f && d->rate.z >= 0.0f;
      } else if (const auto* gr = std::get_if<Gravity>(&acts[k])) {
        // The weight is 1, or (1 - d/radius)^power <= 1.
        follows = !(gr->falloff.radius < kInfinity) ||
                  (gr->falloff.radius > 0.0f && gr->falloff.power >= 0.0f);
        const Vec3 a = gr->acceleration;
        gain = std::abs(a.x) + std::abs(a.y) + std::abs(a.z);
      }
      static_assert(FL_REACH_FLOATS == 10);
      const float box[FL_REACH_FLOATS] = {
          r.lo[0],     r.lo[1], r.lo[2], r.hi[0], r.hi[1], r.hi[2], r.cullable ? r.scale : -1.0f,
          r.quadratic, follows, gain};
      extra_host_.insert(extra_host_.end(), box, box + FL_REACH_FLOATS);
    }
    packedVersion_ = g.actionsVersion;
    packedDt_ = dtBitsF;
    // Compared as bytes: the floats hold integers and doubles as bit patterns (NaN patterns
    // among them), so a comparison of values could never say equal, or miss a -0.
    paramsStale_ |= params_uploaded_.size() != params_host_.size() ||
                    std::memcmp(params_uploaded_.data(), params_host_.data(),
                                params_host_.size() * sizeof(cl::FlActionParams)) != 0;
    extraStale_ |= extra_uploaded_.size() != extra_host_.size() ||
                   std::memcmp(extra_uploaded_.data(), extra_host_.data(),
                               extra_host_.size() * sizeof(float)) != 0;
  }

  InFlight& f = inFlight_.next();
  const std::uint64_t total = planBirths(g, sp, f.tables, emitterCodes_);
  const std::uint32_t births = std::uint32_t(std::min<std::uint64_t>(total, g.capacity));
  g.stats.droppedAtCapacity += total - births;  // the device sees at most `capacity`
  f.births = births;
  // A hair group's strands: the particles it began the step with (a sub-emitter's newborns,
  // appended by the host; otherwise it is empty) and its newborns, in id order.
  const std::size_t hairStrands = g.hair.enabled ? std::min(size_ + births, g.capacity) : 0;

  // The step acts on the live particles and its newborns: an upper bound of both.
  std::size_t bound = size_;
  for (std::size_t k = 0; k < inFlight_.size(); ++k) bound += inFlight_[k].births;
  const std::size_t nBound = std::min(bound + births, g.capacity);
  const bool acts = !g.actions.empty() && nBound > 0;
  const bool kills = acts;                      // the NaN guard can kill in any list
  const std::size_t deathRoom = g.deathRoom();  // Group::recordDeaths
  const bool trails = trailSlots_ > 0;
  // Nothing on the device changes (but a trail's new head, as on the CPU).
  if (!acts && births == 0 && !trails && hairStrands == 0) return;
  // New action constants (a new list, a new dt, a move) go up behind the steps in flight,
  // which the queue runs first, without the host waiting for them: from the step's own copy,
  // which stays as it is until the step retires (after the write, in the queue's order). A
  // buffer that grows is made anew; the steps in flight keep the old one until they end.
  auto upload = [&](GrowBuffer& buf, const void* host, std::size_t bytes,
                    std::vector<std::uint8_t>& copy, const char* what) {
    buf.reserve(context(), bytes, CL_MEM_READ_ONLY);
    if (bytes == 0) return;  // (an empty list: nothing reads it)
    copy.resize(bytes);
    std::memcpy(copy.data(), host, bytes);
    unpushedWrite_ = true;
    check(clEnqueueWriteBuffer(queue(), buf.mem.get(), CL_FALSE, 0, bytes, copy.data(), 0, nullptr,
                               nullptr),
          what);
  };
  if (paramsStale_) {
    upload(params_, params_host_.data(), params_host_.size() * sizeof(cl::FlActionParams), f.params,
           "clEnqueueWriteBuffer (action parameters)");
    params_uploaded_ = params_host_;
    paramsStale_ = false;
  }
  if (extraStale_) {
    upload(extra_, extra_host_.data(), extra_host_.size() * sizeof(float), f.extra,
           "clEnqueueWriteBuffer (action data)");
    extra_uploaded_ = extra_host_;
    extraStale_ = false;
  }
  if (hits && acts) {
    // Room for every particle deflected by each Bounce in each sub-step, or the most a step
    // had, within one buffer the device allows; taken before anything of the step is queued.
    std::size_t bounces = 0;
    for (const Action& a : g.actions.actions()) bounces += std::holds_alternative<Bounce>(a);
    const std::size_t substeps =
        substepsByDistance_ ? g.actions.substeps().maxSubsteps : stepSubsteps(g.actions, sp.dt);
    hitRoom_ = std::min(mostHits(), std::max({hitRoom_,
                                              g.capacity * std::max<std::size_t>(bounces, 1) *
                                                  std::max<std::size_t>(substeps, 1),
                                              std::size_t(1024)}));
    hits_.reserve(context(), (16 + 16 * hitRoom_) * 4);
  }

  cl_command_queue q = queue();
  cl_mem state = state_.mem.get();
  const cl_uint seedLo = cl_uint(sp.seed), seedHi = cl_uint(sp.seed >> 32);
  const cl_uint cap = cl_uint(g.capacity);
  const cl_ulong t1Bits = cl_ulong(doubleBits(sp.end));
  auto launch = [&](cl_kernel k, std::size_t global, std::size_t local, const char* what) {
    cl_event e = nullptr;
    check(clEnqueueNDRangeKernel(q, k, 1, nullptr, &global, &local, 0, nullptr,
                                 shared_->profile ? &e : nullptr),
          what);
    if (e) profiled_.emplace_back(what, Event(e));
  };

  // The emission tables travel in one buffer, at 64-byte aligned offsets: the runs first
  // (they change every step), then the emitters' part, which is written only when it
  // changed (a static emitter's does not). Each write costs a few microseconds on PoCL.
  auto& t = f.tables;
  std::uint32_t off[5] = {};
  if (births > 0) {
    auto& blob = f.blob;
    bool layout = false;  // the runs outgrew their room: everything moves
    if (t.runs.size() > runsRoom_) {
      runsRoom_ = std::max<std::size_t>(2 * runsRoom_, std::max<std::size_t>(t.runs.size(), 4));
      layout = true;
    }
    static_assert(sizeof(cl::FlBirthRun) == 64);
    const std::size_t runsWords = runsRoom_ * 8;
    blob.resize(runsWords);
    if (!t.runs.empty()) std::memcpy(blob.data(), t.runs.data(), t.runs.size() * 64);
    auto append = [&](int at, const void* data, std::size_t bytes) {
      off[at] = std::uint32_t(blob.size() * 8);
      const std::size_t was = blob.size();
      blob.resize(was + (bytes + 63) / 64 * 8);
      if (bytes) std::memcpy(blob.data() + was, data, bytes);
    };
    append(1, t.emitters.data(), t.emitters.size() * sizeof(cl::FlEmitter));
    append(2, t.types.data(), t.types.size() * sizeof(cl::FlParticleType));
    append(3, t.keys.data(), t.keys.size() * sizeof(cl::FlKeyframe));
    append(4, t.shapes.data(), t.shapes.size() * sizeof(float));
    // (resize zeroes the padding append rounds up to: equal tables compare equal)
    const std::size_t staticWords = blob.size() - runsWords;
    if (tables_.reserve(context(), blob.size() * 8, CL_MEM_READ_ONLY)) layout = true;
    const bool same =
        !layout && staticUploaded_.size() == staticWords &&
        std::memcmp(staticUploaded_.data(), blob.data() + runsWords, staticWords * 8) == 0;
    unpushedWrite_ = true;  // (both writes read the slot's blob)
    if (!same) {
      check(clEnqueueWriteBuffer(q, tables_.mem.get(), CL_FALSE, runsWords * 8, staticWords * 8,
                                 blob.data() + runsWords, 0, nullptr, nullptr),
            "clEnqueueWriteBuffer (emitters)");
      staticUploaded_.assign(blob.begin() + std::ptrdiff_t(runsWords), blob.end());
    }
    check(clEnqueueWriteBuffer(q, tables_.mem.get(), CL_FALSE, 0, t.runs.size() * 64, blob.data(),
                               0, nullptr, nullptr),
          "clEnqueueWriteBuffer (birth runs)");
  } else {
    tables_.reserve(context(), 64, CL_MEM_READ_ONLY);
  }
  // fl_birth's arguments after its lanes and tau; fl_small takes the same from `tables` on.
  auto birthArgs = [&](cl_kernel k, cl_uint i, bool withState) {
    if (withState) {
      setArg(k, i++, state);
      setArg(k, i++, cl_uint(births));
      setArg(k, i++, cap);
    }
    setArg(k, i++, tables_.mem.get());
    for (int at = 1; at < 5; ++at) setArg(k, i++, cl_uint(off[at]));
    setArg(k, i++, cl_uint(t.runs.size()));
    if (withState) {
      setArg(k, i++, t1Bits);
      setArg(k, i++, seedLo);
      setArg(k, i++, seedHi);
    }
    setArg(k, i++, cl_uint(g.streamKey()));
  };
  // A small group's step is one launch (fl_small) when its program has it.
  const std::size_t tiles = (nBound + FL_TILE - 1) / FL_TILE;
  const bool oneLaunch = acts && small_ && tiles <= kSmallTiles && !g.hair.enabled &&
                         deathRoom == 0 && !hits && !g.birthsFeed && !trails;
  if (births > 0 && !oneLaunch) {
    birthArgs(birth_.get(), cl_uint(lanes_.size()) + 1, true);
    launch(birth_.get(), roundUp(births, kSmallLocal), kSmallLocal, "fl_birth");
  }
  if (births > 0 && trails) {
    // A newborn's trail starts where it was born (startTrails), in the ring's head.
    cl_kernel k = trailStart_.get();
    for (int c = 0; c < 3; ++c) setArg(k, cl_uint(c), positionLane(c));
    setArg(k, 3, trail_.get());
    setArg(k, 4, trailCount_.get());
    setArg(k, 5, state);
    setArg(k, 6, cl_uint(births));
    setArg(k, 7, cap);
    setArg(k, 8, cl_uint(g.trailHead));
    launch(k, roundUp(births, kSmallLocal), kSmallLocal, "fl_trail_start");
  }
  if (births > 0 && g.birthsFeed) {
    // Where they were born, before the act kernel moves them (a sub-emitter on birth).
    births_.reserve(context(), (8 + 8 * std::size_t(births)) * 4);
    cl_kernel k = birthEvents_.get();
    setArg(k, 0, state);
    setArg(k, 1, cl_uint(births));
    setArg(k, 2, cap);
    setArg(k, 12, births_.mem.get());
    launch(k, roundUp(births, kSmallLocal), kSmallLocal, "fl_births");
  }
  if (acts) {
    cl_kernel k = act_.get();
    if (substepsByDistance_) {
      const cl_uint zero = 0;
      check(
          clEnqueueFillBuffer(q, state, &zero, 4, FL_STATE_MAX_SPEED2 * 4, 4, 0, nullptr, nullptr),
          "clEnqueueFillBuffer (state)");
      setArg(maxSpeed_.get(), 3, state);
      setArg(maxSpeed_.get(), 4, cl_uint(births));
      setArg(maxSpeed_.get(), 5, cap);
      launch(maxSpeed_.get(), std::min(roundUp(nBound, 64), std::size_t(1) << 14), 64,
             "fl_max_speed");
    }
    cl_mem snap = extra_.mem.get();
    if (neighbours_) {
      // Neighbours are read as they were at the start of the step (fused_pass.cpp), the
      // newborns where they were born.
      snap_.reserve(context(), 9 * g.capacity * 4);
      snap = snap_.mem.get();
      for (auto& l : lanes_) {
        int slot = -1;
        if (l.ref.attribute == Attribute::Position) slot = 0;
        if (l.ref.attribute == Attribute::Velocity) slot = 1;
        if (l.ref.attribute == Attribute::RotVelocity) slot = 2;
        if (slot < 0) continue;
        check(clEnqueueCopyBuffer(
                  q, l.mem.get(), snap, 0,
                  (std::size_t(slot) * 3 + std::size_t(l.ref.component)) * g.capacity * 4,
                  nBound * 4, 0, nullptr, nullptr),
              "clEnqueueCopyBuffer (neighbours)");
      }
    }
    cl_uint i = cl_uint(actLanes_.size()) + 1;
    if (oneLaunch) {
      k = small_.get();
      i = 0;
      for (const auto& l : lanes_) setArg(k, i++, l.mem.get());
      setArg(k, i++, codes_.get());
    }
    setArg(k, i++, params_.mem.get());
    setArg(k, i++, state);
    setArg(k, i++, extra_.mem.get());
    setArg(k, i++, snap);
    setArg(k, i++, cl_ulong(doubleBits(sp.dt)));
    setArg(k, i++, cl_ulong(doubleBits(sp.time)));
    setArg(k, i++, seedLo);
    setArg(k, i++, seedHi);
    setArg(k, i++, cl_uint(sp.step));
    setArg(k, i++, cl_uint(g.streamKey() << 16));
    setArg(k, i++, cl_uint(stepSubsteps(g.actions, sp.dt)));
    setArg(k, i++, cl_uint(g.capacity));
    setArg(k, i++, tau_.get());
    setArg(k, i++, cl_uint(births));
    setArg(k, i++, cap);
    setArg(k, i++, t1Bits);
    setArg(k, i++, cl_uint(reachOff_));  // read only by a program that culls
    if (hits && acts) {
      const cl_uint zero = 0;
      check(clEnqueueFillBuffer(q, hits_.mem.get(), &zero, 4, 0, 4, 0, nullptr, nullptr),
            "clEnqueueFillBuffer (collisions)");
      setArg(k, i++, hits_.mem.get());
      setArg(k, i++, cl_uint(hitRoom_));
    }
    if (oneLaunch) {
      setArg(k, i++, tileDead_.get());
      setArg(k, i++, tileOff_.get());
      setArg(k, i++, holes_.get());
      setArg(k, i++, tailList_.get());
      setArg(k, i++, cl_uint(tiles));
      birthArgs(k, i, false);
      launch(k, kActLocal, kActLocal, "fl_small");
    } else {
      launch(k, roundUp(nBound, kActLocal), kActLocal, "fl_act");
    }
  }
  if (oneLaunch) {
    // fl_small did the rest of the step
  } else if (kills) {
    if (tiles <= kSmallTiles) {
      setArg(scanList_.get(), 5, state);
      setArg(scanList_.get(), 6, cl_uint(births));
      setArg(scanList_.get(), 7, cap);
      setArg(scanList_.get(), 8, cl_uint(tiles));
      launch(scanList_.get(), 1, 1, "fl_scan_list");
    } else {
      const std::size_t global = roundUp(tiles, kSmallLocal);
      setArg(count_.get(), 2, state);
      setArg(count_.get(), 3, cl_uint(births));
      setArg(count_.get(), 4, cap);
      launch(count_.get(), global, kSmallLocal, "fl_count");
      setArg(scan_.get(), 3, state);
      setArg(scan_.get(), 4, cl_uint(tiles));
      setArg(scan_.get(), 5, cl_uint(births));
      setArg(scan_.get(), 6, cap);
      launch(scan_.get(), 1, 1, "fl_scan");
      setArg(list_.get(), 5, state);
      launch(list_.get(), global, kSmallLocal, "fl_list");
    }
  } else {
    // No actions: the newborns only join the live particles.
    setArg(scan_.get(), 3, state);
    setArg(scan_.get(), 4, cl_uint(0));
    setArg(scan_.get(), 5, cl_uint(births));
    setArg(scan_.get(), 6, cap);
    launch(scan_.get(), 1, 1, "fl_scan");
  }
  if (kills && deathRoom > 0) {
    // The dead as the pass left them, before the tail moves survivors into their slots.
    events_.reserve(context(), std::min(deathRoom, g.capacity) * kDeathEventBytes);
    cl_kernel k = deaths_.get();
    setArg(k, 2, state);
    setArg(k, 11, events_.mem.get());
    setArg(k, 12, cl_uint(std::min(deathRoom, g.capacity)));
    setArg(k, 13, cl_uint(tiles));
    launch(k, roundUp(std::max<std::size_t>(tiles, 1), kSmallLocal), kSmallLocal, "fl_deaths");
  }
  {
    if (kills && !oneLaunch) {
      cl_kernel k = tailKernel_.get();
      setArg(k, cl_uint(lanes_.size()) + 2, state);
      launch(k, std::min(roundUp(nBound, kSmallLocal), kMaxFillItems), kSmallLocal, "fl_tail");
      if (trails) {  // the trails move with their particles
        k = trailTail_.get();
        setArg(k, 0, trail_.get());
        setArg(k, 1, trailCount_.get());
        setArg(k, 2, cl_uint(3 * trailSlots_));
        setArg(k, 3, cap);
        setArg(k, 4, holes_.get());
        setArg(k, 5, tailList_.get());
        setArg(k, 6, state);
        launch(k, std::min(roundUp(nBound, kSmallLocal), kMaxFillItems), kSmallLocal,
               "fl_trail_tail");
      }
    }
    if (trails) {
      // The ring turns; every live particle's position goes into the new head (recordTrails).
      g.trailHead = (g.trailHead + 1) % trailSlots_;
      cl_kernel k = trailRecord_.get();
      for (int c = 0; c < 3; ++c) setArg(k, cl_uint(c), positionLane(c));
      setArg(k, 3, trail_.get());
      setArg(k, 4, trailCount_.get());
      setArg(k, 5, state);
      setArg(k, 6, cap);
      setArg(k, 7, cl_uint(g.trailHead));
      setArg(k, 8, cl_uint(trailSlots_));
      launch(k, std::max(roundUp(nBound, kSmallLocal), kSmallLocal), kSmallLocal,
             "fl_trail_record");
    }
    if (g.hair.enabled && hairStrands > 0) {
      queueHair(g, sp, hairStrands);
      f.births = 0;  // the group is empty again after the step
    }

    // The step's counts come back without the host waiting; later steps size their launches
    // from them.
    f.state.resize(FL_STATE_HEADER + FL_KILL_CODES);
    cl_event e = nullptr;
    check(clEnqueueReadBuffer(q, state, CL_FALSE, 0, f.state.size() * 4, f.state.data(), 0, nullptr,
                              &e),
          "clEnqueueReadBuffer (state)");
    f.done = Event(e);
    inFlight_.push();
    unpushedWrite_ = false;
  }
  check(clFlush(q), "clFlush");
  deviceNewer_ = true;
  fresh_ = AttributeSet();
  trailFresh_ = false;
  if (g.hair.enabled && hairStrands > 0) {
    // Strands are host data: the step's come back now.
    drain(g);
    readStrands(g, hairStrands);
  }
  while (inFlight_.size() > kMaxInFlight) retire(g, true);
  while (!inFlight_.empty()) {  // take what is done without waiting
    const std::size_t before = inFlight_.size();
    retire(g, false);
    if (inFlight_.size() == before) break;
  }
  if (kills && deathRoom > 0) readDeaths(g, deathRoom, sp.end);
  if (hits && acts) readCollisions(g);
  if (births > 0 && g.birthsFeed) readBirths(g, sp.end);
}

void ClGroup::readBirths(GroupImpl& g, double t1) {
  drain(g);
  std::uint32_t born = 0;
  check(clEnqueueReadBuffer(queue(), births_.mem.get(), CL_TRUE, 0, 4, &born, 0, nullptr, nullptr),
        "clEnqueueReadBuffer (birth count)");
  deathWords_.resize(std::size_t(born) * 8);
  if (born > 0)
    check(clEnqueueReadBuffer(queue(), births_.mem.get(), CL_TRUE, 32, std::size_t(born) * 32,
                              deathWords_.data(), 0, nullptr, nullptr),
          "clEnqueueReadBuffer (births)");
  g.stats.bytesReadBack += 4 + std::size_t(born) * 32;
  if (g.birthEvents.capacity() < g.capacity) g.birthEvents.reserve(g.capacity);  // once
  g.birthEvents.resize(born);
  for (std::size_t r = 0; r < born; ++r) {
    const std::uint32_t* w = deathWords_.data() + 8 * r;
    DeathEvent& e = g.birthEvents[r];
    motionFromWords(w, e);
    e.id = w[6];
    e.action = 0;
    e.time = t1 - double(std::bit_cast<float>(w[7]));
  }
}

void ClGroup::readCollisions(GroupImpl& g) {
  drain(g);
  std::uint32_t total = 0;
  check(clEnqueueReadBuffer(queue(), hits_.mem.get(), CL_TRUE, 0, 4, &total, 0, nullptr, nullptr),
        "clEnqueueReadBuffer (collision count)");
  const std::size_t got = std::min<std::size_t>(total, hitRoom_);
  hitWords_.resize(got * 16);
  if (got > 0)
    check(clEnqueueReadBuffer(queue(), hits_.mem.get(), CL_TRUE, 64, got * 64, hitWords_.data(), 0,
                              nullptr, nullptr),
          "clEnqueueReadBuffer (collisions)");
  g.stats.bytesReadBack += 4 + got * 64;
  // Appended in whatever order the device ran: in the CPU's (particle, sub-step, action).
  hitsSorted_.resize(got);
  for (std::size_t j = 0; j < got; ++j) {
    const std::uint32_t* w = hitWords_.data() + 16 * j;
    CollisionEvent e;
    for (int c = 0; c < 3; ++c) {
      e.position[c] = std::bit_cast<float>(w[2 + c]);
      e.velocity[c] = std::bit_cast<float>(w[5 + c]);
      e.normal[c] = std::bit_cast<float>(w[8 + c]);
    }
    e.id = w[11];
    e.action = w[1] & 0xFFFFu;
    e.time = shared_->fp64()
                 ? std::bit_cast<double>(std::uint64_t(w[12]) | std::uint64_t(w[13]) << 32)
                 : double(std::bit_cast<float>(w[12]));
    hitsSorted_[j] = {std::uint64_t(w[0]) << 32 | w[1], e};
  }
  // Only the first `kept` in the CPU's order are wanted (keys are unique: one order).
  const std::size_t kept = std::min(got, g.collisionRoom());
  std::partial_sort(hitsSorted_.begin(), hitsSorted_.begin() + std::ptrdiff_t(kept),
                    hitsSorted_.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  g.collisionEvents.clear();
  for (std::size_t j = 0; j < kept; ++j) g.collisionEvents.push_back(hitsSorted_[j].second);
  g.stats.collisionEventsDropped += GroupImpl::leftOut(total, g.collisionsPerStep);
  // More than the room: this step kept an arbitrary `hitRoom_` of them; later steps have room
  // for as many.
  if (total > hitRoom_) hitRoom_ = std::min<std::size_t>(total, mostHits());
}

void ClGroup::readDeaths(GroupImpl& g, std::size_t room, double t1) {
  // A game reads the events right after the step: this step's count, then its events.
  drain(g);
  const std::size_t kept = std::min<std::size_t>(lastDead_, std::min(room, g.capacity));
  g.stats.deathEventsDropped += GroupImpl::leftOut(lastDead_, g.deathsPerStep);
  g.deathEvents.resize(kept);  // within the room Group::recordDeaths reserved
  if (kept == 0) return;
  deathWords_.resize(kept * 8);
  check(clEnqueueReadBuffer(queue(), events_.mem.get(), CL_TRUE, 0, kept * kDeathEventBytes,
                            deathWords_.data(), 0, nullptr, nullptr),
        "clEnqueueReadBuffer (death events)");
  g.stats.bytesReadBack += kept * kDeathEventBytes;
  for (std::size_t j = 0; j < kept; ++j) {
    const std::uint32_t* w = deathWords_.data() + 8 * j;
    DeathEvent& e = g.deathEvents[j];
    motionFromWords(w, e);
    e.id = w[6];
    e.action = w[7] == FL_NON_FINITE_CODE ? DeathEvent::kNonFinite : w[7] - 1u;
    e.time = t1;
  }
}

class OpenCLBackend final : public BackendImpl {
 public:
  explicit OpenCLBackend(std::shared_ptr<Shared> shared) : shared_(std::move(shared)) {}
  const char* name() const override { return "opencl"; }
  void step(GroupImpl& g, const StepParams& sp) override {
    auto* mine = dynamic_cast<ClGroup*>(g.mirror.get());
    if (!mine) {
      g.syncHost();
      auto m = std::make_unique<ClGroup>(shared_);
      mine = m.get();
      g.mirror = std::move(m);
    }
    mine->step(g, sp);
  }

 private:
  std::shared_ptr<Shared> shared_;
};

}  // namespace

void finishGroup(GroupImpl& group) {
  if (auto* m = dynamic_cast<ClGroup*>(group.mirror.get())) m->finish(group);
}

std::string programSource(const ActionList& actions, AttributeSet stored, bool fp64) {
  return generateProgram(actions, stored, fp64, emissionSource(GroupImpl{})).source;
}

}  // namespace flurry::detail::ocl

namespace flurry::detail {

std::unique_ptr<BackendImpl> makeOpenCLBackend(const ContextOptions& options) {
  auto shared = std::make_shared<ocl::Shared>();
  shared->runtime = ocl::Runtime::get(ocl::selectDevice(options.device));
  cl_int err = CL_SUCCESS;
  const char* profile = std::getenv("FLURRY_OPENCL_PROFILE");
  shared->profile = profile && *profile && std::string(profile) != "0";
  // As many queues as the device has compute units, up to four: enough for PoCL's cores and
  // for a GPU to overlap small groups' launches.
  const std::size_t queues =
      std::clamp<std::size_t>(shared->runtime->device().info.computeUnits, 1, 4);
  for (std::size_t k = 0; k < queues; ++k) {
    shared->queues.emplace_back(
        clCreateCommandQueue(shared->runtime->context(), shared->device(),
                             shared->profile ? CL_QUEUE_PROFILING_ENABLE : 0, &err));
    ocl::check(err, "clCreateCommandQueue");
  }
  return std::make_unique<ocl::OpenCLBackend>(std::move(shared));
}

}  // namespace flurry::detail
