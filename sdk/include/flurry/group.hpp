// A particle group: a fixed-capacity structure-of-arrays store of particles, the emitters
// that feed it and the action list applied to it every step.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "flurry/actions.hpp"
#include "flurry/attribute.hpp"
#include "flurry/emitter.hpp"
#include "flurry/strands.hpp"
#include "flurry/transform.hpp"

namespace flurry {

namespace detail {
struct GroupImpl;
struct GroupAccess;  // the library's way in (sdk/src/group_impl.hpp)
}  // namespace detail

/// One particle gathered from the arrays (for tests, tools and small groups; hot code reads
/// the arrays through Group::lane()).
struct Particle {
  Vec3 position{0.0f};
  Vec3 velocity{0.0f};
  Vec4 color{1.0f};
  float size = 0.05f;
  float mass = 1.0f;
  float age = 0.0f;
  float lifetime = 1e30f;
  Vec3 prevPosition{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  Vec3 rotVelocity{0.0f};
  float charge = 0.0f;
  bool visible = true;
  float userData = 0.0f;
  Vec3 positionB{0.0f};
  Vec3 velocityB{0.0f};
  std::uint32_t id = 0;  ///< assigned by the group on add()
};

/// Hair (static) mode: every particle's whole life is computed when it is born, through the
/// group's action list, and kept as a strand; the group itself holds no live particles.
struct HairOptions {
  bool enabled = false;
  std::uint32_t every = 1;          ///< a vertex every N steps of the particle's life
  std::uint32_t maxVertices = 256;  ///< a strand ends here if the particle lives on
};

/// Trails (Group::setTrail): each live particle keeps where it was at the end of its last
/// `length` steps (a ring of positions, filled after every step), for ribbons that follow
/// fast particles (hair mode draws a dead particle's whole life instead). The
/// look fields say how flurry::render and trailStrands() draw it: a ribbon `width` (a
/// radius) at the particle, narrowing to `taper` times that and fading to `fade` times the
/// particle's alpha at the trail's oldest point.
struct TrailOptions {
  std::uint32_t length = 0;  ///< positions kept per particle (0: no trail; at most kMaxLength)
  float width = 0.0f;        ///< the ribbon's radius at the particle; 0: the particle's size
  float taper = 1.0f;        ///< the radius at the oldest point, as a fraction of the first
  float fade = 0.0f;         ///< the alpha at the oldest point, as a fraction of the first
  static constexpr std::uint32_t kMaxLength = 256;
  /// Throws InvalidArgument naming the field ("trail.length", ...) of a length past
  /// kMaxLength or a width, taper or fade that is negative or not finite.
  void validate(const std::string& where = "trail") const;
};

/// What a group gives up while its context is short of particles (Context::setParticleBudget):
/// the room left under the budget is shared each step among the groups that emit, in
/// proportion to what each asked for the step before.
enum class BudgetPolicy {
  /// Births past the group's share are not made (GroupStats::droppedAtBudget): the first
  /// planned are kept, emitter by emitter. The default.
  DropNewest,
  /// Every birth is made, and the group's first-born particles die to make room
  /// (GroupStats::killedByBudget; no death event): an effect that must look alive now.
  DropOldest,
  /// Every emitter keeps the same fraction of its births, so that the whole effect thins
  /// evenly instead of its last emitters going quiet (droppedAtBudget).
  ScaleEmission,
};

/// Where the particles went: emitted == size() + killedByAge + absorbed + droppedAtCapacity +
/// droppedAtBudget + killedByBudget + killedNonFinite.
struct GroupStats {
  /// Created by emitters or add(), dropped ones included. A step counts at most 2^40 births
  /// of a group's emitters together: a rate of 1e25/s or a spacing of 1e-30 asks for more
  /// than any group holds (at most 2^32), and what is asked beyond 2^40 is neither created
  /// nor counted.
  std::uint64_t emitted = 0;
  std::uint64_t killedByAge = 0;  ///< by KillOld
  std::uint64_t absorbed = 0;     ///< by Sink (and other absorbers)
  /// Counted in `emitted` but not created: the group was full (within the 2^40 a step).
  std::uint64_t droppedAtCapacity = 0;
  /// Counted in `emitted` but not created: past the group's share of the context's budget.
  std::uint64_t droppedAtBudget = 0;
  /// Killed to keep the context within its budget (BudgetPolicy::DropOldest).
  std::uint64_t killedByBudget = 0;
  /// Killed because a step left their position or velocity NaN or infinite (an extreme
  /// input, a user callback): counted, never propagated.
  std::uint64_t killedNonFinite = 0;
  std::vector<std::uint64_t> killedByAction;  ///< per action-list entry
  /// Particles by the generation of their emitter: 0 from the group's own emitters, 1 from
  /// emitters a prime emitter spawned, 2 from their children, ...
  std::vector<std::uint64_t> emittedByGeneration;
  std::uint64_t emittersSpawned = 0;  ///< by prime emitters and death spawns, all levels
  /// Not spawned: the prime emitter already had PrimeEmitter::maxEmitters live emitters.
  std::uint64_t emittersDropped = 0;
  /// Cumulative wall-clock seconds the CPU backend spent in each part of its steps: the
  /// action pass, the newborns (births planned and written), the compaction (holes closed
  /// from the tail; a pass that one thread walks closes most of them as it goes, in `act`).
  /// For profiling; other backends leave them 0.
  struct StepSeconds {
    double emit = 0.0;
    double act = 0.0;
    double compact = 0.0;
  };
  StepSeconds stepSeconds;
  /// Steps the CPU backend skipped because the group was idle: no live particles and no
  /// emitter that would fire (such a step changes nothing and costs no pass).
  std::uint64_t idleSteps = 0;
  /// Blocks × actions the CPU fused pass skipped because no particle of the block could
  /// reach the action this step (ContextOptions::cull; blocks of about 1024 particles).
  std::uint64_t blockActionsCulled = 0;
  /// Bytes of particle attributes a device backend (OpenCL) copied back to the host because
  /// a reader asked for them (lane(), particle(), bounds(), fetch(), an exporter): each stored
  /// attribute crosses at most once per step, and only if read. The CPU backend leaves it 0.
  std::uint64_t bytesReadBack = 0;
  /// Deaths not recorded because a step had more than Group::recordDeaths' capacity.
  std::uint64_t deathEventsDropped = 0;
  /// Collisions not recorded because a step had more than Group::recordCollisions' capacity.
  std::uint64_t collisionEventsDropped = 0;
};

/// A particle's death, recorded for the game (Group::recordDeaths): where the particle was
/// and how fast it went at the end of the step that killed it.
struct DeathEvent {
  /// `action` of a particle killed because the step left it NaN or infinite.
  static constexpr std::uint32_t kNonFinite = 0xFFFFFFFFu;
  Vec3 position{0.0f};
  Vec3 velocity{0.0f};  ///< zero when the group stores no velocity
  std::uint32_t id = 0;
  /// The index in the action list of what killed it (a KillOld, a Sink, ...), or kNonFinite.
  std::uint32_t action = 0;
  double time = 0.0;  ///< the end of the step it died in
};

/// A particle deflected by a Bounce, recorded for the game (Group::recordCollisions): where
/// and when it met the surface, how fast it came, and the surface's normal there.
struct CollisionEvent {
  Vec3 position{0.0f};  ///< the point of impact, on the surface
  Vec3 velocity{0.0f};  ///< arriving there (before the bounce)
  Vec3 normal{0.0f};    ///< the surface's unit normal there, on the side the particle came from
  std::uint32_t id = 0;
  std::uint32_t action = 0;    ///< the index of the Bounce in the action list
  std::uint32_t reserved = 0;  ///< 0: the layout has no padding (the C API hands it out)
  double time = 0.0;           ///< the moment of impact
};

struct Bounds {
  Vec3 min{0.0f}, max{0.0f};
  bool empty = true;
};

class Group {
 public:
  ~Group();
  Group(const Group&) = delete;
  Group& operator=(const Group&) = delete;

  const std::string& name() const;
  /// Live particles; they occupy indices [0, size()).
  std::size_t size() const;
  std::size_t capacity() const;

  /// The attributes this group stores: what its actions use, plus what readers required.
  AttributeSet attributes() const;
  /// Asks the group to store attributes a reader (renderer, exporter, user code) will read.
  void require(AttributeSet attributes);

  Group& setActions(ActionList actions);
  /// The action list as given (in the group's frame once it has a transform).
  const ActionList& actions() const;

  /// Places the group in the world, at any time between steps (an effect instance's groups
  /// together: EffectInstance::setTransform). From the first call on, the emitters and the
  /// action list are in the group's own frame: what they say is carried by the transform
  /// (see Transform for what follows it) into the world, where the particles are simulated.
  /// In Space::Local the live particles are carried from the old transform to the new one
  /// (on a device backend that reads them back and uploads them once). The identity runs
  /// bitwise as a group never placed. Throws InvalidArgument naming the field
  /// ("transform.scale", ...) for a transform that is not finite, a scale <= 0, or a rotation
  /// that is not a unit quaternion, and "transform.rotation" for a box domain in the effect
  /// under a rotation other than quarter turns; the group is then left as it was.
  Group& setTransform(const Transform& transform);
  const Transform& transform() const;
  /// World (the default) or Local: see Space. Set it before the particles move.
  Group& setSpace(Space space);
  Space space() const;

  /// Runs the group's clock at `scale` times the context's (an effect instance's slowed or
  /// hastened: EffectInstance::setTimeScale), from the next step on: each step then takes
  /// scale·timeStep() seconds of its own clock (Context::time(group)), which its emitters,
  /// Explosion's time and Restore's start read. 0 pauses it: nothing moves, ages or is born
  /// until the scale is raised again. Throws InvalidArgument "scale" unless finite and
  /// 0 <= scale <= 1000.
  Group& setTimeScale(double scale);
  double timeScale() const;
  /// A level of detail for what the game does not see: the group steps only once every
  /// `interval` context steps, each time over the time it skipped (one step of
  /// interval·timeStep(), newborns placed inside it as ever), so it costs 1/interval and
  /// stays on time. Staggered by the group's index, so that a crowd of them spreads over the
  /// frames. Between its steps nothing of it moves and it records no events. Set back to 1,
  /// its next step catches up what it skipped. Throws InvalidArgument "interval" unless
  /// 1 <= interval <= 256.
  Group& setUpdateInterval(std::uint32_t interval);
  std::uint32_t updateInterval() const;
  /// Draws the group's random numbers from `seed` and `stream` (< 65536) instead of the
  /// context's seed and the group's index, from the next step on: groups given the same two
  /// draw alike whichever context and order made them (a replay, a seeded instance:
  /// EffectInstance::setSeed). Throws InvalidArgument "stream" past 65535.
  Group& setSeed(std::uint64_t seed, std::uint32_t stream = 0);

  /// Adds an emitter (validated: throws InvalidArgument naming the bad field).
  Emitter& addEmitter(Emitter emitter);
  /// The emitters as given (in the group's frame once it has a transform); edits through the
  /// span take effect at the next step.
  std::span<Emitter> emitters();
  /// Removes emitter i (0 <= i < emitters().size(); throws InvalidArgument "index"): it emits
  /// no more, and the emitters after it move down by one.
  void removeEmitter(std::size_t i);
  /// Adds an emitter of emitters (validated).
  PrimeEmitter& addPrimeEmitter(PrimeEmitter prime);
  /// Emitters spawned by prime emitters and still alive.
  std::size_t liveEmitterCount() const;
  /// Adds an emitter fed by a group's deaths (validated; the source is looked up when the
  /// context steps). Both backends run it (a device context refuses one for a hair group).
  DeathEmitter& addDeathEmitter(DeathEmitter emitter);
  /// The death emitters; edits through the span take effect at the next step.
  std::span<DeathEmitter> deathEmitters();
  /// Removes death emitter i (throws InvalidArgument "index" past them).
  void removeDeathEmitter(std::size_t i);

  /// Hair mode (see HairOptions). Strands accumulate until clearStrands().
  Group& setHair(HairOptions options);
  const HairOptions& hair() const;
  const Strands& strands() const;
  void clearStrands();

  /// Keeps each particle's last `options.length` positions (TrailOptions), from the next
  /// step on: particles alive now start their trail where they are. Throws InvalidArgument
  /// naming the field ("trail.length" past kMaxLength, a width, taper or fade that is
  /// negative or not finite). Both backends keep trails alike (a device's come to the host
  /// with the positions; hair mode refuses one there). Costs one memory pass over the
  /// positions a step, and the trail's lanes in compaction.
  Group& setTrail(const TrailOptions& options);
  const TrailOptions& trail() const;
  /// Particle i's trail, newest first: its position at the end of the last step, then of
  /// each step before, back to where it was born (or where it was when the trail began).
  /// Writes up to out.size() points and returns how many it has (at most length; 0 without a
  /// trail). Throws InvalidArgument "index" past size().
  std::size_t trail(std::size_t i, std::span<Vec3> out) const;

  /// What this group gives up while the context is over its particle budget (default
  /// DropNewest).
  Group& setBudgetPolicy(BudgetPolicy policy);
  BudgetPolicy budgetPolicy() const;

  /// Adds one particle now; returns false (and counts it dropped) when the group is full.
  bool add(const Particle& p);
  /// Gathers particle i (0 <= i < size()); attributes not stored read as Particle's defaults.
  Particle particle(std::size_t i) const;

  /// On a device backend (OpenCL), copies the named attributes of the live particles back to
  /// the host now, in one transfer, if the device changed them since they were last read;
  /// nothing else crosses. A reader that names what it needs (a renderer: positions and
  /// colours) calls it once a frame; lane(a), ids(), visible() and bounds() read back only
  /// their own attribute, particle() and a writable lane() everything. No-op on the CPU.
  void fetch(AttributeSet attributes) const;

  /// The array of one component of a stored float attribute, size() long.
  /// Throws Error if the attribute is not stored (Id and Visible: use ids() / visible()).
  std::span<const float> lane(Attribute a, int component = 0) const;
  std::span<float> lane(Attribute a, int component = 0);
  std::span<const std::uint32_t> ids() const;
  std::span<const std::uint32_t> visible() const;

  const GroupStats& stats() const;

  /// Records every step's deaths (by age, by an absorber, for a NaN) as DeathEvents for the
  /// game to read after the step (deaths()), at most `perStep` a step: the first in particle
  /// order, the same on any thread count; the rest are counted in
  /// GroupStats::deathEventsDropped (a DeathEmitter that names the group gets all of them,
  /// and deaths() still the first `perStep`). 0 stops it. The room is taken here, not per step, and
  /// while off it costs nothing. Stores ids (the events carry them). Both backends record
  /// the same events; on a device the host waits for each step it records and reads its
  /// events back (what a step costs there while recording).
  Group& recordDeaths(std::size_t perStep);
  /// The deaths of the last step (empty when not recording), valid until the next step.
  std::span<const DeathEvent> deaths() const;
  /// Records every step's collisions (each time a Bounce deflects a particle) as
  /// CollisionEvents for the game to read after the step (collisions()), at most `perStep`
  /// a step: the first in particle order (a particle's own by sub-step, then by action), the
  /// same on any thread count; the rest are counted in GroupStats::collisionEventsDropped
  /// (a collision emitter that names the group gets all of them, and collisions() still the
  /// first `perStep`). A
  /// particle left NaN or infinite is not reported (the step kills it). 0 stops it; while off it
  /// costs nothing. A particle resting on a floor is deflected, and reported, every step it rests
  /// (filter by the speed). Stores ids. Both backends record them; on a device the host
  /// waits for each step it records and reads its events back.
  Group& recordCollisions(std::size_t perStep);
  /// The collisions of the last step (empty when not recording), valid until the next step.
  std::span<const CollisionEvent> collisions() const;
  /// Axis-aligned bounds of the live particles' positions, in the world (for an engine's
  /// culling). The first call takes them in a pass of its own; from then on the CPU backend
  /// keeps them every step inside its action pass, while each block of particles is in cache,
  /// and a call costs nothing until the host changes the particles (add(), a writable lane(),
  /// a move in Space::Local, ...). On a device backend (OpenCL) each call reads the positions
  /// back (once a step) and takes them on the host.
  Bounds bounds() const;
  /// Removes every particle (stats are kept).
  void clear();

 private:
  friend class Context;
  friend struct detail::GroupAccess;
  explicit Group(std::unique_ptr<detail::GroupImpl> impl);
  std::unique_ptr<detail::GroupImpl> impl_;
};

}  // namespace flurry
