#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

#include "action_traits.hpp"
#include "backend.hpp"
#include "flurry/error.hpp"
#include "group_impl.hpp"
#include "page_arena.hpp"
#include "thread_pool.hpp"
#include "transform.hpp"

namespace flurry {

std::string_view attributeName(Attribute a) {
  static constexpr std::string_view names[] = {
      "position", "velocity", "color",        "size",      "mass",        "age",
      "lifetime", "id",       "prevPosition", "up",        "rotVelocity", "charge",
      "visible",  "userData", "positionB",    "velocityB", "birthColor",  "birthSize"};
  const auto i = std::size_t(a);
  return i < std::size(names) ? names[i] : "unknown";
}

namespace detail {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}

namespace {
// A lane's bytes before rounding: at least 16 elements (a vector's tail may read them).
std::size_t laneBytes(std::size_t count) {
  return std::max<std::size_t>(count, 16) * 4;
}
}  // namespace

LaneBuffer::LaneBuffer(std::size_t count) : count_(count) {
  std::size_t bytes = laneBytes(count);
  if (bytes <= kArenaMostBytes) {
    data_ = arenaAllocate(bytes);  // a small group's: beside its neighbours', in huge pages
    return;
  }
  // A lane of a huge page or more starts on one and asks for them (its whole 2 MiB pieces;
  // the rest is in small pages): a pass over a large group then walks the page table once
  // per 2 MiB of a lane, not once per 4 KiB, which under a hypervisor was a third of the step.
  // A lane within an eighth of whole huge pages is rounded up to them (a 500k-particle lane,
  // 2.0 MB, takes one 2 MiB page).
  const std::size_t whole = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  const bool huge = 8 * (whole - bytes) <= bytes || bytes >= kHugePage;
  bytes = 8 * (whole - bytes) <= bytes ? whole : (bytes + 63) / 64 * 64;
  if (posix_memalign(&data_, huge ? kHugePage : 64, bytes) != 0) data_ = nullptr;
  if (!data_)
    throw Error("out of memory allocating " + std::to_string(bytes) + " bytes of particles");
#ifdef MADV_HUGEPAGE
  if (huge) madvise(data_, bytes, MADV_HUGEPAGE);  // a hint; failure only costs speed
#endif
}

namespace {
void freeLane(void* data, std::size_t count) {
  if (!data) return;
  const std::size_t bytes = laneBytes(count);
  if (bytes <= kArenaMostBytes)
    arenaFree(data, bytes);
  else
    std::free(data);
}
}  // namespace

LaneBuffer::~LaneBuffer() {
  freeLane(data_, count_);
}

LaneBuffer& LaneBuffer::operator=(LaneBuffer&& o) noexcept {
  if (this != &o) {
    freeLane(data_, count_);
    data_ = o.data_;
    count_ = o.count_;
    o.data_ = nullptr;
    o.count_ = 0;
  }
  return *this;
}

void assignFill(std::vector<std::uint32_t>& v, std::size_t n, std::uint32_t value) {
  v.assign(n, value);
}
void assignFill(std::vector<float>& v, std::size_t n, float value) {
  v.assign(n, value);
}

Lanes Lanes::offsetBy(std::size_t b) const {
  Lanes r = *this;
  forEachLanePointer(r, [b](auto*& ptr) {
    if (ptr) ptr += b;
  });
  return r;
}

void GroupImpl::cacheLanes() {
  Lanes& l = laneCache;
  auto f = [&](Attribute a, int c) { return lanes[std::size_t(a)][c].f(); };
  for (int c = 0; c < 3; ++c) {
    l.p[c] = f(Attribute::Position, c);
    l.v[c] = f(Attribute::Velocity, c);
    l.prev[c] = f(Attribute::PrevPosition, c);
    l.up[c] = f(Attribute::Up, c);
    l.rot[c] = f(Attribute::RotVelocity, c);
    l.posB[c] = f(Attribute::PositionB, c);
    l.velB[c] = f(Attribute::VelocityB, c);
  }
  for (int c = 0; c < 4; ++c) {
    l.color[c] = f(Attribute::Color, c);
    l.birthColor[c] = f(Attribute::BirthColor, c);
  }
  l.size = f(Attribute::Size, 0);
  l.birthSize = f(Attribute::BirthSize, 0);
  l.mass = f(Attribute::Mass, 0);
  l.age = f(Attribute::Age, 0);
  l.lifetime = f(Attribute::Lifetime, 0);
  l.id = lanes[std::size_t(Attribute::Id)][0].u();
  l.charge = f(Attribute::Charge, 0);
  l.visible = lanes[std::size_t(Attribute::Visible)][0].u();
  l.user = f(Attribute::UserData, 0);
  laneSlots = l.storedSlots();
}

void writeParticle(const Lanes& l, std::size_t i, const Particle& q) {
  for (int c = 0; c < 3; ++c) {
    l.p[c][i] = q.position[c];
    if (l.v[c]) l.v[c][i] = q.velocity[c];
    if (l.prev[c]) l.prev[c][i] = q.prevPosition[c];
    if (l.up[c]) l.up[c][i] = q.up[c];
    if (l.rot[c]) l.rot[c][i] = q.rotVelocity[c];
    if (l.posB[c]) l.posB[c][i] = q.positionB[c];
    if (l.velB[c]) l.velB[c][i] = q.velocityB[c];
  }
  for (int c = 0; c < 4; ++c)
    if (l.color[c]) l.color[c][i] = q.color[c];
  if (l.size) l.size[i] = q.size;
  if (l.mass) l.mass[i] = q.mass;
  if (l.age) l.age[i] = q.age;
  if (l.lifetime) l.lifetime[i] = q.lifetime;
  if (l.id) l.id[i] = q.id;
  if (l.charge) l.charge[i] = q.charge;
  if (l.visible) l.visible[i] = q.visible ? 1u : 0u;
  if (l.user) l.user[i] = q.userData;
}

Particle readParticle(const Lanes& l, std::size_t i) {
  Particle q;
  for (int c = 0; c < 3; ++c) {
    q.position[c] = l.p[c][i];
    if (l.v[c]) q.velocity[c] = l.v[c][i];
    if (l.prev[c]) q.prevPosition[c] = l.prev[c][i];
    if (l.up[c]) q.up[c] = l.up[c][i];
    if (l.rot[c]) q.rotVelocity[c] = l.rot[c][i];
    if (l.posB[c]) q.positionB[c] = l.posB[c][i];
    if (l.velB[c]) q.velocityB[c] = l.velB[c][i];
  }
  for (int c = 0; c < 4; ++c)
    if (l.color[c]) q.color[c] = l.color[c][i];
  if (l.size) q.size = l.size[i];
  if (l.mass) q.mass = l.mass[i];
  if (l.age) q.age = l.age[i];
  if (l.lifetime) q.lifetime = l.lifetime[i];
  if (l.id) q.id = l.id[i];
  if (l.charge) q.charge = l.charge[i];
  if (l.visible) q.visible = l.visible[i] != 0;
  if (l.user) q.userData = l.user[i];
  return q;
}

void GroupImpl::startTrails(std::size_t from, std::size_t to) {
  if (trail.length == 0) return;
  const Lanes L = lanePointers();
  for (int c = 0; c < 3; ++c)
    std::copy(L.p[c] + from, L.p[c] + to, trailLanes[3 * trailHead + c].f() + from);
  std::fill(trailCount.u() + from, trailCount.u() + to, 1u);
}

std::uint32_t* GroupImpl::nextTrailSlot(float** slot) {
  if (trail.length == 0) return nullptr;
  const std::size_t next = 3 * std::size_t((trailHead + 1) % trail.length);
  for (std::size_t c = 0; c < 3; ++c) slot[c] = trailLanes[next + c].f();
  trailRecorded = true;
  return trailCount.u();
}

void GroupImpl::recordTrails(ThreadPool& pool) {
  if (trail.length == 0) return;
  trailHead = (trailHead + 1) % trail.length;
  if (trailRecorded) {  // by the fused pass, block by block
    trailRecorded = false;
    return;
  }
  const Lanes L = lanePointers();
  float* const slot[3] = {trailLanes[3 * trailHead].f(), trailLanes[3 * trailHead + 1].f(),
                          trailLanes[3 * trailHead + 2].f()};
  std::uint32_t* const count = trailCount.u();
  const std::uint32_t most = trail.length;
  constexpr std::size_t kPerTask = 65536;
  auto record = [&](std::size_t t) {
    const std::size_t a = t * kPerTask, b = std::min(size, a + kPerTask);
    for (int c = 0; c < 3; ++c) std::copy(L.p[c] + a, L.p[c] + b, slot[c] + a);
    for (std::size_t i = a; i < b; ++i) count[i] = std::min(count[i] + 1u, most);
  };
  const std::size_t tasks = (size + kPerTask - 1) / kPerTask;
  if (tasks > 1)
    pool.parallelFor(tasks, record);
  else if (tasks == 1)
    record(0);
}

void GroupImpl::ensureStorage() {
  if (actionAttributesVersion != actionsVersion) {
    actionAttributes = actions.attributes();
    actionAttributesVersion = actionsVersion;
  }
  // While particles exist, lanes are kept even when no action reads them any more: they hold
  // state (a rest pose, a charge) that a later action list may read again.
  const AttributeSet want = size > 0 ? wanted() | stored : wanted();
  if (want == stored) return;
  const Particle defaults;
  for (int a = 0; a < int(Attribute::Count); ++a) {
    const Attribute attr = Attribute(a);
    auto& slot = lanes[std::size_t(a)];
    if (want.has(attr) && !stored.has(attr)) {
      for (int c = 0; c < componentCount(attr); ++c) slot[c] = LaneBuffer(capacity);
    } else if (!want.has(attr) && stored.has(attr)) {
      for (auto& lane : slot) lane = LaneBuffer();
    }
  }
  cacheLanes();
  const AttributeSet before = stored;
  stored = want;
  if (size == 0) return;
  // Existing particles get the defaults for the lanes just added.
  const Lanes l = lanePointers();
  for (std::size_t i = 0; i < size; ++i) {
    for (int c = 0; c < 3; ++c) {
      if (!before.has(Attribute::Velocity) && l.v[c]) l.v[c][i] = defaults.velocity[c];
      if (!before.has(Attribute::PrevPosition) && l.prev[c]) l.prev[c][i] = l.p[c][i];
      if (!before.has(Attribute::Up) && l.up[c]) l.up[c][i] = defaults.up[c];
      if (!before.has(Attribute::RotVelocity) && l.rot[c]) l.rot[c][i] = 0.0f;
      if (!before.has(Attribute::PositionB) && l.posB[c]) l.posB[c][i] = l.p[c][i];
      if (!before.has(Attribute::VelocityB) && l.velB[c]) l.velB[c][i] = 0.0f;
    }
    for (int c = 0; c < 4; ++c)
      if (!before.has(Attribute::Color) && l.color[c]) l.color[c][i] = defaults.color[c];
    if (!before.has(Attribute::Size) && l.size) l.size[i] = defaults.size;
    // Particles alive when a curve starts scaling their birth value keep what they have now.
    for (int c = 0; c < 4; ++c)
      if (!before.has(Attribute::BirthColor) && l.birthColor[c])
        l.birthColor[c][i] = l.color[c] ? l.color[c][i] : defaults.color[c];
    if (!before.has(Attribute::BirthSize) && l.birthSize)
      l.birthSize[i] = l.size ? l.size[i] : defaults.size;
    if (!before.has(Attribute::Mass) && l.mass) l.mass[i] = defaults.mass;
    if (!before.has(Attribute::Age) && l.age) l.age[i] = 0.0f;
    if (!before.has(Attribute::Lifetime) && l.lifetime) l.lifetime[i] = defaults.lifetime;
    if (!before.has(Attribute::Charge) && l.charge) l.charge[i] = 0.0f;
    if (!before.has(Attribute::Visible) && l.visible) l.visible[i] = 1u;
    if (!before.has(Attribute::UserData) && l.user) l.user[i] = 0.0f;
  }
}

}  // namespace detail

Group::Group(std::unique_ptr<detail::GroupImpl> impl) : impl_(std::move(impl)) {}
Group::~Group() = default;

const std::string& Group::name() const {
  return impl_->name;
}
std::size_t Group::size() const {
  impl_->syncCount();
  return impl_->size;
}
std::size_t Group::capacity() const {
  return impl_->capacity;
}
AttributeSet Group::attributes() const {
  return impl_->wanted();
}

void Group::require(AttributeSet attributes) {
  impl_->syncHost();
  impl_->required.insert(attributes);
  impl_->ensureStorage();
  impl_->hostChanged();
}

Group& Group::setActions(ActionList actions) {
  impl_->syncHost();
  if (auto* f = impl_->frame.get()) {
    ActionList world =
        f->transform.isIdentity() ? actions : detail::transformActions(actions, f->transform);
    f->actions = std::move(actions);
    actions = std::move(world);
  }
  impl_->actions = std::move(actions);
  ++impl_->actionsVersion;  // the fused pass's plan is rebuilt
  ++impl_->actionsStructure;
  impl_->stats.killedByAction.assign(impl_->actions.size(), 0);
  impl_->ensureStorage();
  impl_->hostChanged();
  return *this;
}

const ActionList& Group::actions() const {
  return impl_->frame ? impl_->frame->actions : impl_->actions;
}

namespace {

// Carries the live particles from transform `from` to `to` (Space::Local): points through
// to ∘ from⁻¹, vectors by the change of rotation alone (see Transform).
void carryParticles(detail::GroupImpl& g, const Transform& from, const Transform& to) {
  g.syncHost();
  if (g.size == 0 && g.live.empty()) return;
  const glm::quat dq = to.rotation * glm::conjugate(from.rotation);
  const float ds = to.scale / from.scale;
  const detail::Lanes L = g.lanePointers();
  auto points = [&](float* const* lane) {
    if (!lane[0]) return;
    for (std::size_t i = 0; i < g.size; ++i) {
      const Vec3 p(lane[0][i], lane[1][i], lane[2][i]);
      const Vec3 q = to.position + dq * (ds * (p - from.position));
      lane[0][i] = q.x, lane[1][i] = q.y, lane[2][i] = q.z;
    }
  };
  auto vectors = [&](float* const* lane) {
    if (!lane[0]) return;
    for (std::size_t i = 0; i < g.size; ++i) {
      const Vec3 v = dq * Vec3(lane[0][i], lane[1][i], lane[2][i]);
      lane[0][i] = v.x, lane[1][i] = v.y, lane[2][i] = v.z;
    }
  };
  points(L.p);
  points(L.prev);
  points(L.posB);
  for (std::size_t k = 0; k < g.trailLanes.size(); k += 3) {
    float* const slot[3] = {g.trailLanes[k].f(), g.trailLanes[k + 1].f(), g.trailLanes[k + 2].f()};
    points(slot);
  }
  vectors(L.v);
  vectors(L.velB);
  vectors(L.up);
  vectors(L.rot);
  // Emitters spawned by prime emitters are part of the effect's state too.
  for (detail::LiveEmitter& e : g.live) {
    e.position = to.position + dq * (ds * (e.position - from.position));
    e.velocity = dq * e.velocity;
  }
  g.hostChanged();
}

}  // namespace

namespace {

// Whether two transforms are the same to the bit (-0 and +0 differ: no move is missed).
bool sameBits(const Transform& a, const Transform& b) {
  const float x[8] = {a.position.x, a.position.y, a.position.z, a.rotation.w,
                      a.rotation.x, a.rotation.y, a.rotation.z, a.scale};
  const float y[8] = {b.position.x, b.position.y, b.position.z, b.rotation.w,
                      b.rotation.x, b.rotation.y, b.rotation.z, b.scale};
  return std::memcmp(x, y, sizeof x) == 0;
}

// Whether the frame's lists refuse some transform: the one refusal a transform meets is a
// box's turn by other than quarter turns (Domain::transformed), whatever the place and
// scale, so the lists are carried once by a turn that is none (as a move would, on copies)
// each time they change.
bool mayRefuse(detail::GroupImpl& g) {
  detail::Frame& f = *g.frame;
  if (f.probed[0] == g.actionsStructure && f.probed[1] == g.emittersVersion) return f.mayRefuse;
  const Transform turn{Vec3(0.0f), glm::angleAxis(0.5f, glm::normalize(Vec3(1.0f, 2.0f, 3.0f))),
                       1.0f};
  try {
    (void)detail::transformActions(f.actions, turn);
    for (const Emitter& e : f.emitters) (void)detail::transformEmitter(e, turn);
    for (const PrimeEmitter& p : f.primes) (void)detail::transformPrime(p, turn);
    f.mayRefuse = false;
  } catch (const Error&) {
    f.mayRefuse = true;
  }
  f.probed[0] = g.actionsStructure;
  f.probed[1] = g.emittersVersion;
  return f.mayRefuse;
}

// The world emitters and prime emitters as the frame's carried by t, in the storage of the
// last ones: lists of the same lengths are assigned element by element, so that a group
// moved every step allocates nothing (see carryEmitter for what still does).
void deriveEmitters(detail::GroupImpl& g, const Transform& t) {
  const detail::Frame& f = *g.frame;
  const bool identity = t.isIdentity();
  g.emitters = f.emitters;
  if (!identity)
    for (Emitter& e : g.emitters) detail::carryEmitter(e, t);
  g.primes = f.primes;
  if (!identity)
    for (PrimeEmitter& p : g.primes) detail::carryPrime(p, t);
  // A spec no live emitter holds is rewritten in place; one a live emitter holds stays as
  // that emitter was spawned with.
  g.primeSpecs.resize(g.primes.size());
  for (std::size_t k = 0; k < g.primes.size(); ++k) {
    if (g.primeSpecs[k] && g.primeSpecs[k].use_count() == 1)
      *g.primeSpecs[k] = g.primes[k].child;
    else
      g.primeSpecs[k] = std::make_shared<EmitterSpec>(g.primes[k].child);
  }
}

}  // namespace

Group& Group::setTransform(const Transform& transform) {
  transform.validate("transform");
  Transform t = transform;
  t.rotation = glm::normalize(t.rotation);
  if (t.rotation == glm::quat(-1.0f, 0.0f, 0.0f, 0.0f)) t.rotation = glm::quat(1.0f, 0, 0, 0);
  auto& g = *impl_;
  // The same transform again, bit for bit (a game sets every effect's each frame, most of
  // them standing still): nothing to derive, and nothing moves (a local-space group's
  // particles, carried by the turn times its inverse, would take its rounding each time).
  if (g.frame && sameBits(t, g.frame->transform) && g.frame->emittersDerived == g.emittersVersion)
    return *this;
  const bool first = !g.frame;
  if (first) {
    // The lists as given become the frame's; the world's are their images at the identity.
    g.frame = std::make_unique<detail::Frame>();
    g.frame->actions = g.actions;
    g.frame->emitters = g.emitters;
    g.frame->primes = g.primes;
  }
  detail::Frame& fr = *g.frame;
  const bool still = fr.moved[0] == g.actionsStructure && fr.moved[1] == g.emittersVersion;
  fr.moved[0] = g.actionsStructure;
  fr.moved[1] = g.emittersVersion;
  if (!first && still && !mayRefuse(g)) {
    // The world's lists are placed by the group's next step, on the threads that step it
    // (GroupImpl::placeEmitters); what the game reads of the group moves now.
    if (fr.space == Space::Local) carryParticles(g, fr.transform, t);
    fr.transform = t;
    fr.placed = false;
    ++g.actionsVersion;  // (only the actions' constants change, as below)
    return *this;
  }
  // The world's lists are rewritten in place (a move allocates nothing); one that refuses the
  // transform (a box turned by other than quarter turns) is derived again at the old one, so
  // that the group is left as it was.
  try {
    if (!detail::placeActions(g.actions, fr.actions, t))
      g.actions = detail::transformActions(fr.actions, t);
    deriveEmitters(g, t);
  } catch (...) {
    if (!detail::placeActions(g.actions, fr.actions, fr.transform))
      g.actions = detail::transformActions(fr.actions, fr.transform);
    deriveEmitters(g, fr.transform);
    if (first) g.frame.reset();
    throw;
  }
  if (fr.space == Space::Local) carryParticles(g, fr.transform, t);
  fr.transform = t;
  fr.placed = true;
  // Only the actions' constants change (actionsStructure stays): a device backend uploads
  // them, and its program (which depends on the kinds of actions and domains alone) is kept.
  ++g.actionsVersion;
  // The emitters' kinds stay too; their values are read every step.
  if (first) ++g.emittersVersion;
  fr.emittersDerived = g.emittersVersion;
  return *this;
}

const Transform& Group::transform() const {
  static const Transform identity;
  return impl_->frame ? impl_->frame->transform : identity;
}

Group& Group::setSpace(Space space) {
  if (!impl_->frame) setTransform(Transform{});
  impl_->frame->space = space;
  return *this;
}

Space Group::space() const {
  return impl_->frame ? impl_->frame->space : Space::World;
}

Group& Group::setTimeScale(double scale) {
  if (!std::isfinite(scale) || !(scale >= 0.0) || scale > 1000.0)
    throw InvalidArgument("scale", "must be finite and 0 <= scale <= 1000");
  impl_->timeScale = scale;
  return *this;
}

double Group::timeScale() const {
  return impl_->timeScale;
}

Group& Group::setUpdateInterval(std::uint32_t interval) {
  if (interval < 1 || interval > 256) throw InvalidArgument("interval", "must be 1 to 256");
  impl_->updateInterval = interval;
  if (impl_->contextSchedule) ++*impl_->contextSchedule;
  return *this;
}

std::uint32_t Group::updateInterval() const {
  return impl_->updateInterval;
}

Group& Group::setSeed(std::uint64_t seed, std::uint32_t stream) {
  if (stream > 0xFFFFu) throw InvalidArgument("stream", "must be < 65536");
  impl_->ownSeed = true;
  impl_->seed = seed;
  impl_->stream = stream;
  return *this;
}

namespace {
// Prefetches [p, p + bytes), at most kMostPrefetched of it: the head of a large buffer (its
// rest streams in by the hardware's own prefetch). Into the L2, not the L1 (locality 2:
// prefetcht1 on x86, PLDL2KEEP on ARM): a small group's step asks for ~100 lines at once,
// and a prefetch into the L1 holds one of the L1's few miss buffers until its line arrives,
// so such a burst stalls the core as the loads themselves would; the L2 tracks many more.
constexpr std::size_t kMostPrefetched = 4096;
void prefetchBytes(const void* p, std::size_t bytes) {
  const auto* c = static_cast<const char*>(p);
  bytes = std::min(bytes, kMostPrefetched);
  for (std::size_t o = 0; o < bytes; o += 64) __builtin_prefetch(c + o, 0, 2);
  // GCC counts a function that only prefetches as one without effects and deletes the calls
  // of such a function it does not inline: prefetchData's walk over the lanes was compiled
  // away (objdump showed no lane prefetch). An empty volatile asm keeps the calls.
  asm volatile("");
}
template <class T>
void prefetchVector(const std::vector<T>& v) {
  if (!v.empty()) prefetchBytes(v.data(), v.size() * sizeof(T));
}
}  // namespace

void* detail::GroupImpl::operator new(std::size_t bytes) {
  return arenaAllocate(bytes);
}
void detail::GroupImpl::operator delete(void* group, std::size_t bytes) noexcept {
  arenaFree(group, bytes);
}

void detail::GroupImpl::prefetchSelf() const {
  // Up to the part a step does not read (the plan's, then the group's).
  prefetchBytes(this, std::size_t(reinterpret_cast<const char*>(&plan.coldStart) -
                                  reinterpret_cast<const char*>(this)));
}

void detail::GroupImpl::prefetchData(int part, int parts) const {
  const std::size_t bytes = size * sizeof(float) + 64;
  int k = 0;
  forEachSlot(laneCache, laneSlots, [&](const std::uint32_t* lane) {
    if (k == part) prefetchBytes(lane, bytes);
    if (++k == parts) k = 0;
  });
  if (part != 0) return;
  prefetchVector(actions.actions());
  prefetchVector(emitters);
  prefetchVector(emitterState);
  prefetchVector(stats.killedByAction);
  prefetchVector(stats.emittedByGeneration);
  prefetchVector(bornRemaining);
  if (holes.capacity() > 0) prefetchBytes(holes.data(), 64);  // written: the first line
  // The reach and moves are read only by a pass that culls, timeFree only for newborns run
  // apart from their block.
  if (plan.cullable) {
    prefetchVector(plan.reach);
    prefetchVector(plan.moves);
  }
  if (!plan.newbornsWithBlock) prefetchVector(plan.timeFree);
  prefetchVector(plan.gathered);
  prefetchVector(plan.curvedBy);
  prefetchVector(plan.records);
  if (frame) prefetchBytes(frame.get(), sizeof(Frame));
}

void detail::GroupImpl::prefetchDeep() const {
  for (const Emitter& e : emitters) {
    prefetchVector(e.types);
    prefetchVector(e.bursts);
    prefetchVector(e.path);
  }
}

void detail::GroupImpl::placeEmitters() {
  if (!frame) return;
  if (!frame->placed) {
    // (Group::setTransform found that these lists take any transform.)
    if (!detail::placeActions(actions, frame->actions, frame->transform))
      actions = detail::transformActions(frame->actions, frame->transform);
    if (frame->emittersDerived == emittersVersion) deriveEmitters(*this, frame->transform);
    frame->placed = true;
  }
  if (frame->emittersDerived == emittersVersion) return;
  deriveEmitters(*this, frame->transform);
  ++emittersVersion;
  frame->emittersDerived = emittersVersion;
}

namespace {
// Throws InvalidArgument "index" unless i < n (n of `what`).
void checkIndex(std::size_t i, std::size_t n, const char* what) {
  if (i >= n)
    throw InvalidArgument("index",
                          std::to_string(i) + " is past the " + std::to_string(n) + " " + what);
}
}  // namespace

Emitter& Group::addEmitter(Emitter emitter) {
  emitter.validate("emitters[" + std::to_string(impl_->emitters.size()) + "]");
  auto& g = *impl_;
  if (g.frame) {
    const Transform& t = g.frame->transform;
    g.emitters.push_back(t.isIdentity() ? emitter : detail::transformEmitter(emitter, t));
    g.frame->emitters.push_back(std::move(emitter));
  } else {
    g.emitters.push_back(std::move(emitter));
  }
  g.emitterState.emplace_back();
  ++g.emittersVersion;
  if (g.frame) {
    g.frame->emittersDerived = g.emittersVersion;
    return g.frame->emitters.back();
  }
  return g.emitters.back();
}

std::span<Emitter> Group::emitters() {
  ++impl_->emittersVersion;  // the caller may edit through the span
  if (impl_->frame) return impl_->frame->emitters;
  return impl_->emitters;
}

void detail::clearEmitters(GroupImpl& g) {
  g.emitters.clear();
  g.emitterState.clear();
  g.primes.clear();
  g.primeState.clear();
  g.primeSpecs.clear();
  g.live.clear();
  g.primeLive.clear();
  if (g.frame) {
    g.frame->emitters.clear();
    g.frame->primes.clear();
  }
  ++g.emittersVersion;
  if (g.frame) g.frame->emittersDerived = g.emittersVersion;
}

void Group::removeEmitter(std::size_t i) {
  auto& g = *impl_;
  checkIndex(i, g.emitters.size(), "emitters");
  g.emitters.erase(g.emitters.begin() + std::ptrdiff_t(i));
  if (g.frame) g.frame->emitters.erase(g.frame->emitters.begin() + std::ptrdiff_t(i));
  g.emitterState.erase(g.emitterState.begin() + std::ptrdiff_t(i));
  ++g.emittersVersion;
}

PrimeEmitter& Group::addPrimeEmitter(PrimeEmitter prime) {
  prime.validate("primeEmitters[" + std::to_string(impl_->primes.size()) + "]");
  auto& g = *impl_;
  if (g.frame) {
    const Transform& t = g.frame->transform;
    g.primes.push_back(t.isIdentity() ? prime : detail::transformPrime(prime, t));
    g.frame->primes.push_back(std::move(prime));
  } else {
    g.primes.push_back(std::move(prime));
  }
  g.primeState.emplace_back();
  g.primeLive.push_back(0);
  ++g.emittersVersion;
  if (g.frame) {
    g.frame->emittersDerived = g.emittersVersion;
    return g.frame->primes.back();
  }
  return g.primes.back();
}

std::size_t Group::liveEmitterCount() const {
  return impl_->live.size();
}

Group& Group::setHair(HairOptions options) {
  if (options.every == 0) throw InvalidArgument("hair.every", "must be >= 1");
  if (options.maxVertices < 2) throw InvalidArgument("hair.maxVertices", "must be >= 2");
  impl_->syncHost();
  impl_->hair = options;
  if (options.enabled) impl_->size = 0;  // a hair group keeps strands, not live particles
  impl_->hostChanged();
  return *this;
}

const HairOptions& Group::hair() const {
  return impl_->hair;
}
const Strands& Group::strands() const {
  impl_->syncHost();
  return impl_->strands;
}
void Group::clearStrands() {
  impl_->strands.clear();
}

void TrailOptions::validate(const std::string& where) const {
  if (length > kMaxLength)
    throw InvalidArgument(where + ".length", std::to_string(length) + " is past the most, " +
                                                 std::to_string(kMaxLength));
  const std::pair<const char*, float> looks[] = {
      {"width", width}, {"taper", taper}, {"fade", fade}};
  for (const auto& [field, value] : looks)
    if (!(value >= 0.0f) || !std::isfinite(value))
      throw InvalidArgument(where + "." + field, "must be finite and >= 0");
}

Group& Group::setBudgetPolicy(BudgetPolicy policy) {
  if (policy != BudgetPolicy::DropNewest && policy != BudgetPolicy::DropOldest &&
      policy != BudgetPolicy::ScaleEmission)
    throw InvalidArgument("policy", "not a BudgetPolicy");
  impl_->budgetPolicy = policy;
  return *this;
}
BudgetPolicy Group::budgetPolicy() const {
  return impl_->budgetPolicy;
}

void detail::GroupImpl::dropOldest(std::size_t excess, const StepParams& params) {
  // Ids grow with birth (modulo 2^32): the first born are the smallest id - nextId. Only
  // while over budget; the scratch grows once.
  thread_local std::vector<std::uint64_t> byIdStore;
  auto& byId = byIdStore;
  byId.resize(size);
  const std::uint32_t* id = lanePointers().id;
  for (std::size_t i = 0; i < size; ++i) byId[i] = std::uint64_t(id[i] - nextId) << 32 | i;
  std::nth_element(byId.begin(), byId.begin() + std::ptrdiff_t(excess), byId.end());
  holes.clear();
  for (std::size_t k = 0; k < excess; ++k) holes.push_back(std::uint32_t(byId[k]));
  std::sort(holes.begin(), holes.end());
  stats.killedByBudget += excess;
  boundsValid = false;  // the box kept by the pass may hold the dead
  compact(*this, params);
}

void detail::GroupImpl::trimToBudget(const StepParams& params) {
  if (keepAtMost == ~std::size_t(0)) return;
  syncCount();
  if (size <= keepAtMost) return;
  syncHost();
  dropOldest(size - keepAtMost, params);
  hostChanged();
}

Group& Group::setTrail(const TrailOptions& options) {
  auto& g = *impl_;
  options.validate();
  g.syncHost();
  if (options.length != g.trail.length) {
    // Built aside and swapped in: a failed allocation leaves the old trail as it was.
    std::vector<detail::LaneBuffer> lanes;
    detail::LaneBuffer count;
    if (options.length > 0) {
      // Zeroed, so that no slot ever holds what the allocator left (a carry reads them all).
      lanes.reserve(3 * std::size_t(options.length));
      for (std::size_t k = 0; k < 3 * std::size_t(options.length); ++k) {
        lanes.emplace_back(g.capacity);
        std::memset(lanes.back().data(), 0, g.capacity * sizeof(float));
      }
      count = detail::LaneBuffer(g.capacity);
      std::memset(count.data(), 0, g.capacity * sizeof(std::uint32_t));
    }
    g.trailLanes = std::move(lanes);
    g.trailCount = std::move(count);
    g.trailHead = 0;
    g.trail = options;
    g.startTrails(0, g.size);
    g.hostChanged();  // a device's group takes the new ring up with its particles
  }
  g.trail = options;
  return *this;
}

const TrailOptions& Group::trail() const {
  return impl_->trail;
}

std::size_t Group::trail(std::size_t i, std::span<Vec3> out) const {
  auto& g = *impl_;
  g.syncHost({Attribute::Position});  // a device's trails come with its positions
  if (i >= g.size)
    throw InvalidArgument("index",
                          std::to_string(i) + " is past the live count " + std::to_string(g.size));
  if (g.trail.length == 0) return 0;
  const std::uint32_t n = g.trailCount.u()[i], len = g.trail.length;
  for (std::uint32_t k = 0; k < n && k < out.size(); ++k) {
    const std::size_t slot = 3 * std::size_t((g.trailHead + len - k) % len);
    out[k] = Vec3(g.trailLanes[slot].f()[i], g.trailLanes[slot + 1].f()[i],
                  g.trailLanes[slot + 2].f()[i]);
  }
  return n;
}

bool Group::add(const Particle& p) {
  auto& g = *impl_;
  g.syncHost();
  g.ensureStorage();
  ++g.stats.emitted;
  if (g.size >= g.capacity) {
    ++g.stats.droppedAtCapacity;
    return false;
  }
  Particle q = p;
  q.id = g.nextId++;
  const std::size_t i = g.size++;
  g.write(i, q);
  // Its colour and size as added are its birth values (ColorOverLife / SizeOverLife).
  const detail::Lanes l = g.lanePointers();
  for (int c = 0; c < 4; ++c)
    if (l.birthColor[c]) l.birthColor[c][i] = q.color[c];
  if (l.birthSize) l.birthSize[i] = q.size;
  g.startTrails(i, i + 1);
  g.hostChanged();
  return true;
}

Particle Group::particle(std::size_t i) const {
  impl_->syncHost();
  if (i >= impl_->size)
    throw InvalidArgument(
        "index", std::to_string(i) + " is past the live count " + std::to_string(impl_->size));
  return impl_->read(i);
}

namespace {
void checkFloatLane(const detail::GroupImpl& g, Attribute a, int component) {
  if (a == Attribute::Id || a == Attribute::Visible || a >= Attribute::Count)
    throw InvalidArgument("attribute", std::string(attributeName(a)) +
                                           " is not a float attribute (use ids() / visible())");
  if (component < 0 || component >= componentCount(a))
    throw InvalidArgument("component", "attribute " + std::string(attributeName(a)) + " has " +
                                           std::to_string(componentCount(a)) + " components");
  if (!g.stored.has(a))
    throw Error("group '" + g.name + "' does not store attribute " + std::string(attributeName(a)) +
                " (call require() first)");
}
}  // namespace

void Group::fetch(AttributeSet attributes) const {
  impl_->syncHost(attributes);
}

std::span<const float> Group::lane(Attribute a, int component) const {
  impl_->syncHost({a});
  checkFloatLane(*impl_, a, component);
  return {impl_->lanes[std::size_t(a)][component].f(), impl_->size};
}

std::span<float> Group::lane(Attribute a, int component) {
  impl_->syncHost();
  checkFloatLane(*impl_, a, component);
  impl_->hostChanged();  // the caller may write through the span
  return {impl_->lanes[std::size_t(a)][component].f(), impl_->size};
}

std::span<const std::uint32_t> Group::ids() const {
  impl_->syncHost({Attribute::Id});
  return {impl_->lanes[std::size_t(Attribute::Id)][0].u(), impl_->size};
}

std::span<const std::uint32_t> Group::visible() const {
  impl_->syncHost({Attribute::Visible});
  if (!impl_->stored.has(Attribute::Visible))
    throw Error("group '" + impl_->name + "' does not store attribute visible");
  return {impl_->lanes[std::size_t(Attribute::Visible)][0].u(), impl_->size};
}

const GroupStats& Group::stats() const {
  impl_->syncStats();
  return impl_->stats;
}

detail::PassScratchUse::PassScratchUse(GroupImpl& group) {
  thread_local PassScratch mine;
  // A large group keeps its own (freed with it): a thread's stays the size of a small one.
  constexpr std::size_t kThreadsMost = 32768;
  threads_ = !mine.busy && group.capacity <= kThreadsMost;
  if (threads_) {
    mine.busy = true;
    scratch_ = &mine;
  } else {
    if (!group.ownScratch) group.ownScratch = std::make_unique<PassScratch>();
    scratch_ = group.ownScratch.get();
  }
}

detail::PassScratchUse::~PassScratchUse() {
  if (threads_) scratch_->busy = false;
}

void detail::GroupImpl::recordDeaths(PassScratch& pass, std::size_t B, std::size_t blocks,
                                     double t1, ThreadPool& pool) {
  auto& deathStart = pass.deathStart;
  const auto& deadCount = pass.deadCount;
  const auto& deadIndex = pass.deadIndex;
  const auto& deadCode = pass.deadCode;
  // Where each block's events start: the first in particle order are kept, up to the room.
  if (deathStart.size() < blocks + 1) deathStart.resize(blocks + 1);  // grows once
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    deathStart[b] = total;
    total += deadCount[b];
  }
  deathStart[blocks] = total;
  const std::size_t kept = std::min(total, deathRoom());
  stats.deathEventsDropped += leftOut(total, deathsPerStep);
  deathEvents.resize(kept);  // within the room reserved by Group::recordDeaths: no allocation
  if (kept == 0) return;
  const Lanes L = lanePointers();
  constexpr std::size_t kBlocksPerTask = 64;
  pool.parallelFor((blocks + kBlocksPerTask - 1) / kBlocksPerTask, [&](std::size_t task) {
    const std::size_t end = std::min(blocks, (task + 1) * kBlocksPerTask);
    for (std::size_t b = task * kBlocksPerTask; b < end && deathStart[b] < kept; ++b) {
      const std::size_t n = std::min<std::size_t>(deadCount[b], kept - deathStart[b]);
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t i = deadIndex[b * B + j];
        const std::uint8_t code = deadCode[b * B + j];
        DeathEvent& e = deathEvents[deathStart[b] + j];
        for (int c = 0; c < 3; ++c) {
          e.position[c] = L.p[c][i];
          e.velocity[c] = L.v[0] ? L.v[c][i] : 0.0f;
        }
        e.id = L.id ? L.id[i] : 0u;
        e.action = code == kNonFiniteCode ? DeathEvent::kNonFinite : std::uint32_t(code) - 1u;
        e.time = t1;
      }
    }
  });
}

void detail::GroupImpl::beginCollisions(std::size_t blocks) {
  if (blockCollisions.size() < blocks) blockCollisions.resize(blocks);
  for (std::size_t b = 0; b < blocks; ++b) blockCollisions[b].clear();
}

void detail::GroupImpl::addCollision(std::size_t block, std::uint64_t key,
                                     const CollisionEvent& e) {
  blockCollisions[block].push_back({key, e});
}

void detail::GroupImpl::endCollisions(std::size_t blocks) {
  collisionEvents.clear();
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    auto& found = blockCollisions[b];
    // In particle order whichever way the pass ran the block (the fused pass takes a block's
    // old particles through the list before its newborns; the unfused one action by action).
    std::sort(found.begin(), found.end(),
              [](const KeyedCollision& x, const KeyedCollision& y) { return x.key < y.key; });
    const std::size_t take = std::min(found.size(), collisionRoom() - collisionEvents.size());
    for (std::size_t k = 0; k < take; ++k) collisionEvents.push_back(found[k].event);
    total += found.size();
  }
  stats.collisionEventsDropped += leftOut(total, collisionsPerStep);
}

namespace {
// Events carry the particles' ids (both backends record them).
void startRecording(Group& g, std::size_t perStep) {
  // (require syncs a device's group both ways even when nothing changes)
  if (perStep > 0 && !g.attributes().has(Attribute::Id)) g.require({Attribute::Id});
}
}  // namespace

Group& Group::recordCollisions(std::size_t perStep) {
  auto& g = *impl_;
  startRecording(*this, perStep);
  g.collisionEvents.clear();
  g.collisionEvents.reserve(std::min(perStep, g.capacity));
  g.collisionsPerStep = perStep;
  return *this;
}

std::span<const CollisionEvent> Group::collisions() const {
  // (A collision emitter fed by the group has the step's others.)
  const auto& all = impl_->collisionEvents;
  return std::span(all).first(std::min(all.size(), impl_->collisionsPerStep));
}

void detail::GroupImpl::recordBirths(double t1) {
  birthEvents.clear();
  if (birthEvents.capacity() < capacity) birthEvents.reserve(capacity);  // once
  const Lanes L = lanePointers();
  for (std::size_t r = 0; r < bornCount; ++r) {
    const std::size_t i = bornFirst + r;
    DeathEvent e;
    e.position = Vec3(L.p[0][i], L.p[1][i], L.p[2][i]);
    if (L.v[0]) e.velocity = Vec3(L.v[0][i], L.v[1][i], L.v[2][i]);
    e.id = L.id[i];
    e.action = 0;
    e.time = t1 - double(bornRemaining[r]);
    birthEvents.push_back(e);
  }
}

void detail::GroupImpl::feedDeaths() {
  if (deathsFeed) return;
  deathEvents.reserve(capacity);  // no step has more deaths than the group holds particles
  deathsFeed = true;
}

Group& Group::recordDeaths(std::size_t perStep) {
  auto& g = *impl_;
  startRecording(*this, perStep);
  g.deathEvents.clear();
  g.deathEvents.reserve(std::min(std::max(perStep, g.deathRoom()), g.capacity));
  g.deathsPerStep = perStep;
  return *this;
}

DeathEmitter& Group::addDeathEmitter(DeathEmitter emitter) {
  auto& g = *impl_;
  const std::string where = "deathEmitters[" + std::to_string(g.deathEmitters.size()) + "]";
  emitter.validate(where);
  g.deathEmitters.push_back(std::move(emitter));
  if (g.contextDeathEmitters) ++*g.contextDeathEmitters;
  return g.deathEmitters.back();
}

std::span<DeathEmitter> Group::deathEmitters() {
  return impl_->deathEmitters;
}

void Group::removeDeathEmitter(std::size_t i) {
  auto& g = *impl_;
  checkIndex(i, g.deathEmitters.size(), "death emitters");
  g.deathEmitters.erase(g.deathEmitters.begin() + std::ptrdiff_t(i));
  if (g.contextDeathEmitters) --*g.contextDeathEmitters;
}

std::span<const DeathEvent> Group::deaths() const {
  // (A death emitter fed by the group has the step's others.)
  const auto& all = impl_->deathEvents;
  return std::span(all).first(std::min(all.size(), impl_->deathsPerStep));
}

Bounds Group::bounds() const {
  return detail::liveBox(*impl_);
}

Bounds detail::liveBox(GroupImpl& g) {
  // The next steps' passes keep it. (Only written once: a line written every frame would be
  // written back.)
  if (!g.boundsWanted) g.boundsWanted = true;
  if (g.size == 0) return {};
  if (g.boundsValid) return g.stepBounds;
  g.syncHost({Attribute::Position});
  Bounds b;
  const detail::Lanes l = g.lanePointers();
  for (int c = 0; c < 3; ++c) {
    const float* x = l.p[c];
    float lo = x[0], hi = x[0];
    for (std::size_t i = 1; i < g.size; ++i) {
      lo = std::min(lo, x[i]);
      hi = std::max(hi, x[i]);
    }
    b.min[c] = lo;
    b.max[c] = hi;
  }
  b.empty = false;
  return b;
}

void Group::clear() {
  impl_->syncHost();
  impl_->size = 0;
  impl_->hostChanged();
}

}  // namespace flurry
