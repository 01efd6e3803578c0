// Effect files: a whole scene (groups, emitters, prime emitters, action lists, render
// settings) described in JSON, loaded, validated and built into a Context.
// The format is documented in docs/effect-format.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "flurry/actions.hpp"
#include "flurry/context.hpp"
#include "flurry/emitter.hpp"
#include "flurry/error.hpp"
#include "flurry/field.hpp"
#include "flurry/group.hpp"

namespace flurry {

/// A malformed or invalid effect file. what() is "FILE: JSON.PATH: why", e.g.
/// `fountain.json: groups[0].emitters[2].rate: must be finite and >= 0`;
/// parameter() is the JSON path alone (empty for a syntax error, whose why() gives the line
/// and column).
class EffectError : public InvalidArgument {
 public:
  EffectError(std::string file, std::string path, std::string why);
  const char* what() const noexcept override { return message_.c_str(); }
  const std::string& file() const noexcept { return file_; }
  const std::string& path() const noexcept { return parameter(); }
  const std::string& why() const noexcept { return why_; }

 private:
  std::string file_, why_, message_;
};

/// Something an effect asks for that cannot happen as written, e.g. a KillOld in a group
/// without a Move (its particles never age). Not an error: the effect loads and runs as
/// written. The library reports warnings (Effect::warnings), it never prints them.
struct EffectWarning {
  std::string path;  ///< the JSON path, e.g. "groups[0].actions[3]"
  std::string why;
  /// "path: why".
  std::string message() const { return path.empty() ? why : path + ": " + why; }
};

/// One group of an effect, as loaded (validated, not yet built).
struct EffectGroup {
  std::string name;
  std::size_t capacity = 0;
  std::vector<Emitter> emitters;
  std::vector<PrimeEmitter> primeEmitters;
  /// Emitters fed by deaths; their `source` names a group of the effect (an instance's
  /// build names that group's instance).
  std::vector<DeathEmitter> deathEmitters;
  /// The action list, with the 2-D constraint already inserted for a `mode2d` group.
  ActionList actions;
  HairOptions hair;
  TrailOptions trail;                              ///< kept when trail.length > 0 (Group::setTrail)
  BudgetPolicy budget = BudgetPolicy::DropNewest;  ///< past its share of a context's budget
  /// Attributes stored although no action reads them (a renderer or exporter will).
  AttributeSet require;
};

class EffectInstance;

/// A loaded effect file.
struct Effect {
  std::string name;
  std::string description;  ///< one line, shown by `flurry list`
  double dt = 1.0 / 30.0;   ///< seconds per step
  std::uint64_t seed = 1;
  int frames = 300;  ///< steps `flurry run` takes by default
  /// Where its particles live when an instance moves (`"space": "world"` or `"local"`).
  Space space = Space::World;
  std::vector<EffectGroup> groups;
  /// The `render` object as JSON text ("{}" when absent); the core does not read it, a
  /// renderer parses it (docs/rendering.md).
  std::string render = "{}";
  /// The file it came from (empty for an embedded or in-memory effect).
  std::filesystem::path file;
  /// What the loader found suspicious (see EffectWarning and docs/effect-format.md), in file
  /// order. `flurry validate` and `flurry run` print them.
  std::vector<EffectWarning> warnings;

  /// ContextOptions with this effect's seed and dt (the rest default).
  ContextOptions contextOptions() const;
  /// Creates the groups in `ctx` with their emitters, actions, hair options and required
  /// attributes. maxCapacity > 0 caps every group's capacity. A non-empty `instance` names
  /// the groups "GROUP@INSTANCE", so that one effect can be built many times in a Context
  /// (each instance draws its own random numbers; Context::destroyGroup removes one).
  /// The effect's times (its emitters' start, stop, bursts and path keys, an Explosion's
  /// time, a Restore's start) count from when it is built: built at ctx.time() = T, a burst
  /// at 0 fires at T and a rate starts at T, as a game's effect started mid-level expects.
  /// Returns the groups created. Errors raised by the core are rethrown as EffectError
  /// naming the group.
  std::vector<Group*> build(Context& ctx, std::size_t maxCapacity = 0,
                            std::string_view instance = {}) const;
  /// build() as an instance a game places, moves and prewarms: see EffectInstance.
  EffectInstance instantiate(Context& ctx, std::string_view instance,
                             std::size_t maxCapacity = 0) const;
  /// Scales how many particles the effect makes, as a quality setting does (Niagara's spawn
  /// count scale): every emitter's rate, burst counts and births by distance, the emitters
  /// a prime emitter spawns (theirs, and their death bursts, at every level), and every
  /// group's capacity, by `factor` (finite, > 0). Counts are rounded; a burst keeps at
  /// least one particle. How many emitters a prime emitter spawns is left as it is.
  /// InvalidArgument("factor") otherwise.
  void scaleSpawning(double factor);
};

/// One effect built into a Context (Effect::instantiate): its groups, placed together. A
/// handle: copies refer to the same groups, which belong to the context.
class EffectInstance {
 public:
  EffectInstance() = default;
  const std::vector<Group*>& groups() const { return groups_; }
  /// Places every group of the instance, at any time between steps (Group::setTransform: the
  /// emitters and the action lists' geometry follow; in Space::Local the live particles too).
  /// All or nothing: throws InvalidArgument naming the field and leaves the instance where it
  /// was.
  EffectInstance& setTransform(const Transform& transform);
  const Transform& transform() const { return transform_; }
  /// Starts the instance as if it had run `seconds` already (Context::prewarm of its groups):
  /// call it before the instance's first step. Returns the steps taken.
  std::uint64_t prewarm(double seconds);
  /// The box of every live particle of the instance, in the world: the union of its groups'
  /// Group::bounds() (kept by the CPU pass every step once asked). Empty when none lives.
  Bounds bounds() const;
  /// Runs the instance at `scale` times the game's time (slow motion, a paused effect at 0):
  /// Group::setTimeScale of every group. Throws InvalidArgument "scale".
  EffectInstance& setTimeScale(double scale);
  double timeScale() const;
  /// Steps the instance once every `interval` context steps, catching up each time (see
  /// Group::setUpdateInterval): a game sets it when the instance leaves the view or goes far
  /// away, and back to 1 when it returns. Its groups step together. InvalidArgument
  /// "interval" unless 1 <= interval <= 256.
  EffectInstance& setUpdateInterval(std::uint32_t interval);
  /// Gives the instance its own random numbers: group k of the effect draws from (seed, k)
  /// (Group::setSeed), so two instances with one seed look alike wherever they are made
  /// (a replay), and a seed per instance tells them apart. From the next step on.
  EffectInstance& setSeed(std::uint64_t seed);
  /// Stops emitting now (every emitter's and prime emitter's stop becomes the time on its
  /// group's clock, Context::time(group)): the live particles, and the showers prime emitters
  /// launched, live out their lives. A one-shot effect a game lets finish.
  void stop();
  /// Stops emitting and removes every particle and shower at once (the groups stay; their
  /// stats are kept).
  void kill();
  /// Starts it over now: kill(), then its emitters, prime emitters and action lists as the
  /// effect built them (before any stop() or edit), their times counting from now on each
  /// group's clock: bursts at 0 fire again, a rate starts with no backlog, it emits as many
  /// as an instance made now would. The transform, time scale and seed stay, and the stats
  /// (but the per-action kill counts, which start again). A pooled one-shot effect a game
  /// fires again.
  void restart();
  /// True when nothing of it lives and nothing can be born again: a game may destroy() it.
  bool done() const;
  /// Destroys its groups (Context::destroyGroup); the handle is empty after.
  void destroy();

 private:
  friend struct Effect;
  Context* context_ = nullptr;
  std::vector<Group*> groups_;
  /// The first groups' internals, held here: bounds(), asked of every instance each frame,
  /// then reads one cache line of each group, not the vector and the Group on the way.
  detail::GroupImpl* impls_[2] = {};
  Transform transform_;
};

/// Reads a sampled vector field kept outside the effect file (`{"vdb": "file.vdb", "grid":
/// "vel"}`). The path is already resolved against the effect file's folder. Throw an Error on
/// failure; the loader reports it with the field's JSON path.
using FieldResolver =
    std::function<VectorField(const std::filesystem::path& file, const std::string& grid)>;

struct EffectLoadOptions {
  /// For `{"vdb": ...}` fields; without one such a field is an error (the core does not
  /// link OpenVDB: `flurry` passes flurry::vdb::readVectorField when built with it).
  FieldResolver fieldResolver;
  /// Relative paths in the effect resolve against this folder (loadEffect: the file's).
  std::filesystem::path baseDir;
  /// Checks the `render` object (its JSON text; relative paths resolve against baseDir).
  /// Throw an InvalidArgument whose parameter() is the JSON path ("render.camera.pitch"):
  /// the loader reports it as an EffectError naming the file. The core does not read
  /// `render`; without a checker it is kept unchecked. `flurry` passes one that calls
  /// flurry::parseRenderSettings when it is built with the renderer.
  std::function<void(std::string_view render, const std::filesystem::path& baseDir)> renderChecker;
  /// loadEffect refuses a file larger than this (bytes), reading no further: an effect file
  /// is a hand-written text, and a special file (/dev/zero) must not be read forever.
  std::size_t maxFileBytes = std::size_t(64) << 20;
};

/// Parses and validates an effect from JSON text. `fileName` names it in errors.
/// Throws EffectError; never anything else for bad input (std::bad_alloc aside).
Effect parseEffect(std::string_view json, const std::string& fileName = "<effect>",
                   const EffectLoadOptions& options = {});

/// Reads, parses and validates an effect file. Throws EffectError (IoError-like failures, a
/// folder, a file over EffectLoadOptions::maxFileBytes, are reported as EffectError with an
/// empty JSON path).
Effect loadEffect(const std::filesystem::path& file, EffectLoadOptions options = {});

/// Writes `effect` as effect-file JSON that parseEffect reads back to the same effect: every
/// group, emitter, action (a `mode2d` group's Constrain2D as the action it became), sampled
/// field (inline, even one read from a VDB file) and the render object; fields at their
/// defaults are left out. Throws InvalidArgument naming the JSON path of what a file cannot
/// hold (a Callback action).
std::string saveEffect(const Effect& effect);

/// The names effect files use for attributes ("color", "size", ...): attributeName(a).
/// Returns false if `name` is not one.
bool attributeFromName(std::string_view name, Attribute& out);

}  // namespace flurry
