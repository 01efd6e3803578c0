// The C API over the C++ SDK. Every entry point runs its body through `guard`, which turns
// any exception into a status code and a thread-local message: nothing is thrown across the
// boundary. Action lists and emitters are kept as the JSON an effect file would hold and
// read by the effect loader (effect/effect_parts.hpp), the one place that knows each
// action's fields, defaults and validation.
#include "flurry.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "effect/effect_parts.hpp"
#include "flurry/context.hpp"
#include "flurry/effect.hpp"
#include "flurry/error.hpp"
#include "flurry/group.hpp"
#include "flurry/interop.hpp"
#include "flurry/log.hpp"
#include "flurry/version.hpp"
#ifdef FLURRY_C_HAS_OPENCL
#include "flurry/opencl.hpp"
#endif
#ifdef FLURRY_C_HAS_VDB
#include "flurry/vdb.hpp"
#endif

using json = nlohmann::json;

struct flurry_context {
  explicit flurry_context(const flurry::ContextOptions& o) : ctx(o) {}
  flurry::Context ctx;
};
struct flurry_effect {
  flurry::Effect fx;
  std::vector<std::string> warnings;  // EffectWarning::message(), kept for the C strings
};
struct flurry_action_list {
  json actions = json::array();
};
struct flurry_emitter {
  json fields = json::object();
};
struct flurry_instance {
  flurry::EffectInstance instance;
};

namespace {

static_assert(int(FLURRY_ATTR_COUNT) == int(flurry::Attribute::Count));
static_assert(int(FLURRY_ATTR_ID) == int(flurry::Attribute::Id));
static_assert(int(FLURRY_ATTR_VISIBLE) == int(flurry::Attribute::Visible));
static_assert(int(FLURRY_ATTR_BIRTH_SIZE) == int(flurry::Attribute::BirthSize));
static_assert(int(FLURRY_BACKEND_AUTO) == int(flurry::Backend::Auto));

constexpr int kOpenCLDeviceNotFound = -1;  // CL_DEVICE_NOT_FOUND

/// The integer a C caller stored in an enum. Read as bytes: in C++ an enum object holding a
/// value outside its enumerators' range is undefined behaviour to load, and C allows it.
template <class E>
long long rawValue(const E& e) {
  std::underlying_type_t<E> v;
  static_assert(sizeof v == sizeof e);
  std::memcpy(&v, &e, sizeof v);
  return (long long)v;
}

/// A failure the C layer itself detects (a NULL handle, an index out of range, ...).
struct Failure {
  flurry_status status;
  std::string message;
};

thread_local std::string t_lastError;
thread_local bool t_outOfMemory = false;  // the message itself could not be stored

flurry_status fail(flurry_status s, const char* message) noexcept {
  t_outOfMemory = false;
  try {
    t_lastError = message;
  } catch (...) {
    t_lastError.clear();
    t_outOfMemory = true;
  }
  return s;
}

template <class F>
flurry_status guard(F&& body) noexcept {
  try {
    body();
    return FLURRY_OK;
  } catch (const Failure& f) {
    return fail(f.status, f.message.c_str());
  } catch (const flurry::EffectError& e) {
    return fail(FLURRY_ERROR_EFFECT, e.what());
  } catch (const flurry::InvalidArgument& e) {
    return fail(FLURRY_ERROR_INVALID_ARGUMENT, e.what());
  } catch (const flurry::IoError& e) {
    return fail(FLURRY_ERROR_IO, e.what());
#ifdef FLURRY_C_HAS_OPENCL
  } catch (const flurry::OpenCLError& e) {
    return fail(e.code() == kOpenCLDeviceNotFound ? FLURRY_ERROR_NO_DEVICE : FLURRY_ERROR_OPENCL,
                e.what());
#endif
  } catch (const std::bad_alloc&) {
    return fail(FLURRY_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(FLURRY_ERROR_OTHER, e.what());
  } catch (...) {
    return fail(FLURRY_ERROR_OTHER, "an unknown C++ exception");
  }
}

/// Throws FLURRY_ERROR_NULL_ARGUMENT naming the argument.
template <class T>
void need(const T* p, const char* name) {
  if (!p) throw Failure{FLURRY_ERROR_NULL_ARGUMENT, std::string(name) + ": is NULL"};
}

flurry::Group& group(flurry_group* g) {
  return *reinterpret_cast<flurry::Group*>(g);
}
const flurry::Group& group(const flurry_group* g) {
  return *reinterpret_cast<const flurry::Group*>(g);
}
flurry_group* handle(flurry::Group& g) {
  return reinterpret_cast<flurry_group*>(&g);
}

// ---- fields set by path ---------------------------------------------------------------------

/// One step of a field path: a key ("surface") or an array index ("[2]").
struct Step {
  std::string key;
  std::size_t index = 0;
  bool isIndex = false;
};

/// Splits "a.b[2].c" into steps; throws InvalidArgument naming `full` if it is not a path.
std::vector<Step> parsePath(std::string_view f, const std::string& full) {
  auto bad = [&](const char* why) { throw flurry::InvalidArgument(full, why); };
  constexpr const char* kSyntax = "not a field path (name, name.name or name[i])";
  if (f.empty()) bad("an empty field name");
  std::vector<Step> steps;
  std::size_t i = 0;
  while (i < f.size()) {
    const std::size_t end = std::min(f.find_first_of(".[", i), f.size());
    if (end == i) bad(kSyntax);
    steps.push_back({std::string(f.substr(i, end - i))});
    i = end;
    while (i < f.size() && f[i] == '[') {
      const std::size_t close = f.find(']', i);
      if (close == f.npos || close == i + 1) bad(kSyntax);
      std::size_t n = 0;
      for (std::size_t k = i + 1; k < close; ++k) {
        if (f[k] < '0' || f[k] > '9') bad(kSyntax);
        n = n * 10 + std::size_t(f[k] - '0');
        if (n > 65536) bad("an array index above 65536");
      }
      steps.push_back({{}, n, true});
      i = close + 1;
    }
    if (i < f.size()) {
      if (f[i] != '.' || i + 1 == f.size()) bad(kSyntax);
      ++i;
    }
  }
  if (steps.size() == 1 && steps.front().key == "type")
    bad("the type is set when the action is added (flurry_action_list_add)");
  return steps;
}

/// Sets the value at `field` ("a", "a.b", "a[2].b") under `root`, creating the objects and
/// arrays on the way; or, with `erase`, removes the named field if it is there. `where` is
/// the JSON path of `root`, for messages.
void setField(json& root, const std::string& where, const char* field, json value,
              bool erase = false) {
  need(field, "field");
  const std::string full = where + "." + field;
  const std::vector<Step> steps = parsePath(field, full);
  if (erase && steps.back().isIndex)
    throw flurry::InvalidArgument(full, "only a named field can be unset");
  json* cur = &root;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const Step& s = steps[k];
    const bool last = k + 1 == steps.size();
    if (erase) {
      if (!s.isIndex && cur->is_object() && last) {
        cur->erase(s.key);
        return;
      }
      if (s.isIndex ? !cur->is_array() || cur->size() <= s.index
                    : !cur->is_object() || !cur->contains(s.key))
        return;  // not set: nothing to remove
    }
    if (s.isIndex) {
      if (!cur->is_array()) *cur = json::array();
      while (cur->size() <= s.index) cur->push_back(nullptr);
      cur = &(*cur)[s.index];
    } else {
      if (!cur->is_object()) *cur = json::object();
      cur = &(*cur)[s.key];
    }
  }
  *cur = std::move(value);
}

/// A float as the effect format holds it: +-inf as "inf" / "-inf" (JSON has no infinity).
json number(const std::string& where, const char* field, double v) {
  if (std::isnan(v)) throw flurry::InvalidArgument(where + "." + (field ? field : ""), "is NaN");
  if (std::isinf(v)) return v > 0 ? json("inf") : json("-inf");
  return json(v);
}

json parseJson(const std::string& where, const char* field, const char* text) {
  need(text, "json");
  try {
    return json::parse(text, nullptr, true, true);
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw flurry::EffectError("", where + "." + (field ? field : ""), why);
  }
}

std::string actionPath(std::size_t i) {
  return "actions[" + std::to_string(i) + "]";
}

json& action(flurry_action_list* list, std::size_t index) {
  need(list, "list");
  if (index >= list->actions.size())
    throw Failure{FLURRY_ERROR_NOT_FOUND, "action index " + std::to_string(index) +
                                              ": the list has " +
                                              std::to_string(list->actions.size()) + " actions"};
  return list->actions[index];
}

flurry::EffectLoadOptions loadOptions() {
  flurry::EffectLoadOptions o;
#ifdef FLURRY_C_HAS_VDB
  o.fieldResolver = [](const std::filesystem::path& file, const std::string& grid) {
    return flurry::vdb::readVectorField(file, grid);
  };
#endif
  return o;
}

flurry::ActionList readActions(const flurry_action_list* list) {
  return flurry::detail::parseEffectActions(list->actions.dump(), "", "actions", loadOptions());
}
flurry::Emitter readEmitter(const flurry_emitter* e) {
  return flurry::detail::parseEffectEmitter(e->fields.dump(), "", "emitter", loadOptions());
}

flurry::Attribute attribute(const flurry_attribute& a) {
  const long long v = rawValue(a);
  if (v < 0 || v >= FLURRY_ATTR_COUNT)
    throw flurry::InvalidArgument("attribute", std::to_string(v) + " is not a flurry_attribute");
  return flurry::Attribute(v);
}

/// Checks that `g` stores float attribute `a` and has component `c`.
void checkLane(const flurry::Group& g, flurry::Attribute a, int c) {
  const std::string name(flurry::attributeName(a));
  if (a == flurry::Attribute::Id || a == flurry::Attribute::Visible)
    throw Failure{FLURRY_ERROR_WRONG_TYPE,
                  "attribute " + name + ": stored as uint32 (flurry_group_ids / _visible)"};
  if (c < 0 || c >= flurry::componentCount(a))
    throw flurry::InvalidArgument("component", std::to_string(c) + " is not a component of " +
                                                   name + " (it has " +
                                                   std::to_string(flurry::componentCount(a)) + ")");
  if (!g.attributes().has(a))
    throw Failure{FLURRY_ERROR_NOT_STORED, "group '" + g.name() + "' does not store " + name +
                                               " (flurry_group_require it before stepping)"};
}

// A transform from the C arrays (rotation as x, y, z, w), and back; absent outputs skipped.
flurry::Transform transformOf(const float position[3], const float rotation[4], float scale) {
  need(position, "position");
  need(rotation, "rotation");
  flurry::Transform t;
  t.position = flurry::Vec3(position[0], position[1], position[2]);
  t.rotation = glm::quat(rotation[3], rotation[0], rotation[1], rotation[2]);  // w, x, y, z
  t.scale = scale;
  return t;
}
void writeTransform(const flurry::Transform& t, float position[3], float rotation[4],
                    float* scale) {
  if (position) position[0] = t.position.x, position[1] = t.position.y, position[2] = t.position.z;
  if (rotation)
    rotation[0] = t.rotation.x, rotation[1] = t.rotation.y, rotation[2] = t.rotation.z,
    rotation[3] = t.rotation.w;
  if (scale) *scale = t.scale;
}
}  // namespace

extern "C" {

// ---- version and errors ---------------------------------------------------------------------

const char* flurry_version(void) {
  return flurry::versionString();
}
int flurry_abi_version(void) {
  return FLURRY_C_ABI_VERSION;
}
const char* flurry_last_error(void) {
  return t_outOfMemory ? "out of memory" : t_lastError.c_str();
}
const char* flurry_status_name(flurry_status status) {
  switch (rawValue(status)) {
    case FLURRY_OK:
      return "FLURRY_OK";
    case FLURRY_ERROR_NULL_ARGUMENT:
      return "FLURRY_ERROR_NULL_ARGUMENT";
    case FLURRY_ERROR_INVALID_ARGUMENT:
      return "FLURRY_ERROR_INVALID_ARGUMENT";
    case FLURRY_ERROR_EFFECT:
      return "FLURRY_ERROR_EFFECT";
    case FLURRY_ERROR_IO:
      return "FLURRY_ERROR_IO";
    case FLURRY_ERROR_NO_DEVICE:
      return "FLURRY_ERROR_NO_DEVICE";
    case FLURRY_ERROR_OPENCL:
      return "FLURRY_ERROR_OPENCL";
    case FLURRY_ERROR_NOT_BUILT:
      return "FLURRY_ERROR_NOT_BUILT";
    case FLURRY_ERROR_NOT_FOUND:
      return "FLURRY_ERROR_NOT_FOUND";
    case FLURRY_ERROR_NOT_STORED:
      return "FLURRY_ERROR_NOT_STORED";
    case FLURRY_ERROR_WRONG_TYPE:
      return "FLURRY_ERROR_WRONG_TYPE";
    case FLURRY_ERROR_OUT_OF_MEMORY:
      return "FLURRY_ERROR_OUT_OF_MEMORY";
    case FLURRY_ERROR_OTHER:
      return "FLURRY_ERROR_OTHER";
  }
  return "unknown flurry_status";
}

// ---- log ------------------------------------------------------------------------------------

static_assert(int(FLURRY_LOG_DEBUG) == int(flurry::LogLevel::Debug));
static_assert(int(FLURRY_LOG_ERROR) == int(flurry::LogLevel::Error));

flurry_status flurry_set_log_callback(flurry_log_fn fn, void* user_data) {
  return guard([&] {
    if (!fn) {
      flurry::setLogCallback({});
      return;
    }
    flurry::setLogCallback([fn, user_data](flurry::LogLevel level, std::string_view message) {
      const std::string text(message);  // C wants it NUL-terminated
      fn(flurry_log_level(int(level)), text.c_str(), user_data);
    });
  });
}

// ---- context --------------------------------------------------------------------------------

flurry_status flurry_context_options_init(flurry_context_options* options) {
  return guard([&] {
    need(options, "options");
    const flurry::ContextOptions d;
    options->seed = d.seed;
    options->dt = d.dt;
    options->threads = d.threads;
    options->backend = FLURRY_BACKEND_CPU;
    options->device = nullptr;
  });
}

namespace {

// A flurry_scheduler as the SDK's TaskScheduler.
class CScheduler final : public flurry::TaskScheduler {
 public:
  explicit CScheduler(const flurry_scheduler& s) : s_(s) {}
  unsigned concurrency() const override { return s_.concurrency; }
  void parallelFor(std::size_t count, flurry::TaskRef task) override {
    s_.parallel_for(s_.user, count, task.call, task.context);
  }

 private:
  flurry_scheduler s_;
};

flurry_status createContext(const flurry_context_options* options, bool withScheduler,
                            const flurry_scheduler* scheduler, flurry_context** out) {
  return guard([&] {
    need(out, "out");
    *out = nullptr;
    flurry::ContextOptions o;
    if (withScheduler) {
      need(scheduler, "scheduler");
      if (!scheduler->parallel_for)
        throw flurry::InvalidArgument("scheduler", "parallel_for is NULL");
      o.scheduler = std::make_shared<CScheduler>(*scheduler);
    }
    if (options) {
      const long long backend = rawValue(options->backend);
      if (backend < 0 || backend > FLURRY_BACKEND_AUTO)
        throw flurry::InvalidArgument("backend",
                                      std::to_string(backend) + " is not a flurry_backend");
      o.seed = options->seed;
      o.dt = options->dt;
      o.threads = options->threads;
      o.backend = flurry::Backend(backend);
      if (options->device) o.device = options->device;
    }
#ifndef FLURRY_C_HAS_OPENCL
    if (o.backend == flurry::Backend::OpenCL)
      throw Failure{FLURRY_ERROR_NOT_BUILT,
                    "backend opencl: this build of Flurry has no OpenCL backend "
                    "(FLURRY_OPENCL=OFF)"};
#endif
    *out = new flurry_context(o);
  });
}

}  // namespace

flurry_status flurry_context_create(const flurry_context_options* options, flurry_context** out) {
  return createContext(options, false, nullptr, out);
}

flurry_status flurry_context_create_with_scheduler(const flurry_context_options* options,
                                                   const flurry_scheduler* scheduler,
                                                   flurry_context** out) {
  return createContext(options, true, scheduler, out);
}

flurry_status flurry_context_stats_get(const flurry_context* ctx, flurry_context_stats* out) {
  return guard([&] {
    need(ctx, "ctx");
    need(out, "stats");
    const flurry::ContextStats s = ctx->ctx.stats();
    out->groups = s.groups;
    out->instances = s.instances;
    out->particles = s.particles;
    out->capacity = s.capacity;
    out->last_step_seconds = s.lastStepSeconds;
    out->last_emit_seconds = s.lastStepParts.emit;
    out->last_act_seconds = s.lastStepParts.act;
    out->last_compact_seconds = s.lastStepParts.compact;
    out->emitted = s.emitted;
    out->dropped_at_capacity = s.droppedAtCapacity;
    out->death_events_dropped = s.deathEventsDropped;
    out->collision_events_dropped = s.collisionEventsDropped;
    out->idle_steps = s.idleSteps;
    out->dropped_at_budget = s.droppedAtBudget;
    out->killed_by_budget = s.killedByBudget;
  });
}

flurry_status flurry_context_set_particle_budget(flurry_context* ctx, size_t particles) {
  return guard([&] {
    need(ctx, "ctx");
    ctx->ctx.setParticleBudget(particles);
  });
}

flurry_status flurry_group_set_budget_policy(flurry_group* g, int policy) {
  return guard([&] {
    need(g, "group");
    static_assert(int(flurry::BudgetPolicy::DropOldest) == FLURRY_BUDGET_DROP_OLDEST &&
                  int(flurry::BudgetPolicy::ScaleEmission) == FLURRY_BUDGET_SCALE_EMISSION);
    group(g).setBudgetPolicy(flurry::BudgetPolicy(policy));
  });
}

flurry_status flurry_group_set_time_scale(flurry_group* g, double scale) {
  return guard([&] {
    need(g, "group");
    group(g).setTimeScale(scale);
  });
}
flurry_status flurry_group_set_seed(flurry_group* g, uint64_t seed, uint32_t stream) {
  return guard([&] {
    need(g, "group");
    group(g).setSeed(seed, stream);
  });
}
flurry_status flurry_group_set_update_interval(flurry_group* g, uint32_t interval) {
  return guard([&] {
    need(g, "group");
    group(g).setUpdateInterval(interval);
  });
}
flurry_status flurry_context_group_time(const flurry_context* ctx, const flurry_group* g,
                                        double* time) {
  return guard([&] {
    need(ctx, "ctx");
    need(g, "group");
    need(time, "time");
    *time = ctx->ctx.time(group(g));
  });
}

flurry_status flurry_context_destroy(flurry_context* ctx) {
  return guard([&] { delete ctx; });  // NULL is fine, as free(NULL)
}

flurry_status flurry_context_step(flurry_context* ctx) {
  return guard([&] {
    need(ctx, "ctx");
    ctx->ctx.step();
  });
}
flurry_status flurry_context_run(flurry_context* ctx, uint64_t steps) {
  return guard([&] {
    need(ctx, "ctx");
    ctx->ctx.run(steps);
  });
}
flurry_status flurry_context_time(const flurry_context* ctx, double* seconds) {
  return guard([&] {
    need(ctx, "ctx");
    need(seconds, "seconds");
    *seconds = ctx->ctx.time();
  });
}
flurry_status flurry_context_step_index(const flurry_context* ctx, uint64_t* index) {
  return guard([&] {
    need(ctx, "ctx");
    need(index, "index");
    *index = ctx->ctx.stepIndex();
  });
}
flurry_status flurry_context_time_step(const flurry_context* ctx, double* dt) {
  return guard([&] {
    need(ctx, "ctx");
    need(dt, "dt");
    *dt = ctx->ctx.timeStep();
  });
}
flurry_status flurry_context_set_time_step(flurry_context* ctx, double dt) {
  return guard([&] {
    need(ctx, "ctx");
    ctx->ctx.setTimeStep(dt);
  });
}
flurry_status flurry_context_backend(const flurry_context* ctx, flurry_backend* backend) {
  return guard([&] {
    need(ctx, "ctx");
    need(backend, "backend");
    *backend = flurry_backend(ctx->ctx.backend());
  });
}
flurry_status flurry_context_backend_fallback(const flurry_context* ctx, const char** why) {
  return guard([&] {
    need(ctx, "ctx");
    need(why, "why");
    *why = ctx->ctx.backendFallback().c_str();
  });
}
flurry_status flurry_context_create_group(flurry_context* ctx, const char* name, size_t capacity,
                                          flurry_group** out) {
  return guard([&] {
    need(ctx, "ctx");
    need(name, "name");
    need(out, "out");
    *out = handle(ctx->ctx.createGroup(name, capacity));
  });
}
flurry_status flurry_context_group(flurry_context* ctx, const char* name, flurry_group** out) {
  return guard([&] {
    need(ctx, "ctx");
    need(name, "name");
    need(out, "out");
    *out = nullptr;
    for (flurry::Group* g : ctx->ctx.groups())
      if (g->name() == name) {
        *out = handle(*g);
        return;
      }
    throw Failure{FLURRY_ERROR_NOT_FOUND, "no group named '" + std::string(name) + "'"};
  });
}
flurry_status flurry_context_group_count(const flurry_context* ctx, size_t* count) {
  return guard([&] {
    need(ctx, "ctx");
    need(count, "count");
    *count = const_cast<flurry::Context&>(ctx->ctx).groups().size();
  });
}
flurry_status flurry_context_group_at(flurry_context* ctx, size_t index, flurry_group** out) {
  return guard([&] {
    need(ctx, "ctx");
    need(out, "out");
    *out = nullptr;
    const std::vector<flurry::Group*> all = ctx->ctx.groups();
    if (index >= all.size())
      throw Failure{FLURRY_ERROR_NOT_FOUND, "group index " + std::to_string(index) +
                                                ": the context has " + std::to_string(all.size()) +
                                                " groups"};
    *out = handle(*all[index]);
  });
}

// ---- effects --------------------------------------------------------------------------------

namespace {
flurry_effect* wrap(flurry::Effect fx) {
  auto* e = new flurry_effect{std::move(fx), {}};
  try {
    for (const flurry::EffectWarning& w : e->fx.warnings) e->warnings.push_back(w.message());
  } catch (...) {
    delete e;
    throw;
  }
  return e;
}
}  // namespace

flurry_status flurry_effect_load(const char* path, flurry_effect** out) {
  return guard([&] {
    need(path, "path");
    need(out, "out");
    *out = nullptr;
    *out = wrap(flurry::loadEffect(path, loadOptions()));
  });
}
flurry_status flurry_effect_parse(const char* text, const char* name, flurry_effect** out) {
  return guard([&] {
    need(text, "json");
    need(out, "out");
    *out = nullptr;
    *out = wrap(flurry::parseEffect(text, name ? name : "<effect>", loadOptions()));
  });
}
flurry_status flurry_effect_destroy(flurry_effect* effect) {
  return guard([&] { delete effect; });
}
flurry_status flurry_effect_name(const flurry_effect* effect, const char** name) {
  return guard([&] {
    need(effect, "effect");
    need(name, "name");
    *name = effect->fx.name.c_str();
  });
}
flurry_status flurry_effect_frames(const flurry_effect* effect, int* frames) {
  return guard([&] {
    need(effect, "effect");
    need(frames, "frames");
    *frames = effect->fx.frames;
  });
}
flurry_status flurry_effect_scale_spawning(flurry_effect* effect, double factor) {
  return guard([&] {
    need(effect, "effect");
    effect->fx.scaleSpawning(factor);
  });
}
flurry_status flurry_effect_context_options(const flurry_effect* effect,
                                            flurry_context_options* options) {
  return guard([&] {
    need(effect, "effect");
    need(options, "options");
    flurry_context_options_init(options);
    options->seed = effect->fx.seed;
    options->dt = effect->fx.dt;
  });
}
flurry_status flurry_effect_warning_count(const flurry_effect* effect, size_t* count) {
  return guard([&] {
    need(effect, "effect");
    need(count, "count");
    *count = effect->warnings.size();
  });
}
flurry_status flurry_effect_warning(const flurry_effect* effect, size_t index,
                                    const char** message) {
  return guard([&] {
    need(effect, "effect");
    need(message, "message");
    if (index >= effect->warnings.size())
      throw Failure{FLURRY_ERROR_NOT_FOUND, "warning index " + std::to_string(index) +
                                                ": the effect has " +
                                                std::to_string(effect->warnings.size())};
    *message = effect->warnings[index].c_str();
  });
}
flurry_status flurry_effect_render_json(const flurry_effect* effect, const char** text) {
  return guard([&] {
    need(effect, "effect");
    need(text, "json");
    *text = effect->fx.render.c_str();
  });
}
flurry_status flurry_effect_build(const flurry_effect* effect, flurry_context* ctx,
                                  size_t max_capacity) {
  return guard([&] {
    need(effect, "effect");
    need(ctx, "ctx");
    effect->fx.build(ctx->ctx, max_capacity);
  });
}

// ---- action lists ---------------------------------------------------------------------------

flurry_status flurry_action_list_create(flurry_action_list** out) {
  return guard([&] {
    need(out, "out");
    *out = nullptr;
    *out = new flurry_action_list;
  });
}
flurry_status flurry_action_list_destroy(flurry_action_list* list) {
  return guard([&] { delete list; });
}
flurry_status flurry_action_list_add(flurry_action_list* list, const char* name, size_t* index) {
  return guard([&] {
    need(list, "list");
    need(name, "action");
    const std::size_t i = list->actions.size();
    flurry::detail::checkEffectActionType(name, "", actionPath(i));
    list->actions.push_back(json{{"type", name}});
    if (index) *index = i;
  });
}
flurry_status flurry_action_list_count(const flurry_action_list* list, size_t* count) {
  return guard([&] {
    need(list, "list");
    need(count, "count");
    *count = list->actions.size();
  });
}
flurry_status flurry_action_set_float(flurry_action_list* list, size_t i, const char* field,
                                      double v) {
  return guard([&] {
    json& a = action(list, i);
    setField(a, actionPath(i), field, number(actionPath(i), field, v));
  });
}
flurry_status flurry_action_set_int(flurry_action_list* list, size_t i, const char* field,
                                    int64_t v) {
  return guard([&] { setField(action(list, i), actionPath(i), field, json(v)); });
}
flurry_status flurry_action_set_bool(flurry_action_list* list, size_t i, const char* field, int v) {
  return guard([&] { setField(action(list, i), actionPath(i), field, json(v != 0)); });
}
flurry_status flurry_action_set_vec3(flurry_action_list* list, size_t i, const char* field, float x,
                                     float y, float z) {
  return guard([&] {
    json& a = action(list, i);
    const std::string p = actionPath(i);
    setField(a, p, field,
             json::array({number(p, field, x), number(p, field, y), number(p, field, z)}));
  });
}
flurry_status flurry_action_set_vec4(flurry_action_list* list, size_t i, const char* field, float x,
                                     float y, float z, float w) {
  return guard([&] {
    json& a = action(list, i);
    const std::string p = actionPath(i);
    setField(a, p, field,
             json::array({number(p, field, x), number(p, field, y), number(p, field, z),
                          number(p, field, w)}));
  });
}
flurry_status flurry_action_set_string(flurry_action_list* list, size_t i, const char* field,
                                       const char* v) {
  return guard([&] {
    json& a = action(list, i);
    need(v, "value");
    setField(a, actionPath(i), field, json(v));
  });
}
flurry_status flurry_action_set_domain(flurry_action_list* list, size_t i, const char* field,
                                       const char* domain) {
  return guard([&] {
    json& a = action(list, i);
    need(domain, "domain");
    setField(a, actionPath(i), field, json{{"type", domain}});
  });
}
flurry_status flurry_action_set_json(flurry_action_list* list, size_t i, const char* field,
                                     const char* text) {
  return guard([&] {
    json& a = action(list, i);
    setField(a, actionPath(i), field, parseJson(actionPath(i), field, text));
  });
}
flurry_status flurry_action_unset(flurry_action_list* list, size_t i, const char* field) {
  return guard([&] { setField(action(list, i), actionPath(i), field, nullptr, true); });
}
flurry_status flurry_action_list_validate(const flurry_action_list* list) {
  return guard([&] {
    need(list, "list");
    readActions(list);
  });
}

// ---- emitters -------------------------------------------------------------------------------

flurry_status flurry_emitter_create(flurry_emitter** out) {
  return guard([&] {
    need(out, "out");
    *out = nullptr;
    *out = new flurry_emitter;
  });
}
flurry_status flurry_emitter_destroy(flurry_emitter* e) {
  return guard([&] { delete e; });
}
flurry_status flurry_emitter_set_float(flurry_emitter* e, const char* field, double v) {
  return guard([&] {
    need(e, "emitter");
    setField(e->fields, "emitter", field, number("emitter", field, v));
  });
}
flurry_status flurry_emitter_set_int(flurry_emitter* e, const char* field, int64_t v) {
  return guard([&] {
    need(e, "emitter");
    setField(e->fields, "emitter", field, json(v));
  });
}
flurry_status flurry_emitter_set_bool(flurry_emitter* e, const char* field, int v) {
  return guard([&] {
    need(e, "emitter");
    setField(e->fields, "emitter", field, json(v != 0));
  });
}
flurry_status flurry_emitter_set_vec3(flurry_emitter* e, const char* field, float x, float y,
                                      float z) {
  return guard([&] {
    need(e, "emitter");
    const std::string p = "emitter";
    setField(e->fields, p, field,
             json::array({number(p, field, x), number(p, field, y), number(p, field, z)}));
  });
}
flurry_status flurry_emitter_set_vec4(flurry_emitter* e, const char* field, float x, float y,
                                      float z, float w) {
  return guard([&] {
    need(e, "emitter");
    const std::string p = "emitter";
    setField(e->fields, p, field,
             json::array({number(p, field, x), number(p, field, y), number(p, field, z),
                          number(p, field, w)}));
  });
}
flurry_status flurry_emitter_set_string(flurry_emitter* e, const char* field, const char* v) {
  return guard([&] {
    need(e, "emitter");
    need(v, "value");
    setField(e->fields, "emitter", field, json(v));
  });
}
flurry_status flurry_emitter_set_domain(flurry_emitter* e, const char* field, const char* domain) {
  return guard([&] {
    need(e, "emitter");
    need(domain, "domain");
    setField(e->fields, "emitter", field, json{{"type", domain}});
  });
}
flurry_status flurry_emitter_set_json(flurry_emitter* e, const char* field, const char* text) {
  return guard([&] {
    need(e, "emitter");
    setField(e->fields, "emitter", field, parseJson("emitter", field, text));
  });
}
flurry_status flurry_emitter_unset(flurry_emitter* e, const char* field) {
  return guard([&] {
    need(e, "emitter");
    setField(e->fields, "emitter", field, nullptr, true);
  });
}
flurry_status flurry_emitter_validate(const flurry_emitter* e) {
  return guard([&] {
    need(e, "emitter");
    readEmitter(e);
  });
}

// ---- groups ---------------------------------------------------------------------------------

flurry_status flurry_group_name(const flurry_group* g, const char** name) {
  return guard([&] {
    need(g, "group");
    need(name, "name");
    *name = group(g).name().c_str();
  });
}
flurry_status flurry_group_set_transform(flurry_group* g, const float position[3],
                                         const float rotation[4], float scale) {
  return guard([&] {
    need(g, "group");
    const flurry::Transform t = transformOf(position, rotation, scale);
    group(g).setTransform(t);
  });
}
flurry_status flurry_group_transform(const flurry_group* g, float position[3], float rotation[4],
                                     float* scale) {
  return guard([&] {
    need(g, "group");
    const flurry::Transform& t = group(g).transform();
    writeTransform(t, position, rotation, scale);
  });
}
flurry_status flurry_group_set_space(flurry_group* g, flurry_space space) {
  return guard([&] {
    need(g, "group");
    const long long v = rawValue(space);
    if (v != FLURRY_SPACE_WORLD && v != FLURRY_SPACE_LOCAL)
      throw flurry::InvalidArgument("space", "not a flurry_space");
    group(g).setSpace(v == FLURRY_SPACE_LOCAL ? flurry::Space::Local : flurry::Space::World);
  });
}
flurry_status flurry_group_space(const flurry_group* g, flurry_space* space) {
  return guard([&] {
    need(g, "group");
    need(space, "space");
    *space = group(g).space() == flurry::Space::Local ? FLURRY_SPACE_LOCAL : FLURRY_SPACE_WORLD;
  });
}
flurry_status flurry_context_prewarm(flurry_context* ctx, flurry_group* const* groups, size_t count,
                                     double seconds, uint64_t* steps) {
  return guard([&] {
    need(ctx, "ctx");
    if (count > 0) need(groups, "groups");
    std::vector<flurry::Group*> gs;
    for (size_t i = 0; i < count; ++i) {
      need(groups[i], "groups[i]");
      gs.push_back(&group(groups[i]));
    }
    const std::uint64_t n = ctx->ctx.prewarm(gs, seconds);
    if (steps) *steps = n;
  });
}
flurry_status flurry_effect_instantiate(const flurry_effect* effect, flurry_context* ctx,
                                        const char* name, size_t max_capacity,
                                        flurry_instance** out) {
  return guard([&] {
    need(effect, "effect");
    need(ctx, "ctx");
    need(name, "name");
    need(out, "out");
    *out = nullptr;
    auto inst = std::make_unique<flurry_instance>();
    inst->instance = effect->fx.instantiate(ctx->ctx, name, max_capacity);
    *out = inst.release();
  });
}
flurry_status flurry_instance_destroy(flurry_instance* inst) {
  return guard([&] {
    if (!inst) return;  // as free(NULL)
    std::unique_ptr<flurry_instance> owned(inst);
    owned->instance.destroy();
  });
}
flurry_status flurry_instance_set_transform(flurry_instance* inst, const float position[3],
                                            const float rotation[4], float scale) {
  return guard([&] {
    need(inst, "instance");
    const flurry::Transform t = transformOf(position, rotation, scale);
    inst->instance.setTransform(t);
  });
}
flurry_status flurry_instance_transform(const flurry_instance* inst, float position[3],
                                        float rotation[4], float* scale) {
  return guard([&] {
    need(inst, "instance");
    const flurry::Transform& t = inst->instance.transform();
    writeTransform(t, position, rotation, scale);
  });
}
flurry_status flurry_instance_prewarm(flurry_instance* inst, double seconds, uint64_t* steps) {
  return guard([&] {
    need(inst, "instance");
    const std::uint64_t n = inst->instance.prewarm(seconds);
    if (steps) *steps = n;
  });
}
flurry_status flurry_instance_set_time_scale(flurry_instance* inst, double scale) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.setTimeScale(scale);
  });
}
flurry_status flurry_instance_set_update_interval(flurry_instance* inst, uint32_t interval) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.setUpdateInterval(interval);
  });
}
flurry_status flurry_instance_set_seed(flurry_instance* inst, uint64_t seed) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.setSeed(seed);
  });
}
flurry_status flurry_instance_stop(flurry_instance* inst) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.stop();
  });
}
flurry_status flurry_instance_kill(flurry_instance* inst) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.kill();
  });
}
flurry_status flurry_instance_restart(flurry_instance* inst) {
  return guard([&] {
    need(inst, "instance");
    inst->instance.restart();
  });
}
flurry_status flurry_instance_done(const flurry_instance* inst, int* done) {
  return guard([&] {
    need(inst, "instance");
    need(done, "done");
    *done = inst->instance.done() ? 1 : 0;
  });
}
flurry_status flurry_instance_group_count(const flurry_instance* inst, size_t* count) {
  return guard([&] {
    need(inst, "instance");
    need(count, "count");
    *count = inst->instance.groups().size();
  });
}
flurry_status flurry_instance_group_at(const flurry_instance* inst, size_t index,
                                       flurry_group** out) {
  return guard([&] {
    need(inst, "instance");
    need(out, "out");
    *out = nullptr;
    const std::vector<flurry::Group*>& all = inst->instance.groups();
    if (index >= all.size())
      throw Failure{FLURRY_ERROR_NOT_FOUND, "group index " + std::to_string(index) +
                                                ": the instance has " + std::to_string(all.size()) +
                                                " groups"};
    *out = handle(*all[index]);
  });
}
flurry_status flurry_instance_bounds(const flurry_instance* inst, float min[3], float max[3],
                                     int* empty) {
  return guard([&] {
    need(inst, "instance");
    need(min, "min");
    need(max, "max");
    need(empty, "empty");
    const flurry::Bounds b = inst->instance.bounds();
    for (int k = 0; k < 3; ++k) min[k] = b.min[k], max[k] = b.max[k];
    *empty = b.empty ? 1 : 0;
  });
}
flurry_status flurry_group_size(const flurry_group* g, size_t* size) {
  return guard([&] {
    need(g, "group");
    need(size, "size");
    *size = group(g).size();
  });
}
flurry_status flurry_group_capacity(const flurry_group* g, size_t* capacity) {
  return guard([&] {
    need(g, "group");
    need(capacity, "capacity");
    *capacity = group(g).capacity();
  });
}
flurry_status flurry_group_set_actions(flurry_group* g, const flurry_action_list* list) {
  return guard([&] {
    need(g, "group");
    need(list, "list");
    group(g).setActions(readActions(list));
  });
}
flurry_status flurry_group_add_emitter(flurry_group* g, const flurry_emitter* e) {
  return guard([&] {
    need(g, "group");
    need(e, "emitter");
    group(g).addEmitter(readEmitter(e));
  });
}
flurry_status flurry_group_require(flurry_group* g, flurry_attribute a) {
  return guard([&] {
    need(g, "group");
    group(g).require({attribute(a)});
  });
}
flurry_status flurry_group_stores(const flurry_group* g, flurry_attribute a, int* stored) {
  return guard([&] {
    need(g, "group");
    need(stored, "stored");
    *stored = group(g).attributes().has(attribute(a)) ? 1 : 0;
  });
}
flurry_status flurry_group_clear(flurry_group* g) {
  return guard([&] {
    need(g, "group");
    group(g).clear();
  });
}
flurry_status flurry_group_lane(const flurry_group* g, flurry_attribute a, int component,
                                const float** data, size_t* count, size_t* stride) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    need(stride, "stride");
    const flurry::Attribute at = attribute(a);
    checkLane(group(g), at, component);
    const std::span<const float> s = group(g).lane(at, component);
    *data = s.data();
    *count = s.size();
    *stride = sizeof(float);
  });
}
flurry_status flurry_group_lane_mut(flurry_group* g, flurry_attribute a, int component,
                                    float** data, size_t* count, size_t* stride) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    need(stride, "stride");
    const flurry::Attribute at = attribute(a);
    checkLane(group(g), at, component);
    const std::span<float> s = group(g).lane(at, component);
    *data = s.data();
    *count = s.size();
    *stride = sizeof(float);
  });
}
flurry_status flurry_group_ids(const flurry_group* g, const uint32_t** data, size_t* count,
                               size_t* stride) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    need(stride, "stride");
    const std::span<const std::uint32_t> s = group(g).ids();
    *data = s.data();
    *count = s.size();
    *stride = sizeof(std::uint32_t);
  });
}
flurry_status flurry_group_visible(const flurry_group* g, const uint32_t** data, size_t* count,
                                   size_t* stride) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    need(stride, "stride");
    if (!group(g).attributes().has(flurry::Attribute::Visible))
      throw Failure{FLURRY_ERROR_NOT_STORED,
                    "group '" + group(g).name() + "' does not store visible (no Block action)"};
    const std::span<const std::uint32_t> s = group(g).visible();
    *data = s.data();
    *count = s.size();
    *stride = sizeof(std::uint32_t);
  });
}
flurry_status flurry_group_bounds(const flurry_group* g, float min[3], float max[3], int* empty) {
  return guard([&] {
    need(g, "group");
    need(min, "min");
    need(max, "max");
    need(empty, "empty");
    const flurry::Bounds b = group(g).bounds();
    for (int k = 0; k < 3; ++k) min[k] = b.min[k], max[k] = b.max[k];
    *empty = b.empty ? 1 : 0;
  });
}
// The C event is the C++ one, field for field: deaths() is handed out without a copy.
static_assert(sizeof(flurry_death_event) == sizeof(flurry::DeathEvent));
static_assert(offsetof(flurry_death_event, id) == offsetof(flurry::DeathEvent, id));
static_assert(offsetof(flurry_death_event, time) == offsetof(flurry::DeathEvent, time));
static_assert(FLURRY_DEATH_NON_FINITE == flurry::DeathEvent::kNonFinite);
flurry_status flurry_group_add_death_emitter(flurry_group* g, const char* text) {
  return guard([&] {
    need(g, "group");
    need(text, "json");
    group(g).addDeathEmitter(
        flurry::detail::parseEffectDeathEmitter(text, "", "deathEmitter", loadOptions()));
  });
}
flurry_status flurry_group_record_deaths(flurry_group* g, size_t perStep) {
  return guard([&] {
    need(g, "group");
    group(g).recordDeaths(perStep);
  });
}
flurry_status flurry_group_deaths(const flurry_group* g, const flurry_death_event** events,
                                  size_t* count, uint64_t* dropped) {
  return guard([&] {
    need(g, "group");
    need(events, "events");
    need(count, "count");
    const std::span<const flurry::DeathEvent> d = group(g).deaths();
    *events = reinterpret_cast<const flurry_death_event*>(d.data());
    *count = d.size();
    if (dropped) *dropped = group(g).stats().deathEventsDropped;
  });
}
static_assert(sizeof(flurry_collision_event) == sizeof(flurry::CollisionEvent));
static_assert(offsetof(flurry_collision_event, normal) == offsetof(flurry::CollisionEvent, normal));
static_assert(offsetof(flurry_collision_event, id) == offsetof(flurry::CollisionEvent, id));
static_assert(offsetof(flurry_collision_event, reserved) ==
              offsetof(flurry::CollisionEvent, reserved));
static_assert(offsetof(flurry_collision_event, time) == offsetof(flurry::CollisionEvent, time));
flurry_status flurry_group_record_collisions(flurry_group* g, size_t perStep) {
  return guard([&] {
    need(g, "group");
    group(g).recordCollisions(perStep);
  });
}
flurry_status flurry_group_collisions(const flurry_group* g, const flurry_collision_event** events,
                                      size_t* count, uint64_t* dropped) {
  return guard([&] {
    need(g, "group");
    need(events, "events");
    need(count, "count");
    const std::span<const flurry::CollisionEvent> c = group(g).collisions();
    *events = reinterpret_cast<const flurry_collision_event*>(c.data());
    *count = c.size();
    if (dropped) *dropped = group(g).stats().collisionEventsDropped;
  });
}
flurry_status flurry_group_stats_get(const flurry_group* g, flurry_group_stats* out) {
  return guard([&] {
    need(g, "group");
    need(out, "stats");
    const flurry::GroupStats& s = group(g).stats();
    out->emitted = s.emitted;
    out->killed_by_age = s.killedByAge;
    out->absorbed = s.absorbed;
    out->dropped_at_capacity = s.droppedAtCapacity;
    out->killed_non_finite = s.killedNonFinite;
    out->emitters_spawned = s.emittersSpawned;
    out->emitters_dropped = s.emittersDropped;
    out->idle_steps = s.idleSteps;
    out->block_actions_culled = s.blockActionsCulled;
    out->emit_seconds = s.stepSeconds.emit;
    out->act_seconds = s.stepSeconds.act;
    out->compact_seconds = s.stepSeconds.compact;
    out->dropped_at_budget = s.droppedAtBudget;
    out->killed_by_budget = s.killedByBudget;
  });
}
flurry_status flurry_group_killed_by_action(const flurry_group* g, const uint64_t** data,
                                            size_t* count) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    const std::vector<std::uint64_t>& v = group(g).stats().killedByAction;
    *data = v.data();
    *count = v.size();
  });
}
flurry_status flurry_group_emitted_by_generation(const flurry_group* g, const uint64_t** data,
                                                 size_t* count) {
  return guard([&] {
    need(g, "group");
    need(data, "data");
    need(count, "count");
    const std::vector<std::uint64_t>& v = group(g).stats().emittedByGeneration;
    *data = v.data();
    *count = v.size();
  });
}

// ---- packed vertex data ---------------------------------------------------------------------

flurry_status flurry_group_require_instances(flurry_group* g) {
  return guard([&] {
    need(g, "group");
    group(g).require(flurry::PackLayout::instances().attributes());
  });
}
flurry_status flurry_group_pack_instances(const flurry_group* g, void* out, size_t capacity_bytes,
                                          const float eye[3], size_t* written) {
  return guard([&] {
    need(g, "group");
    need(written, "written");
    *written = 0;
    if (capacity_bytes > 0) need(out, "out");
    static_assert(FLURRY_INSTANCE_STRIDE == 32);
    const flurry::PackLayout layout = flurry::PackLayout::instances();
    flurry::PackOptions options;
    if (eye) options.sortFromEye = flurry::Vec3(eye[0], eye[1], eye[2]);
    *written = flurry::packParticles(
        group(g), layout, std::span<std::byte>(static_cast<std::byte*>(out), capacity_bytes),
        options);
  });
}

flurry_status flurry_group_set_trail(flurry_group* g, const flurry_trail_options* o) {
  return guard([&] {
    need(g, "group");
    need(o, "options");
    group(g).setTrail({o->length, o->width, o->taper, o->fade});
  });
}

flurry_status flurry_group_pack_trails(const flurry_group* g, float* out, size_t capacityVertices,
                                       uint32_t* starts, size_t capacityStarts, size_t* vertices,
                                       size_t* strands) {
  return guard([&] {
    need(g, "group");
    need(vertices, "vertices");
    need(strands, "strands");
    *vertices = *strands = 0;
    thread_local flurry::Strands scratch;  // grown once, reused every frame
    flurry::trailStrands(group(g), scratch);
    const std::size_t v = scratch.vertexCount(), s = scratch.size();
    if (v > capacityVertices)
      throw flurry::InvalidArgument(
          "capacity_vertices",
          "holds " + std::to_string(capacityVertices) + ", " + std::to_string(v) + " needed");
    if (s + 1 > capacityStarts)
      throw flurry::InvalidArgument(
          "capacity_starts",
          "holds " + std::to_string(capacityStarts) + ", " + std::to_string(s + 1) + " needed");
    if (v > 0) need(out, "out");
    need(starts, "starts");
    static_assert(FLURRY_INSTANCE_STRIDE == 8 * sizeof(float));
    for (std::size_t i = 0; i < v; ++i) {
      float* r = out + 8 * i;
      const flurry::Vec3 p = scratch.position[i];
      const flurry::Vec4 c = scratch.color[i];
      r[0] = p.x, r[1] = p.y, r[2] = p.z, r[3] = scratch.radius[i];
      r[4] = c.r, r[5] = c.g, r[6] = c.b, r[7] = c.a;
    }
    std::copy(scratch.start.begin(), scratch.start.end(), starts);
    *vertices = v;
    *strands = s;
  });
}

// ---- OpenVDB --------------------------------------------------------------------------------

int flurry_has_vdb(void) {
#ifdef FLURRY_C_HAS_VDB
  return 1;
#else
  return 0;
#endif
}
flurry_status flurry_group_write_vdb(const flurry_group* g, const char* path) {
  return guard([&] {
    need(g, "group");
    need(path, "path");
#ifdef FLURRY_C_HAS_VDB
    flurry::vdb::writeFile(path, group(g));
#else
    throw Failure{FLURRY_ERROR_NOT_BUILT,
                  "VDB export: this build of Flurry has no OpenVDB exporter (FLURRY_VDB=OFF)"};
#endif
  });
}

}  // extern "C"
