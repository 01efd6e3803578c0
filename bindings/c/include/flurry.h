/* Flurry's C API (C99): the SDK for game engines and other languages' bindings.
 *
 * Handles are opaque. Every call returns a flurry_status; FLURRY_OK is 0. On failure
 * flurry_last_error() gives the message on the calling thread, worded as the C++ SDK's
 * exceptions (an effect error reads "FILE: JSON.PATH: why"). No C++ exception crosses this
 * interface.
 *
 * Ownership: what a *_create / *_load / *_parse call returns is the caller's, to be freed
 * with the matching *_destroy. A group belongs to its context (valid until the context is
 * destroyed). Pointers into a group's data (flurry_group_lane, flurry_group_ids, the stats
 * arrays) stay valid until the next step, build or change of that group. Strings returned as
 * `const char*` belong to the handle they came from. See docs/c-api.md.
 */
#ifndef FLURRY_H
#define FLURRY_H

#include <stddef.h>
#include <stdint.h>

/* The library is built with hidden visibility and a version script (flurry_c.map): only
 * what is marked here is exported. */
#if defined(__GNUC__)
#define FLURRY_C_EXPORT __attribute__((visibility("default")))
#else
#define FLURRY_C_EXPORT
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** The C interface's ABI number: raised when a struct, enum value or signature changes. */
#define FLURRY_C_ABI_VERSION 2 /* 2: the stats structs count budget drops */

typedef enum flurry_status {
  FLURRY_OK = 0,
  FLURRY_ERROR_NULL_ARGUMENT = 1,    /**< a handle or pointer argument is NULL */
  FLURRY_ERROR_INVALID_ARGUMENT = 2, /**< a value out of range, a bad field path */
  FLURRY_ERROR_EFFECT = 3,           /**< an effect file, JSON text or fields set in code */
  FLURRY_ERROR_IO = 4,               /**< a file could not be read or written */
  FLURRY_ERROR_NO_DEVICE = 5,        /**< no OpenCL platform, or no device matching */
  FLURRY_ERROR_OPENCL = 6,           /**< another OpenCL failure */
  FLURRY_ERROR_NOT_BUILT = 7,        /**< the feature is not in this build (OpenCL, VDB) */
  FLURRY_ERROR_NOT_FOUND = 8,        /**< no group of that name, an index out of range */
  FLURRY_ERROR_NOT_STORED = 9,       /**< the group does not store that attribute */
  FLURRY_ERROR_WRONG_TYPE = 10,      /**< e.g. a float array asked of a uint32 attribute */
  FLURRY_ERROR_OUT_OF_MEMORY = 11,
  FLURRY_ERROR_OTHER = 12 /**< any other failure (the message says what) */
} flurry_status;

typedef enum flurry_backend {
  FLURRY_BACKEND_CPU = 0,
  FLURRY_BACKEND_OPENCL = 1,
  FLURRY_BACKEND_AUTO = 2 /**< OpenCL if a device is usable, else the CPU */
} flurry_backend;

/** The particle attributes (flurry::Attribute). Id and Visible are uint32, the rest float. */
typedef enum flurry_attribute {
  FLURRY_ATTR_POSITION = 0, /**< 3 components */
  FLURRY_ATTR_VELOCITY,     /**< 3 */
  FLURRY_ATTR_COLOR,        /**< 4: r, g, b, a */
  FLURRY_ATTR_SIZE,         /**< radius */
  FLURRY_ATTR_MASS,
  FLURRY_ATTR_AGE,
  FLURRY_ATTR_LIFETIME,
  FLURRY_ATTR_ID, /**< uint32: flurry_group_ids */
  FLURRY_ATTR_PREV_POSITION,
  FLURRY_ATTR_UP,
  FLURRY_ATTR_ROT_VELOCITY,
  FLURRY_ATTR_CHARGE,
  FLURRY_ATTR_VISIBLE, /**< uint32: flurry_group_visible */
  FLURRY_ATTR_USER_DATA,
  FLURRY_ATTR_POSITION_B,
  FLURRY_ATTR_VELOCITY_B,
  FLURRY_ATTR_BIRTH_COLOR,
  FLURRY_ATTR_BIRTH_SIZE,
  FLURRY_ATTR_COUNT
} flurry_attribute;

typedef struct flurry_context flurry_context;
typedef struct flurry_group flurry_group;
typedef struct flurry_effect flurry_effect;
typedef struct flurry_action_list flurry_action_list;
typedef struct flurry_emitter flurry_emitter;
typedef struct flurry_instance flurry_instance;

/* ---- version and errors ------------------------------------------------------------------ */

/** "0.1.0": the SDK's version. */
FLURRY_C_EXPORT const char* flurry_version(void);
/** FLURRY_C_ABI_VERSION of the library loaded (compare with the header's). */
FLURRY_C_EXPORT int flurry_abi_version(void);
/** The message of the last failed call on this thread ("" if none). Valid until the next
 * failing call on this thread. */
FLURRY_C_EXPORT const char* flurry_last_error(void);
/** A status's name: "FLURRY_ERROR_EFFECT", ... */
FLURRY_C_EXPORT const char* flurry_status_name(flurry_status status);

/* ---- log (flurry::setLogCallback) --------------------------------------------------------- */

typedef enum flurry_log_level {
  FLURRY_LOG_DEBUG = 0,
  FLURRY_LOG_INFO = 1,
  FLURRY_LOG_WARNING = 2,
  FLURRY_LOG_ERROR = 3
} flurry_log_level;

/** Receives one message of the library (one line, valid during the call) and the user_data
 * given with it. It may be called from any thread, from several at once. */
typedef void (*flurry_log_fn)(flurry_log_level level, const char* message, void* user_data);
/** Sends the library's messages to `fn`; NULL (the default) drops them: the library never
 * prints. Process-wide (every context), thread-safe. */
FLURRY_C_EXPORT flurry_status flurry_set_log_callback(flurry_log_fn fn, void* user_data);

/* ---- context ----------------------------------------------------------------------------- */

typedef struct flurry_context_options {
  uint64_t seed;          /**< 1 */
  double dt;              /**< seconds per step: 1/30 */
  unsigned threads;       /**< 0: one per hardware thread */
  flurry_backend backend; /**< FLURRY_BACKEND_CPU */
  const char* device;     /**< OpenCL: a substring of the platform or device name; NULL: any */
} flurry_context_options;

/** Fills `options` with the defaults above. */
FLURRY_C_EXPORT flurry_status flurry_context_options_init(flurry_context_options* options);
/** Creates a context; `options` NULL takes the defaults. FLURRY_BACKEND_OPENCL fails with
 * FLURRY_ERROR_NOT_BUILT (no OpenCL in this build) or FLURRY_ERROR_NO_DEVICE. */
FLURRY_C_EXPORT flurry_status flurry_context_create(const flurry_context_options* options,
                                                    flurry_context** out);
/** One parallel loop's body: call task(task_context, i) with each index (it never unwinds
 * into the caller: what the work fails with is reported by the call that asked for it). */
typedef void (*flurry_task_fn)(void* task_context, size_t index);
/** A game's own job system, to run the context's parallel work instead of its own threads. */
typedef struct flurry_scheduler {
  void* user;           /**< handed back to parallel_for; must outlive the context */
  unsigned concurrency; /**< tasks it may run at once, the calling thread counted: 1 to 1024 */
  /** Runs task(task_context, i) exactly once for every i in [0, count), on any threads and in
   * any order, and returns when all have returned. Called from the thread that called the
   * context (flurry_context_step, ...), never from inside a task, and only for count >= 2.
   * The particles are bitwise the same whatever the order and the threads. */
  void (*parallel_for)(void* user, size_t count, flurry_task_fn task, void* task_context);
} flurry_scheduler;

/** flurry_context_create with the work run on `scheduler` (copied; its `user` must outlive
 * the context). `options->threads` must be 0 (FLURRY_ERROR_INVALID_ARGUMENT naming "threads"
 * otherwise); a NULL parallel_for or a concurrency outside 1..1024 names "scheduler". */
FLURRY_C_EXPORT flurry_status flurry_context_create_with_scheduler(
    const flurry_context_options* options, const flurry_scheduler* scheduler, flurry_context** out);
FLURRY_C_EXPORT flurry_status flurry_context_destroy(flurry_context* ctx);
/** Advances every group by one time step. */
FLURRY_C_EXPORT flurry_status flurry_context_step(flurry_context* ctx);
FLURRY_C_EXPORT flurry_status flurry_context_run(flurry_context* ctx, uint64_t steps);
FLURRY_C_EXPORT flurry_status flurry_context_time(const flurry_context* ctx, double* seconds);
FLURRY_C_EXPORT flurry_status flurry_context_step_index(const flurry_context* ctx, uint64_t* index);
FLURRY_C_EXPORT flurry_status flurry_context_time_step(const flurry_context* ctx, double* dt);
FLURRY_C_EXPORT flurry_status flurry_context_set_time_step(flurry_context* ctx, double dt);
/** The backend it runs (FLURRY_BACKEND_AUTO resolves to CPU or OpenCL). */
FLURRY_C_EXPORT flurry_status flurry_context_backend(const flurry_context* ctx,
                                                     flurry_backend* backend);
/** What a game's overlay shows, summed over the context's groups (flurry::ContextStats). */
typedef struct flurry_context_stats {
  size_t groups;
  size_t instances; /**< distinct INSTANCE names of groups named GROUP@INSTANCE */
  size_t particles; /**< alive now */
  size_t capacity;
  double last_step_seconds; /**< wall clock of the last step */
  /** The last step's parts over every group (CPU seconds: parallel groups add up). */
  double last_emit_seconds, last_act_seconds, last_compact_seconds;
  uint64_t emitted, dropped_at_capacity, death_events_dropped, collision_events_dropped;
  uint64_t idle_steps;
  uint64_t dropped_at_budget, killed_by_budget; /**< flurry_context_set_particle_budget */
} flurry_context_stats;

FLURRY_C_EXPORT flurry_status flurry_context_stats_get(const flurry_context* ctx,
                                                       flurry_context_stats* stats);

/** What a group gives up past its share of the context's particle budget
 * (flurry::BudgetPolicy). */
typedef enum flurry_budget_policy {
  FLURRY_BUDGET_DROP_NEWEST = 0,    /**< births past the share are not made (the default) */
  FLURRY_BUDGET_DROP_OLDEST = 1,    /**< births are made; the first-born die to make room */
  FLURRY_BUDGET_SCALE_EMISSION = 2, /**< every emitter keeps the same fraction of its births */
} flurry_budget_policy;
/** The most particles all groups together hold (0: none); the room under it is shared each
 * step among the groups that emit (flurry::Context::setParticleBudget), on either backend. */
FLURRY_C_EXPORT flurry_status flurry_context_set_particle_budget(flurry_context* ctx,
                                                                 size_t particles);
/** `policy`: a flurry_budget_policy (an int, so that a value outside it is an error, not
 * undefined behaviour). */
FLURRY_C_EXPORT flurry_status flurry_group_set_budget_policy(flurry_group* group, int policy);
/** One group alone, as the flurry_instance_ calls do an instance's groups: its clock at
 * `scale` times the context's (0 pauses it), its random numbers from (`seed`, `stream`
 * < 65536), a step every `interval` context steps (1 to 256) over the time it skipped
 * (flurry::Group::setTimeScale, setSeed, setUpdateInterval). */
FLURRY_C_EXPORT flurry_status flurry_group_set_time_scale(flurry_group* group, double scale);
FLURRY_C_EXPORT flurry_status flurry_group_set_seed(flurry_group* group, uint64_t seed,
                                                    uint32_t stream);
FLURRY_C_EXPORT flurry_status flurry_group_set_update_interval(flurry_group* group,
                                                               uint32_t interval);
/** The time on the group's own clock, where its next step starts (flurry::Context::time(group)). */
FLURRY_C_EXPORT flurry_status flurry_context_group_time(const flurry_context* ctx,
                                                        const flurry_group* group, double* time);
/** Why FLURRY_BACKEND_AUTO took the CPU ("" when it did not). */
FLURRY_C_EXPORT flurry_status flurry_context_backend_fallback(const flurry_context* ctx,
                                                              const char** why);
/** A new empty group of fixed capacity, owned by the context. */
FLURRY_C_EXPORT flurry_status flurry_context_create_group(flurry_context* ctx, const char* name,
                                                          size_t capacity, flurry_group** out);
/** The group of that name (FLURRY_ERROR_NOT_FOUND if none). */
FLURRY_C_EXPORT flurry_status flurry_context_group(flurry_context* ctx, const char* name,
                                                   flurry_group** out);
FLURRY_C_EXPORT flurry_status flurry_context_group_count(const flurry_context* ctx, size_t* count);
FLURRY_C_EXPORT flurry_status flurry_context_group_at(flurry_context* ctx, size_t index,
                                                      flurry_group** out);

/* ---- effects ----------------------------------------------------------------------------- */

/** Loads and validates an effect file (FLURRY_ERROR_EFFECT: "FILE: JSON.PATH: why"). */
FLURRY_C_EXPORT flurry_status flurry_effect_load(const char* path, flurry_effect** out);
/** Parses an effect from JSON text; `name` names it in errors (NULL: "<effect>"). */
FLURRY_C_EXPORT flurry_status flurry_effect_parse(const char* json, const char* name,
                                                  flurry_effect** out);
FLURRY_C_EXPORT flurry_status flurry_effect_destroy(flurry_effect* effect);
FLURRY_C_EXPORT flurry_status flurry_effect_name(const flurry_effect* effect, const char** name);
/** The steps `flurry run` takes by default. */
FLURRY_C_EXPORT flurry_status flurry_effect_frames(const flurry_effect* effect, int* frames);
/** The effect's seed and dt over the defaults (then choose the backend). */
FLURRY_C_EXPORT flurry_status flurry_effect_context_options(const flurry_effect* effect,
                                                            flurry_context_options* options);
FLURRY_C_EXPORT flurry_status flurry_effect_warning_count(const flurry_effect* effect,
                                                          size_t* count);
/** Warning `index`: "JSON.PATH: why". */
FLURRY_C_EXPORT flurry_status flurry_effect_warning(const flurry_effect* effect, size_t index,
                                                    const char** message);
/** The `render` object as JSON text ("{}" when absent). */
FLURRY_C_EXPORT flurry_status flurry_effect_render_json(const flurry_effect* effect,
                                                        const char** json);
/** Scales how many particles the effect makes, a quality knob (Effect::scaleSpawning): every
 * emitter's rate, bursts and births by distance, the showers of prime emitters, and the
 * groups' capacities, by `factor` (finite, > 0: else FLURRY_ERROR_INVALID_ARGUMENT). */
FLURRY_C_EXPORT flurry_status flurry_effect_scale_spawning(flurry_effect* effect, double factor);
/** Creates the effect's groups in `ctx`; max_capacity > 0 caps each group's capacity. */
FLURRY_C_EXPORT flurry_status flurry_effect_build(const flurry_effect* effect, flurry_context* ctx,
                                                  size_t max_capacity);

/* ---- action lists and emitters, by name and field ----------------------------------------
 * Fields are those of the effect format (docs/effect-format.md), validated by the effect
 * loader when the list or emitter is used (or checked with *_validate), so that an error
 * names the field as an effect file would: "actions[1].restitution: must be in [0, 1]".
 * A field path may go into objects and arrays: "surface.normal", "types[0].lifetime". A
 * domain field is set with *_set_domain (its type) and then its own fields
 * ("surface.normal"), or whole with *_set_json. A float field accepts +-INFINITY where the
 * format accepts "inf"; NaN is refused. */

FLURRY_C_EXPORT flurry_status flurry_action_list_create(flurry_action_list** out);
FLURRY_C_EXPORT flurry_status flurry_action_list_destroy(flurry_action_list* list);
/** Appends an action by name ("Gravity", "Bounce", ...); its index in *index (may be NULL).
 * An unknown name is FLURRY_ERROR_EFFECT: "actions[2].type: unknown action ..." */
FLURRY_C_EXPORT flurry_status flurry_action_list_add(flurry_action_list* list, const char* action,
                                                     size_t* index);
FLURRY_C_EXPORT flurry_status flurry_action_list_count(const flurry_action_list* list,
                                                       size_t* count);
FLURRY_C_EXPORT flurry_status flurry_action_set_float(flurry_action_list* list, size_t index,
                                                      const char* field, double value);
FLURRY_C_EXPORT flurry_status flurry_action_set_int(flurry_action_list* list, size_t index,
                                                    const char* field, int64_t value);
FLURRY_C_EXPORT flurry_status flurry_action_set_bool(flurry_action_list* list, size_t index,
                                                     const char* field, int value);
FLURRY_C_EXPORT flurry_status flurry_action_set_vec3(flurry_action_list* list, size_t index,
                                                     const char* field, float x, float y, float z);
FLURRY_C_EXPORT flurry_status flurry_action_set_vec4(flurry_action_list* list, size_t index,
                                                     const char* field, float x, float y, float z,
                                                     float w);
FLURRY_C_EXPORT flurry_status flurry_action_set_string(flurry_action_list* list, size_t index,
                                                       const char* field, const char* value);
/** Sets `field` to a domain of type `domain` ("plane", "sphere", ...); its fields follow. */
FLURRY_C_EXPORT flurry_status flurry_action_set_domain(flurry_action_list* list, size_t index,
                                                       const char* field, const char* domain);
/** Sets `field` to a JSON value given as text (a domain, a fuzzy value, keys, ...). */
FLURRY_C_EXPORT flurry_status flurry_action_set_json(flurry_action_list* list, size_t index,
                                                     const char* field, const char* json);
/** Removes a field set before (its default applies again); nothing if it is not set. */
FLURRY_C_EXPORT flurry_status flurry_action_unset(flurry_action_list* list, size_t index,
                                                  const char* field);
/** Reads the whole list as the loader would, without using it. */
FLURRY_C_EXPORT flurry_status flurry_action_list_validate(const flurry_action_list* list);

FLURRY_C_EXPORT flurry_status flurry_emitter_create(flurry_emitter** out);
FLURRY_C_EXPORT flurry_status flurry_emitter_destroy(flurry_emitter* emitter);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_float(flurry_emitter* emitter, const char* field,
                                                       double value);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_int(flurry_emitter* emitter, const char* field,
                                                     int64_t value);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_bool(flurry_emitter* emitter, const char* field,
                                                      int value);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_vec3(flurry_emitter* emitter, const char* field,
                                                      float x, float y, float z);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_vec4(flurry_emitter* emitter, const char* field,
                                                      float x, float y, float z, float w);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_string(flurry_emitter* emitter, const char* field,
                                                        const char* value);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_domain(flurry_emitter* emitter, const char* field,
                                                        const char* domain);
FLURRY_C_EXPORT flurry_status flurry_emitter_set_json(flurry_emitter* emitter, const char* field,
                                                      const char* json);
FLURRY_C_EXPORT flurry_status flurry_emitter_unset(flurry_emitter* emitter, const char* field);
FLURRY_C_EXPORT flurry_status flurry_emitter_validate(const flurry_emitter* emitter);

/* ---- groups ------------------------------------------------------------------------------ */

FLURRY_C_EXPORT flurry_status flurry_group_name(const flurry_group* group, const char** name);
/** Where a group's particles live when it moves (flurry::Space). */
typedef enum flurry_space {
  FLURRY_SPACE_WORLD = 0, /**< born particles stay put; emitters and colliders follow */
  FLURRY_SPACE_LOCAL = 1  /**< the live particles move with the group */
} flurry_space;
/** Places the group in the world (flurry::Group::setTransform), at any time between steps:
 * world = position + rotation * (scale * local), rotation a unit quaternion x, y, z, w. From
 * then on its emitters and action lists are in its own frame and follow it. Refused
 * (FLURRY_ERROR_INVALID_ARGUMENT naming "transform.position", "transform.rotation" or
 * "transform.scale") unless finite with scale > 0 and a unit rotation; the group is then
 * unchanged. */
FLURRY_C_EXPORT flurry_status flurry_group_set_transform(flurry_group* group,
                                                         const float position[3],
                                                         const float rotation[4], float scale);
/** The group's transform (the identity if none was set); any output may be NULL. */
FLURRY_C_EXPORT flurry_status flurry_group_transform(const flurry_group* group, float position[3],
                                                     float rotation[4], float* scale);
FLURRY_C_EXPORT flurry_status flurry_group_set_space(flurry_group* group, flurry_space space);
FLURRY_C_EXPORT flurry_status flurry_group_space(const flurry_group* group, flurry_space* space);
/** Starts `count` groups of `ctx` as if they had run `seconds` already (flurry::Context::prewarm):
 * they alone are stepped, the context's clock does not move; *steps (may be NULL) gets the
 * steps taken. */
FLURRY_C_EXPORT flurry_status flurry_context_prewarm(flurry_context* ctx,
                                                     flurry_group* const* groups, size_t count,
                                                     double seconds, uint64_t* steps);

/* ---- effect instances ------------------------------------------------------------------- */

/** Builds the effect into `ctx` as an instance a game places, moves and prewarms
 * (flurry::Effect::instantiate): its groups are named "GROUP@NAME", so that one effect can be
 * built many times in a context; max_capacity > 0 caps each group's capacity. The handle
 * belongs to the caller: flurry_instance_destroy it while `ctx` lives. */
FLURRY_C_EXPORT flurry_status flurry_effect_instantiate(const flurry_effect* effect,
                                                        flurry_context* ctx, const char* name,
                                                        size_t max_capacity, flurry_instance** out);
/** Removes the instance's groups from its context and frees the handle (NULL is fine). */
FLURRY_C_EXPORT flurry_status flurry_instance_destroy(flurry_instance* instance);
/** Places every group of the instance (as flurry_group_set_transform), all or nothing: a
 * transform a group refuses leaves the whole instance where it was. A move allocates nothing
 * once the instance has been placed. */
FLURRY_C_EXPORT flurry_status flurry_instance_set_transform(flurry_instance* instance,
                                                            const float position[3],
                                                            const float rotation[4], float scale);
/** The instance's transform (the identity until one is set); any output may be NULL. */
FLURRY_C_EXPORT flurry_status flurry_instance_transform(const flurry_instance* instance,
                                                        float position[3], float rotation[4],
                                                        float* scale);
/** Starts the instance as if it had run `seconds` already (flurry_context_prewarm of its
 * groups); *steps (may be NULL) gets the steps taken. */
FLURRY_C_EXPORT flurry_status flurry_instance_prewarm(flurry_instance* instance, double seconds,
                                                      uint64_t* steps);
/** Runs the instance at `scale` times the context's time (finite, 0 <= scale <= 1000; 0
 * pauses it): flurry::EffectInstance::setTimeScale. */
FLURRY_C_EXPORT flurry_status flurry_instance_set_time_scale(flurry_instance* instance,
                                                             double scale);
/** Gives the instance its own random numbers (flurry::EffectInstance::setSeed): instances
 * with one seed look alike wherever they are made. */
FLURRY_C_EXPORT flurry_status flurry_instance_set_seed(flurry_instance* instance, uint64_t seed);
/** Steps the instance once every `interval` context steps (1 to 256), each time over the
 * time it skipped: a level of detail for an instance out of sight
 * (flurry::EffectInstance::setUpdateInterval). */
FLURRY_C_EXPORT flurry_status flurry_instance_set_update_interval(flurry_instance* instance,
                                                                  uint32_t interval);
/** Stops emitting now (flurry::EffectInstance::stop): the live particles live out their lives. */
FLURRY_C_EXPORT flurry_status flurry_instance_stop(flurry_instance* instance);
/** Stops emitting and removes every particle at once (the groups stay). */
FLURRY_C_EXPORT flurry_status flurry_instance_kill(flurry_instance* instance);
/** Starts the instance over now (flurry::EffectInstance::restart): everything removed, its
 * emitters as the effect built them, their times counting from now. */
FLURRY_C_EXPORT flurry_status flurry_instance_restart(flurry_instance* instance);
/** *done = 1 when nothing of the instance lives and nothing can be born again (then
 * flurry_instance_destroy it), else 0. */
FLURRY_C_EXPORT flurry_status flurry_instance_done(const flurry_instance* instance, int* done);
FLURRY_C_EXPORT flurry_status flurry_instance_group_count(const flurry_instance* instance,
                                                          size_t* count);
/** Group `index` of the instance, in the effect's order (FLURRY_ERROR_NOT_FOUND past them). */
FLURRY_C_EXPORT flurry_status flurry_instance_group_at(const flurry_instance* instance,
                                                       size_t index, flurry_group** out);
/** The union of the instance's groups' bounds, for an engine's culling (*empty 1 when no
 * particle lives). Kept by the CPU pass every step once asked. */
FLURRY_C_EXPORT flurry_status flurry_instance_bounds(const flurry_instance* instance, float min[3],
                                                     float max[3], int* empty);

/** Live particles: indices [0, size). */
FLURRY_C_EXPORT flurry_status flurry_group_size(const flurry_group* group, size_t* size);
FLURRY_C_EXPORT flurry_status flurry_group_capacity(const flurry_group* group, size_t* capacity);
/** Replaces the group's action list with `list` (read and validated; errors name
 * "actions[i].field"). The list stays the caller's. */
FLURRY_C_EXPORT flurry_status flurry_group_set_actions(flurry_group* group,
                                                       const flurry_action_list* list);
/** Adds a copy of `emitter` (read and validated; errors name "emitter.field"). */
FLURRY_C_EXPORT flurry_status flurry_group_add_emitter(flurry_group* group,
                                                       const flurry_emitter* emitter);
/** Asks the group to store `attribute` although no action reads it (before stepping). */
FLURRY_C_EXPORT flurry_status flurry_group_require(flurry_group* group, flurry_attribute attribute);
/** Whether the group stores `attribute` (*stored 1 or 0). */
FLURRY_C_EXPORT flurry_status flurry_group_stores(const flurry_group* group,
                                                  flurry_attribute attribute, int* stored);
/** Removes every particle (the statistics are kept). */
FLURRY_C_EXPORT flurry_status flurry_group_clear(flurry_group* group);

/** One component of a float attribute: particle i's value is at
 * *(const float*)((const char*)*data + i * *stride) for i < *count; *stride in bytes.
 * Valid until the next step. FLURRY_ERROR_NOT_STORED if the group does not store it,
 * FLURRY_ERROR_WRONG_TYPE for Id and Visible. *data may be NULL when *count is 0. */
FLURRY_C_EXPORT flurry_status flurry_group_lane(const flurry_group* group,
                                                flurry_attribute attribute, int component,
                                                const float** data, size_t* count, size_t* stride);
/** The same array, writable (writing marks the particles changed for the backend). */
FLURRY_C_EXPORT flurry_status flurry_group_lane_mut(flurry_group* group, flurry_attribute attribute,
                                                    int component, float** data, size_t* count,
                                                    size_t* stride);
/** The particles' ids (always stored). */
FLURRY_C_EXPORT flurry_status flurry_group_ids(const flurry_group* group, const uint32_t** data,
                                               size_t* count, size_t* stride);
/** 1 visible, 0 hidden by a blocker (FLURRY_ERROR_NOT_STORED without a Block action). */
FLURRY_C_EXPORT flurry_status flurry_group_visible(const flurry_group* group, const uint32_t** data,
                                                   size_t* count, size_t* stride);
/** Axis-aligned bounds of the live particles (*empty 1 when there are none). */
FLURRY_C_EXPORT flurry_status flurry_group_bounds(const flurry_group* group, float min[3],
                                                  float max[3], int* empty);

/** flurry_death_event.action of a particle killed for being NaN or infinite. */
#define FLURRY_DEATH_NON_FINITE 0xFFFFFFFFu

/** A particle's death (flurry::DeathEvent): where it was and how fast it went at the end of
 * the step that killed it. */
typedef struct flurry_death_event {
  float position[3];
  float velocity[3]; /**< zero when the group stores no velocity */
  uint32_t id;
  uint32_t action; /**< index in the action list of what killed it, or FLURRY_DEATH_NON_FINITE */
  double time;     /**< the end of the step it died in */
} flurry_death_event;

/** Adds a death emitter (flurry::DeathEmitter: particles born where the group named by its
 * "source" has deaths), given as the JSON object an effect file's "deathEmitters" holds, e.g.
 * {"source": "rain", "count": 3, "cause": 0, "types": [{"velocity": [0, 2, 0]}]}. Bad fields
 * are FLURRY_ERROR_EFFECT naming "deathEmitter.FIELD"; the source is looked up when the
 * context steps (a missing one fails that step, before anything moves). Both backends. */
FLURRY_C_EXPORT flurry_status flurry_group_add_death_emitter(flurry_group* group, const char* json);

/** Records each step's deaths, at most `per_step` a step (the first in particle order; the
 * rest counted in flurry_group_deaths' *dropped); 0 stops. Both backends record them. */
FLURRY_C_EXPORT flurry_status flurry_group_record_deaths(flurry_group* group, size_t per_step);
/** The last step's deaths (valid until the next step); *dropped (may be NULL) gets the deaths
 * not recorded for want of room, over the group's life. */
FLURRY_C_EXPORT flurry_status flurry_group_deaths(const flurry_group* group,
                                                  const flurry_death_event** events, size_t* count,
                                                  uint64_t* dropped);

/** A particle deflected by a Bounce (flurry::CollisionEvent): where and when it met the
 * surface, how fast it came, and the surface's unit normal on its side. */
typedef struct flurry_collision_event {
  float position[3]; /**< the point of impact */
  float velocity[3]; /**< arriving there, before the bounce */
  float normal[3];
  uint32_t id;
  uint32_t action;   /**< index of the Bounce in the action list */
  uint32_t reserved; /**< 0 */
  double time;       /**< the moment of impact */
} flurry_collision_event;

/** Records each step's collisions, at most `per_step` a step (the first in particle order; the
 * rest counted in flurry_group_collisions' *dropped); 0 stops. Both backends record them. */
FLURRY_C_EXPORT flurry_status flurry_group_record_collisions(flurry_group* group, size_t per_step);
/** The last step's collisions (valid until the next step); *dropped (may be NULL) gets those
 * not recorded for want of room, over the group's life. */
FLURRY_C_EXPORT flurry_status flurry_group_collisions(const flurry_group* group,
                                                      const flurry_collision_event** events,
                                                      size_t* count, uint64_t* dropped);

/** Where the particles went (flurry::GroupStats):
 * emitted == size + killed_by_age + absorbed + dropped_at_capacity + dropped_at_budget +
 * killed_by_budget + killed_non_finite. */
typedef struct flurry_group_stats {
  uint64_t emitted;
  uint64_t killed_by_age;
  uint64_t absorbed;
  uint64_t dropped_at_capacity;
  uint64_t killed_non_finite;
  uint64_t emitters_spawned;
  uint64_t emitters_dropped;
  uint64_t idle_steps;
  uint64_t block_actions_culled;
  double emit_seconds, act_seconds, compact_seconds; /**< CPU backend's cumulative times */
  uint64_t dropped_at_budget, killed_by_budget;      /**< past its share of the budget */
} flurry_group_stats;

FLURRY_C_EXPORT flurry_status flurry_group_stats_get(const flurry_group* group,
                                                     flurry_group_stats* stats);
/** Particles killed by each action-list entry (valid until the next step). */
FLURRY_C_EXPORT flurry_status flurry_group_killed_by_action(const flurry_group* group,
                                                            const uint64_t** data, size_t* count);
/** Particles emitted by generation: 0 the group's own emitters, 1 spawned emitters, ... */
FLURRY_C_EXPORT flurry_status flurry_group_emitted_by_generation(const flurry_group* group,
                                                                 const uint64_t** data,
                                                                 size_t* count);

/* ---- packed vertex data for an engine's own draw (flurry/interop.hpp) -------------------- */

/** Flurry's instance record, 32 bytes a particle, all float: x, y, z, radius, r, g, b, a. */
#define FLURRY_INSTANCE_STRIDE 32
/** Asks the group to store what flurry_group_pack_instances reads (call before stepping). */
FLURRY_C_EXPORT flurry_status flurry_group_require_instances(flurry_group* group);
/** Packs the visible live particles into `out` (`capacity_bytes` long: at least
 * size * FLURRY_INSTANCE_STRIDE), nearest last to `eye` when it is not NULL (for blending
 * without a depth buffer), the group's order otherwise; *written particles. */
FLURRY_C_EXPORT flurry_status flurry_group_pack_instances(const flurry_group* group, void* out,
                                                          size_t capacity_bytes, const float eye[3],
                                                          size_t* written);

/** Trails (flurry::TrailOptions): each particle keeps its last `length` positions (0: none;
 * at most 256); the ribbons flurry_group_pack_trails makes are `width` in radius at the
 * particle (0: its size), narrowing to `taper` times that and fading to `fade` times its
 * alpha at the oldest point. */
typedef struct flurry_trail_options {
  uint32_t length;
  float width, taper, fade;
} flurry_trail_options;
/** Sets the group's trail (FLURRY_ERROR_INVALID_ARGUMENT naming "trail.length", ...), on
 * either backend. */
FLURRY_C_EXPORT flurry_status flurry_group_set_trail(flurry_group* group,
                                                     const flurry_trail_options* options);
/** Packs the visible live particles' trails as ribbons: vertices of FLURRY_INSTANCE_STRIDE
 * (x, y, z, radius, r, g, b, a, newest point first) into `out` (`capacity_vertices` of them:
 * size * length always suffices), and where each strand starts into `starts`
 * (`capacity_starts` entries: strands + 1, the last being the vertex count; size + 1
 * suffices). *vertices and *strands get the counts; a particle with one point has none. */
FLURRY_C_EXPORT flurry_status flurry_group_pack_trails(const flurry_group* group, float* out,
                                                       size_t capacity_vertices, uint32_t* starts,
                                                       size_t capacity_starts, size_t* vertices,
                                                       size_t* strands);

/* ---- OpenVDB export (flurry/vdb.hpp) ----------------------------------------------------- */

/** Whether this library was built with the OpenVDB exporter. */
FLURRY_C_EXPORT int flurry_has_vdb(void);
/** Writes the group's visible particles to `path` as a fog volume and a point cloud
 * (atomically). FLURRY_ERROR_NOT_BUILT without OpenVDB; FLURRY_ERROR_IO naming the path. */
FLURRY_C_EXPORT flurry_status flurry_group_write_vdb(const flurry_group* group, const char* path);

#ifdef __cplusplus
}
#endif

#endif /* FLURRY_H */
