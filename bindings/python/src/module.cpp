// flurry._flurry: the Python module's native part (nanobind). The pure-Python package
// flurry/__init__.py builds effects from keyword arguments on top of it.
//
// Attribute arrays are numpy views of the group's lanes, never copies. A lane is one
// allocation of the group's capacity that a step never moves, so a view stays valid while the
// group's attribute set stays as it is; the only Python call that changes it, Group.require,
// refuses while views of the group are alive. A view holds a reference to the Context, so
// the storage outlives it whatever Python drops first.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "builtin.hpp"
#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "flurry/transform.hpp"
#include "flurry/version.hpp"
#ifdef FLURRY_PY_RENDER
#include "flurry/render.hpp"
#endif
#ifdef FLURRY_PY_VDB
#include "flurry/vdb.hpp"
#endif

namespace nb = nanobind;
using namespace nb::literals;

namespace {

namespace fs = std::filesystem;

// Python exception types, created at import (see NB_MODULE).
PyObject* pyError = nullptr;
PyObject* pyInvalidArgument = nullptr;
PyObject* pyEffectError = nullptr;
PyObject* pyIoError = nullptr;
PyObject* pyRenderError = nullptr;

void raise(PyObject* type, const char* what,
           std::initializer_list<std::pair<const char*, std::string>> attrs) {
  // Messages name files: a path need not be UTF-8, so undecodable bytes are replaced.
  PyObject* exc = PyObject_CallFunction(
      type, "N", PyUnicode_DecodeUTF8(what, Py_ssize_t(std::strlen(what)), "replace"));
  if (!exc) return;  // the call set its own error
  for (const auto& [name, value] : attrs) {
    PyObject* v = PyUnicode_DecodeUTF8(value.data(), Py_ssize_t(value.size()), "replace");
    if (v) PyObject_SetAttrString(exc, name, v);
    Py_XDECREF(v);
  }
  PyErr_SetObject(type, exc);
  Py_DECREF(exc);
}

struct ContextBox {
  std::unique_ptr<flurry::Context> ctx;
  // Live numpy views per group (all, writable).
  std::map<const flurry::Group*, std::pair<int, int>> views;
};

// The owner of a numpy view: keeps the Context alive and counts the group's views.
struct ViewOwner {
  nb::object context;
  ContextBox* pc;
  const flurry::Group* group;
  bool writable;
  ~ViewOwner() {
    auto& [all, writes] = pc->views[group];
    --all;
    if (writable) --writes;
  }
};

struct GroupRef {
  nb::object context;  // the Python Context: keeps the group alive
  ContextBox* pc;
  flurry::Group* g;
};

// A transform from Python values: position (x, y, z), rotation as a unit quaternion
// (w, x, y, z), uniform scale.
flurry::Transform transformOf(const std::array<float, 3>& p, const std::array<float, 4>& q,
                              float scale) {
  flurry::Transform t;
  t.position = flurry::Vec3(p[0], p[1], p[2]);
  t.rotation = glm::quat(q[0], q[1], q[2], q[3]);
  t.scale = scale;
  return t;
}

nb::dict transformDict(const flurry::Transform& t) {
  nb::dict d;
  d["position"] = std::array<float, 3>{t.position.x, t.position.y, t.position.z};
  d["rotation"] = std::array<float, 4>{t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z};
  d["scale"] = t.scale;
  return d;
}

flurry::Space spaceOf(const std::string& name) {
  if (name == "world") return flurry::Space::World;
  if (name == "local") return flurry::Space::Local;
  throw flurry::InvalidArgument("space", "must be \"world\" or \"local\", not \"" + name + "\"");
}

// An effect instance (Effect.instantiate): its groups, placed and prewarmed together.
struct InstanceRef {
  nb::object context;  // the Python Context: keeps the groups alive
  ContextBox* pc;
  flurry::EffectInstance instance;
};

flurry::Attribute attributeOf(const std::string& name) {
  flurry::Attribute a{};
  if (!flurry::attributeFromName(name, a)) {
    std::string names;
    for (int i = 0; i < int(flurry::Attribute::Count); ++i)
      names += (i ? ", " : "") + std::string(flurry::attributeName(flurry::Attribute(i)));
    throw flurry::InvalidArgument("attribute",
                                  "unknown attribute \"" + name + "\" (" + names + ")");
  }
  return a;
}

nb::object viewOf(const GroupRef& pg, const void* data, std::size_t n, bool writable, bool u32) {
  auto* owner = new ViewOwner{pg.context, pg.pc, pg.g, writable};
  auto& [all, writes] = pg.pc->views[pg.g];
  ++all;
  if (writable) ++writes;
  nb::capsule cap(owner, [](void* p) noexcept { delete static_cast<ViewOwner*>(p); });
  const std::size_t shape[1] = {n};
  void* ptr = const_cast<void*>(data);
  if (u32)
    return nb::ndarray<nb::numpy, const std::uint32_t, nb::ndim<1>>(ptr, 1, shape, cap).cast();
  if (writable) return nb::ndarray<nb::numpy, float, nb::ndim<1>>(ptr, 1, shape, cap).cast();
  return nb::ndarray<nb::numpy, const float, nb::ndim<1>>(ptr, 1, shape, cap).cast();
}

nb::object lane(const GroupRef& pg, const std::string& name, int component, bool writable) {
  const flurry::Attribute a = attributeOf(name);
  if (a == flurry::Attribute::Id || a == flurry::Attribute::Visible) {
    if (writable)
      throw flurry::InvalidArgument("writable", name + " is maintained by the group: read-only");
    if (component != 0)
      throw flurry::InvalidArgument("component", "attribute " + name + " has 1 components");
    const flurry::Group& g = *pg.g;
    auto s = a == flurry::Attribute::Id ? g.ids() : g.visible();
    return viewOf(pg, s.data(), s.size(), false, true);
  }
  if (writable) {
    std::span<float> s = pg.g->lane(a, component);  // marks the host copy changed
    return viewOf(pg, s.data(), s.size(), true, false);
  }
  std::span<const float> s = std::as_const(*pg.g).lane(a, component);
  return viewOf(pg, s.data(), s.size(), false, false);
}

// A numpy array that owns `values` (moved into its capsule): for copies the caller keeps.
template <class T>
nb::object owned(std::vector<T> values, std::initializer_list<std::size_t> shape) {
  auto* v = new std::vector<T>(std::move(values));
  nb::capsule cap(v, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(v->data(), shape.size(), shape.begin(), cap).cast();
}

// Strands (hair, trails) as numpy arrays, copied: position (v, 3), color (v, 4), radius (v,),
// start (strands + 1,).
nb::dict strandArrays(const flurry::Strands& s) {
  const std::size_t n = s.vertexCount();
  std::vector<float> pos(n * 3), col(s.color.size() * 4);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) pos[i * 3 + c] = s.position[i][c];
  for (std::size_t i = 0; i < s.color.size(); ++i)
    for (int c = 0; c < 4; ++c) col[i * 4 + c] = s.color[i][c];
  nb::dict d;
  d["position"] = owned(std::move(pos), {n, 3});
  d["color"] = owned(std::move(col), {s.color.size(), 4});
  d["radius"] = owned(s.radius, {s.radius.size()});
  d["start"] = owned(s.start, {s.start.size()});
  return d;
}

// A step's events (deaths, collisions) as numpy arrays, copied: the next step replaces them.
// Each has a position, a velocity, an id, an action and a time; a collision a normal too.
template <class Event>
nb::dict eventArrays(std::span<const Event> d) {
  constexpr bool hasNormal = requires(const Event& e) {
    e.normal;
  };
  const std::size_t n = d.size();
  std::vector<float> pos(n * 3), vel(n * 3), nrm(hasNormal ? n * 3 : 0);
  std::vector<std::uint32_t> id(n), action(n);
  std::vector<double> time(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      pos[i * 3 + c] = d[i].position[c];
      vel[i * 3 + c] = d[i].velocity[c];
      if constexpr (hasNormal) nrm[i * 3 + c] = d[i].normal[c];
    }
    id[i] = d[i].id, action[i] = d[i].action, time[i] = d[i].time;
  }
  nb::dict out;
  out["position"] = owned(std::move(pos), {n, 3});
  out["velocity"] = owned(std::move(vel), {n, 3});
  if constexpr (hasNormal) out["normal"] = owned(std::move(nrm), {n, 3});
  out["id"] = owned(std::move(id), {n});
  out["action"] = owned(std::move(action), {n});
  out["time"] = owned(std::move(time), {n});
  return out;
}

std::vector<std::string> attributeNames(flurry::AttributeSet set) {
  std::vector<std::string> out;
  for (int i = 0; i < int(flurry::Attribute::Count); ++i)
    if (set.has(flurry::Attribute(i)))
      out.emplace_back(flurry::attributeName(flurry::Attribute(i)));
  return out;
}

flurry::EffectLoadOptions loadOptions() {
  flurry::EffectLoadOptions o;
#ifdef FLURRY_PY_VDB
  o.fieldResolver = [](const fs::path& file, const std::string& grid) {
    return flurry::vdb::readVectorField(file, grid);
  };
#endif
#ifdef FLURRY_PY_RENDER
  o.renderChecker = [](std::string_view render, const fs::path& baseDir) {
    flurry::parseRenderSettings(render, baseDir);
  };
#endif
  return o;
}

flurry::Backend backendOf(const std::string& name) {
  if (name == "cpu") return flurry::Backend::Cpu;
  if (name == "opencl") return flurry::Backend::OpenCL;
  if (name == "auto") return flurry::Backend::Auto;
  throw flurry::InvalidArgument("backend", "\"" + name + "\" is not cpu, opencl or auto");
}

const char* backendName(flurry::Backend b) {
  return b == flurry::Backend::OpenCL ? "opencl" : b == flurry::Backend::Auto ? "auto" : "cpu";
}

void step(ContextBox& pc, std::size_t steps) {
  const bool device = pc.ctx->backend() == flurry::Backend::OpenCL;
  for (std::size_t i = 0; i < steps; ++i) {
    // A device backend keeps the particles on the device: writes through writable views go
    // to it before the step, and live views get the step's values back after it. Groups
    // without views pay nothing.
    if (device)
      for (flurry::Group* g : pc.ctx->groups())
        if (pc.views[g].second > 0) g->lane(flurry::Attribute::Position);
    {
      nb::gil_scoped_release release;
      pc.ctx->step();
    }
    if (device)
      for (flurry::Group* g : pc.ctx->groups())
        if (pc.views[g].first > 0) std::as_const(*g).ids();
  }
}

// A Bounds as Python sees it: None when nothing lives, else ((min x, y, z), (max x, y, z)).
nb::object boundsOf(const flurry::Bounds& b) {
  if (b.empty) return nb::none();
  return nb::make_tuple(nb::make_tuple(b.min.x, b.min.y, b.min.z),
                        nb::make_tuple(b.max.x, b.max.y, b.max.z));
}

}  // namespace

NB_MODULE(_flurry, m) {
  m.doc() = "Flurry particle systems: the native part (use the flurry package)";
  m.attr("__version__") = std::to_string(flurry::kVersionMajor) + "." +
                          std::to_string(flurry::kVersionMinor) + "." +
                          std::to_string(flurry::kVersionPatch);

  // flurry.Error derives from RuntimeError; InvalidArgument also from ValueError; EffectError
  // from InvalidArgument; IoError also from OSError; RenderError from Error.
  pyError = PyErr_NewException("flurry.Error", PyExc_RuntimeError, nullptr);
  pyInvalidArgument = PyErr_NewException(
      "flurry.InvalidArgument",
      nb::make_tuple(nb::handle(pyError), nb::handle(PyExc_ValueError)).release().ptr(), nullptr);
  pyEffectError = PyErr_NewException("flurry.EffectError", pyInvalidArgument, nullptr);
  pyIoError = PyErr_NewException(
      "flurry.IoError",
      nb::make_tuple(nb::handle(pyError), nb::handle(PyExc_OSError)).release().ptr(), nullptr);
  pyRenderError = PyErr_NewException("flurry.RenderError", pyError, nullptr);
  m.attr("Error") = nb::handle(pyError);
  m.attr("InvalidArgument") = nb::handle(pyInvalidArgument);
  m.attr("EffectError") = nb::handle(pyEffectError);
  m.attr("IoError") = nb::handle(pyIoError);
  m.attr("RenderError") = nb::handle(pyRenderError);
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const flurry::EffectError& e) {
      raise(
          pyEffectError, e.what(),
          {{"file", e.file()}, {"path", e.path()}, {"why", e.why()}, {"parameter", e.parameter()}});
    } catch (const flurry::InvalidArgument& e) {
      raise(pyInvalidArgument, e.what(), {{"parameter", e.parameter()}});
    } catch (const flurry::IoError& e) {
      raise(pyIoError, e.what(), {{"path", e.path()}});
#ifdef FLURRY_PY_RENDER
    } catch (const flurry::RenderError& e) {
      raise(pyRenderError, e.what(), {});
#endif
    } catch (const flurry::Error& e) {
      raise(pyError, e.what(), {});
    }
  });

  nb::class_<flurry::GroupStats>(m, "GroupStats", "Where a group's particles went (GroupStats).")
      .def_ro("emitted", &flurry::GroupStats::emitted)
      .def_ro("killed_by_age", &flurry::GroupStats::killedByAge)
      .def_ro("absorbed", &flurry::GroupStats::absorbed)
      .def_ro("dropped_at_capacity", &flurry::GroupStats::droppedAtCapacity)
      .def_ro("killed_non_finite", &flurry::GroupStats::killedNonFinite)
      .def_ro("killed_by_action", &flurry::GroupStats::killedByAction)
      .def_ro("emitted_by_generation", &flurry::GroupStats::emittedByGeneration)
      .def_ro("emitters_spawned", &flurry::GroupStats::emittersSpawned)
      .def_ro("emitters_dropped", &flurry::GroupStats::emittersDropped)
      .def_ro("idle_steps", &flurry::GroupStats::idleSteps)
      .def_ro("block_actions_culled", &flurry::GroupStats::blockActionsCulled)
      .def_ro("death_events_dropped", &flurry::GroupStats::deathEventsDropped)
      .def_ro("collision_events_dropped", &flurry::GroupStats::collisionEventsDropped)
      .def_ro("dropped_at_budget", &flurry::GroupStats::droppedAtBudget)
      .def_ro("killed_by_budget", &flurry::GroupStats::killedByBudget)
      .def("__repr__", [](const flurry::GroupStats& s) {
        return "GroupStats(emitted=" + std::to_string(s.emitted) +
               ", killed_by_age=" + std::to_string(s.killedByAge) +
               ", absorbed=" + std::to_string(s.absorbed) +
               ", dropped_at_capacity=" + std::to_string(s.droppedAtCapacity) +
               ", killed_non_finite=" + std::to_string(s.killedNonFinite) + ")";
      });

  nb::class_<flurry::ContextStats>(m, "ContextStats",
                                   "What a game's overlay shows, summed over the groups "
                                   "(Context.stats).")
      .def_ro("groups", &flurry::ContextStats::groups)
      .def_ro("instances", &flurry::ContextStats::instances)
      .def_ro("particles", &flurry::ContextStats::particles)
      .def_ro("capacity", &flurry::ContextStats::capacity)
      .def_ro("last_step_seconds", &flurry::ContextStats::lastStepSeconds)
      .def_prop_ro("last_step_emit_seconds",
                   [](const flurry::ContextStats& s) { return s.lastStepParts.emit; })
      .def_prop_ro("last_step_act_seconds",
                   [](const flurry::ContextStats& s) { return s.lastStepParts.act; })
      .def_prop_ro("last_step_compact_seconds",
                   [](const flurry::ContextStats& s) { return s.lastStepParts.compact; })
      .def_ro("emitted", &flurry::ContextStats::emitted)
      .def_ro("dropped_at_capacity", &flurry::ContextStats::droppedAtCapacity)
      .def_ro("death_events_dropped", &flurry::ContextStats::deathEventsDropped)
      .def_ro("collision_events_dropped", &flurry::ContextStats::collisionEventsDropped)
      .def_ro("idle_steps", &flurry::ContextStats::idleSteps)
      .def_ro("dropped_at_budget", &flurry::ContextStats::droppedAtBudget)
      .def_ro("killed_by_budget", &flurry::ContextStats::killedByBudget);

  nb::class_<GroupRef>(m, "Group", "A particle group of a Context (it keeps its Context alive).")
      .def_prop_ro("name", [](const GroupRef& g) { return g.g->name(); })
      .def("__len__", [](const GroupRef& g) { return g.g->size(); })
      .def_prop_ro(
          "size", [](const GroupRef& g) { return g.g->size(); }, "Live particles.")
      .def_prop_ro("capacity", [](const GroupRef& g) { return g.g->capacity(); })
      .def_prop_ro(
          "attributes", [](const GroupRef& g) { return attributeNames(g.g->attributes()); },
          "Names of the attributes the group stores.")
      .def_prop_ro(
          "stats", [](const GroupRef& g) { return std::as_const(*g.g).stats(); },
          "A copy of the group's statistics now.")
      .def_prop_ro(
          "live_views", [](const GroupRef& g) { return g.pc->views[g.g].first; },
          "numpy views of this group's lanes still alive.")
      .def("lane", &lane,
           nb::sig("def lane(self, attribute: str, component: int = 0, writable: bool = False) "
                   "-> numpy.ndarray"),
           "attribute"_a, "component"_a = 0, "writable"_a = false,
           "A numpy view (no copy) of one component of an attribute, size() long: float32, or "
           "uint32 for id and visible (always read-only). writable=True allows writing; the "
           "next step sees what was written.")
      .def(
          "require",
          [](GroupRef& pg, const std::vector<std::string>& names) {
            flurry::AttributeSet set;
            for (const auto& n : names) set.insert(attributeOf(n));
            if (pg.g->attributes().contains(set)) return;
            // Adding lanes may free others: views would dangle.
            if (int live = pg.pc->views[pg.g].first; live > 0)
              throw flurry::Error("group '" + pg.g->name() + "' has " + std::to_string(live) +
                                  " live attribute views; delete them before require() changes "
                                  "its storage");
            pg.g->require(set);
          },
          "attributes"_a, "Asks the group to store these attributes too (for a reader).")
      .def(
          "strands",
          // Copies: a strand store grows (and reallocates) as steps add strands.
          [](const GroupRef& pg) { return strandArrays(pg.g->strands()); },
          "Hair mode's strands, copied: position (v, 3), color (v, 4), radius (v,), and start "
          "(strands + 1,): strand k is vertices start[k]:start[k+1].")
      .def(
          "set_trail",
          [](GroupRef& pg, std::uint32_t length, float width, float taper, float fade) {
            pg.g->setTrail({length, width, taper, fade});
          },
          "length"_a, "width"_a = 0.0f, "taper"_a = 1.0f, "fade"_a = 0.0f,
          "Keeps each particle's last `length` positions (0: none; at most 256) for ribbons: "
          "`width` their radius at the particle (0: its size), narrowing to `taper` times it "
          "and fading to `fade` times its alpha at the oldest point. CPU backend only.")
      .def(
          "trail",
          [](const GroupRef& pg, std::size_t i) {
            std::vector<flurry::Vec3> points(flurry::TrailOptions::kMaxLength);
            points.resize(pg.g->trail(i, points));
            std::vector<float> xyz(points.size() * 3);
            for (std::size_t k = 0; k < points.size(); ++k)
              for (int c = 0; c < 3; ++c) xyz[k * 3 + c] = points[k][c];
            return owned(std::move(xyz), {points.size(), 3});
          },
          "i"_a, "Particle i's trail (set_trail), newest first, as an (n, 3) array.")
      .def(
          "trails",
          [](const GroupRef& pg) {
            flurry::Strands s;
            flurry::trailStrands(*pg.g, s);
            return strandArrays(s);
          },
          "The live particles' trails as ribbons, copied as strands() gives hair: one strand "
          "per particle with two points or more, newest first, radius and alpha along it.")
      .def(
          "bounds", [](const GroupRef& pg) { return boundsOf(pg.g->bounds()); },
          "The live particles' axis-aligned box, ((x, y, z), (x, y, z)), or None when none "
          "lives; once asked, the CPU pass keeps it every step.")
      .def(
          "record_deaths", [](GroupRef& pg, std::size_t perStep) { pg.g->recordDeaths(perStep); },
          "per_step"_a,
          "Records each step's deaths, at most per_step a step (the first in particle order; "
          "the rest counted in stats.death_events_dropped); 0 stops. Both backends.")
      .def(
          "deaths", [](const GroupRef& pg) { return eventArrays(pg.g->deaths()); },
          "The last step's deaths (record_deaths), copied: position (n, 3), velocity (n, 3), "
          "id (n,), action (n,): the index in the action list of what killed it, or "
          "0xFFFFFFFF for a NaN or infinity, and time (n,): the end of the step.")
      .def(
          "record_collisions",
          [](GroupRef& pg, std::size_t perStep) { pg.g->recordCollisions(perStep); }, "per_step"_a,
          "Records each step's collisions (each time a Bounce deflects a particle), at most "
          "per_step a step (the first in particle order; the rest counted in "
          "stats.collision_events_dropped); 0 stops. Both backends.")
      .def(
          "collisions", [](const GroupRef& pg) { return eventArrays(pg.g->collisions()); },
          "The last step's collisions (record_collisions), copied: position (n, 3) of impact, "
          "velocity (n, 3) arriving, normal (n, 3) of the surface on the particle's side, id "
          "(n,), action (n,): the Bounce's index in the action list, and time (n,) of impact.")
      .def(
          "sync", [](GroupRef& pg) { std::as_const(*pg.g).ids(); },
          "Brings the host copy up to date (OpenCL); Context.step does it for groups with views.")
      .def(
          "set_transform",
          [](GroupRef& pg, const std::array<float, 3>& position,
             const std::array<float, 4>& rotation,
             float scale) { pg.g->setTransform(transformOf(position, rotation, scale)); },
          "position"_a = std::array<float, 3>{0, 0, 0},
          "rotation"_a = std::array<float, 4>{1, 0, 0, 0}, "scale"_a = 1.0f,
          "Places the group (its emitters and its actions' geometry follow): rotation is a unit "
          "quaternion (w, x, y, z), scale uniform.")
      .def_prop_ro(
          "transform", [](const GroupRef& pg) { return transformDict(pg.g->transform()); },
          "The group's transform: position, rotation (w, x, y, z), scale.")
      .def_prop_rw(
          "time_scale", [](const GroupRef& pg) { return pg.g->timeScale(); },
          [](GroupRef& pg, double scale) { pg.g->setTimeScale(scale); },
          "How fast the group's clock runs against the context's (0 pauses it).")
      .def(
          "set_seed",
          [](GroupRef& pg, std::uint64_t seed, std::uint32_t stream) {
            pg.g->setSeed(seed, stream);
          },
          "seed"_a, "stream"_a = 0,
          "Draws its random numbers from (seed, stream) instead of the context's seed and its "
          "index.")
      .def_prop_ro(
          "time", [](const GroupRef& pg) { return pg.pc->ctx->time(*pg.g); },
          "The time on its own clock, where its next step starts (the context's unless scaled, "
          "prewarmed or skipping steps).")
      .def_prop_rw(
          "update_interval", [](const GroupRef& pg) { return pg.g->updateInterval(); },
          [](GroupRef& pg, std::uint32_t n) { pg.g->setUpdateInterval(n); },
          "Steps once every this many context steps over the time it skipped (1: every step).")
      .def_prop_rw(
          "budget_policy",
          [](const GroupRef& pg) {
            const char* names[] = {"drop_newest", "drop_oldest", "scale_emission"};
            return std::string(names[int(pg.g->budgetPolicy())]);
          },
          [](GroupRef& pg, const std::string& name) {
            const char* names[] = {"drop_newest", "drop_oldest", "scale_emission"};
            for (int k = 0; k < 3; ++k)
              if (name == names[k]) {
                pg.g->setBudgetPolicy(flurry::BudgetPolicy(k));
                return;
              }
            throw flurry::InvalidArgument("budget_policy", "\"" + name +
                                                               "\" is not drop_newest, drop_oldest "
                                                               "or scale_emission");
          },
          "What the group gives up past its share of the context's particle_budget: "
          "\"drop_newest\" (the default), \"drop_oldest\" or \"scale_emission\".")
      .def_prop_rw(
          "space",
          [](const GroupRef& pg) {
            return std::string(pg.g->space() == flurry::Space::Local ? "local" : "world");
          },
          [](GroupRef& pg, const std::string& space) { pg.g->setSpace(spaceOf(space)); },
          "\"world\": born particles stay where they are when the group moves; \"local\": they "
          "move with it.")
      .def("__repr__", [](const GroupRef& g) {
        return "<flurry.Group '" + g.g->name() + "' " + std::to_string(g.g->size()) + "/" +
               std::to_string(g.g->capacity()) + ">";
      });

  nb::class_<ContextBox>(m, "Context", "Owns groups, the seed, the time step and the backend.")
      .def(
          "__init__",
          [](ContextBox* self, std::uint64_t seed, double dt, unsigned threads,
             const std::string& backend, const std::string& device, bool cull) {
            flurry::ContextOptions o;
            o.seed = seed, o.dt = dt, o.threads = threads, o.backend = backendOf(backend);
            o.device = device, o.cull = cull;
            new (self) ContextBox{std::make_unique<flurry::Context>(o), {}};
          },
          "seed"_a = 1, "dt"_a = 1.0 / 30.0, "threads"_a = 0, "backend"_a = "cpu", "device"_a = "",
          "cull"_a = true)
      .def(
          "step", [](ContextBox& pc, std::size_t steps) { step(pc, steps); }, "steps"_a = 1,
          "Advances every group by `steps` steps (the GIL is released while stepping).")
      .def(
          "group",
          [](nb::handle self, const std::string& name) {
            ContextBox& pc = nb::cast<ContextBox&>(self);
            return GroupRef{nb::borrow(self), &pc, &pc.ctx->group(name)};
          },
          "name"_a)
      .def_prop_ro("groups",
                   [](nb::handle self) {
                     ContextBox& pc = nb::cast<ContextBox&>(self);
                     std::vector<GroupRef> out;
                     for (flurry::Group* g : pc.ctx->groups())
                       out.push_back(GroupRef{nb::borrow(self), &pc, g});
                     return out;
                   })
      .def(
          "create_group",
          [](nb::handle self, std::string name, std::size_t capacity) {
            ContextBox& pc = nb::cast<ContextBox&>(self);
            return GroupRef{nb::borrow(self), &pc, &pc.ctx->createGroup(std::move(name), capacity)};
          },
          "name"_a, "capacity"_a, "An empty group (no emitters, no actions).")
      .def(
          "prewarm",
          [](ContextBox& pc, const std::vector<GroupRef>& groups, double seconds) {
            std::vector<flurry::Group*> gs;
            for (const auto& g : groups) gs.push_back(g.g);
            nb::gil_scoped_release release;
            return pc.ctx->prewarm(gs, seconds);
          },
          "groups"_a, "seconds"_a,
          "Starts the groups as if they had run `seconds` already; returns the steps taken.")
      .def_prop_ro("time", [](const ContextBox& pc) { return pc.ctx->time(); })
      .def_prop_ro("step_index", [](const ContextBox& pc) { return pc.ctx->stepIndex(); })
      .def_prop_rw(
          "dt", [](const ContextBox& pc) { return pc.ctx->timeStep(); },
          [](ContextBox& pc, double dt) { pc.ctx->setTimeStep(dt); })
      .def_prop_ro("seed", [](const ContextBox& pc) { return pc.ctx->seed(); })
      .def_prop_rw(
          "particle_budget", [](const ContextBox& pc) { return pc.ctx->particleBudget(); },
          [](ContextBox& pc, std::size_t n) { pc.ctx->setParticleBudget(n); },
          "The most particles all groups together hold (0: none); each group's budget_policy "
          "says what it gives up past its share. CPU backend only.")
      .def_prop_ro("threads", [](const ContextBox& pc) { return pc.ctx->threads(); })
      .def_prop_ro(
          "stats", [](const ContextBox& pc) { return pc.ctx->stats(); },
          "The groups' statistics summed, and what the last step cost (a snapshot).")
      .def_prop_ro(
          "backend", [](const ContextBox& pc) { return backendName(pc.ctx->backend()); },
          "The backend running: \"cpu\" or \"opencl\".")
      .def_prop_ro(
          "backend_fallback", [](const ContextBox& pc) { return pc.ctx->backendFallback(); },
          "Why backend=\"auto\" took the CPU (empty when it did not).");

  nb::class_<flurry::Effect>(m, "Effect", "A loaded, validated effect (groups, emitters, actions).")
      .def_static(
          "parse",
          [](const std::string& json, const std::string& name, const fs::path& baseDir) {
            flurry::EffectLoadOptions o = loadOptions();
            o.baseDir = baseDir;
            return flurry::parseEffect(json, name, o);
          },
          "json"_a, "name"_a = "<python>", "base_dir"_a = fs::path(),
          "Parses an effect from JSON text; errors name `name` and the JSON path.")
      .def_static(
          "load", [](const fs::path& file) { return flurry::loadEffect(file, loadOptions()); },
          "file"_a)
      .def_static(
          "builtin",
          [](const std::string& name) {
            const flurry::samples::Sample* s = flurry::samples::findSample(name);
            if (!s) return flurry::samples::loadEffectOrSample(name, loadOptions());  // says why
            return flurry::parseEffect(s->json, s->file, loadOptions());
          },
          "name"_a, "A built-in effect (samples/effects/NAME.json, embedded).")
      .def_ro("name", &flurry::Effect::name)
      .def_ro("description", &flurry::Effect::description)
      .def_ro("dt", &flurry::Effect::dt)
      .def_ro("seed", &flurry::Effect::seed)
      .def_ro("frames", &flurry::Effect::frames)
      .def_ro("render", &flurry::Effect::render, "The `render` object as JSON text.")
      .def_prop_ro("file", [](const flurry::Effect& e) { return e.file.string(); })
      .def_prop_ro("group_names",
                   [](const flurry::Effect& e) {
                     std::vector<std::string> out;
                     for (const auto& g : e.groups) out.push_back(g.name);
                     return out;
                   })
      .def_prop_ro("warnings",
                   [](const flurry::Effect& e) {
                     std::vector<std::string> out;
                     for (const auto& w : e.warnings) out.push_back(w.message());
                     return out;
                   })
      .def("scale_spawning", &flurry::Effect::scaleSpawning, "factor"_a,
           "Scales every emitter's rate, bursts and births by distance, the showers of prime "
           "emitters, and the capacities, by `factor` (> 0): a quality knob.")
      .def(
          "build",
          [](const flurry::Effect& e, nb::handle context, std::size_t maxCapacity) {
            ContextBox& pc = nb::cast<ContextBox&>(context);
            std::vector<GroupRef> out;
            for (flurry::Group* g : e.build(*pc.ctx, maxCapacity))
              out.push_back(GroupRef{nb::borrow(context), &pc, g});
            return out;
          },
          "context"_a, "max_capacity"_a = 0,
          "Creates the effect's groups in `context`; max_capacity > 0 caps every group.")
      .def(
          "instantiate",
          [](const flurry::Effect& e, nb::handle context, const std::string& name,
             std::size_t maxCapacity) {
            ContextBox& pc = nb::cast<ContextBox&>(context);
            return InstanceRef{nb::borrow(context), &pc, e.instantiate(*pc.ctx, name, maxCapacity)};
          },
          "context"_a, "name"_a, "max_capacity"_a = 0,
          "Builds the effect as an instance named `name` (groups GROUP@name) to place and "
          "prewarm.");

  nb::class_<InstanceRef>(m, "EffectInstance", "One effect built into a Context, placed as one.")
      .def_prop_ro("groups",
                   [](const InstanceRef& pi) {
                     std::vector<GroupRef> out;
                     for (flurry::Group* g : pi.instance.groups())
                       out.push_back(GroupRef{pi.context, pi.pc, g});
                     return out;
                   })
      .def(
          "set_transform",
          [](InstanceRef& pi, const std::array<float, 3>& position,
             const std::array<float, 4>& rotation,
             float scale) { pi.instance.setTransform(transformOf(position, rotation, scale)); },
          "position"_a = std::array<float, 3>{0, 0, 0},
          "rotation"_a = std::array<float, 4>{1, 0, 0, 0}, "scale"_a = 1.0f,
          "Places every group of the instance, all or none.")
      .def(
          "prewarm",
          [](InstanceRef& pi, double seconds) {
            nb::gil_scoped_release release;
            return pi.instance.prewarm(seconds);
          },
          "seconds"_a, "Starts the instance as if it had run `seconds`; returns the steps taken.")
      .def(
          "bounds", [](const InstanceRef& pi) { return boundsOf(pi.instance.bounds()); },
          "The union of its groups' bounds, or None when no particle lives.")
      .def(
          "stop", [](InstanceRef& pi) { pi.instance.stop(); },
          "Stops emitting now: the live particles live out their lives.")
      .def(
          "kill", [](InstanceRef& pi) { pi.instance.kill(); },
          "Stops emitting and removes every particle at once (the groups stay).")
      .def(
          "restart", [](InstanceRef& pi) { pi.instance.restart(); },
          "Starts it over now: everything removed, its emitters as the effect built them.")
      .def_prop_ro(
          "done", [](const InstanceRef& pi) { return pi.instance.done(); },
          "True when nothing of it lives and nothing can be born again.")
      .def_prop_rw(
          "time_scale", [](const InstanceRef& pi) { return pi.instance.timeScale(); },
          [](InstanceRef& pi, double scale) { pi.instance.setTimeScale(scale); },
          "How fast the instance runs against the context's time (0 pauses it).")
      .def(
          "set_update_interval",
          [](InstanceRef& pi, std::uint32_t interval) { pi.instance.setUpdateInterval(interval); },
          "interval"_a,
          "Steps it once every `interval` context steps, catching up each time (out of sight).")
      .def(
          "set_seed", [](InstanceRef& pi, std::uint64_t seed) { pi.instance.setSeed(seed); },
          "seed"_a,
          "Gives the instance its own random numbers: instances with one seed look alike.");

  m.def(
      "load",
      [](const fs::path& nameOrPath) {  // a path: any bytes the file system allows
        return flurry::samples::loadEffectOrSample(nameOrPath.string(), loadOptions());
      },
      "name_or_path"_a,
      "An effect file by path (an existing file, or a name ending in .json or holding a /), "
      "else a built-in effect by name (builtin_effects()).");
  m.def(
      "builtin_effects",
      [] {
        std::vector<std::string> out;
        for (const auto& s : flurry::samples::builtinSamples()) out.push_back(s.name);
        return out;
      },
      "Names of the built-in effects.");
  m.def(
      "cpu_instruction_set", [] { return std::string(flurry::cpuInstructionSet()); },
      "The build the CPU backend runs here: 'avx512', 'avx2' or 'baseline' (SSE2), the widest "
      "the CPU has (FLURRY_ISA picks a narrower one).");

#ifdef FLURRY_PY_VDB
  m.attr("has_vdb") = true;
  m.def(
      "write_vdb",
      [](const fs::path& path, const GroupRef& g, bool fog, bool points, float fogVoxelSize,
         float pointsVoxelSize, float density, bool keepHidden) {
        flurry::vdb::ExportOptions o;
        o.fog = fog, o.points = points, o.fogVoxelSize = fogVoxelSize;
        o.pointsVoxelSize = pointsVoxelSize, o.density = density, o.keepHidden = keepHidden;
        flurry::vdb::FileStats s;
        {
          nb::gil_scoped_release release;
          s = flurry::vdb::writeFile(path, *g.g, o);
        }
        nb::dict d;
        d["path"] = s.path.string(), d["bytes"] = s.bytes, d["points"] = s.points;
        d["fog_voxels"] = s.fogVoxels, d["fog_voxel_size"] = s.fogVoxelSize;
        d["points_voxel_size"] = s.pointsVoxelSize, d["mass"] = s.mass;
        return d;
      },
      "path"_a, "group"_a, "fog"_a = true, "points"_a = true, "fog_voxel_size"_a = 0.0f,
      "points_voxel_size"_a = 0.0f, "density"_a = 1.0f, "keep_hidden"_a = false,
      "Writes the group's visible particles as an OpenVDB file (fog volume and points); "
      "returns what was written.");
#else
  m.attr("has_vdb") = false;
#endif

#ifdef FLURRY_PY_RENDER
  m.attr("has_render") = true;
  struct RendererBox {
    flurry::OffscreenRenderer r;
  };
  nb::class_<RendererBox>(m, "Renderer",
                          "Offscreen renderer (OpenGL 3.3; starts Xvfb when there is no display).")
      .def(
          "__init__",
          [](RendererBox* self, int width, int height, const std::string& settings, int samples) {
            flurry::OffscreenOptions o;
            o.width = width, o.height = height, o.samples = samples;
            new (self)
                RendererBox{flurry::OffscreenRenderer(o, flurry::parseRenderSettings(settings))};
          },
          "width"_a = 640, "height"_a = 360, "settings"_a = "{}", "samples"_a = 4,
          "settings: an effect's `render` object as JSON text (Effect.render).")
      .def_static(
          "attributes", [] { return attributeNames(flurry::Renderer::attributes()); },
          "What rendering reads: Group.require() them before stepping.")
      .def(
          "render",
          [](RendererBox& pr, const std::vector<GroupRef>& groups) {
            std::vector<const flurry::Group*> gs;
            for (const auto& g : groups) gs.push_back(g.g);
            auto* image = new flurry::Image(pr.r.render(gs));
            nb::capsule cap(image, [](void* p) noexcept { delete static_cast<flurry::Image*>(p); });
            const std::size_t shape[3] = {std::size_t(image->height), std::size_t(image->width), 4};
            return nb::ndarray<nb::numpy, std::uint8_t, nb::ndim<3>>(image->rgba.data(), 3, shape,
                                                                     cap);
          },
          "groups"_a, "An (height, width, 4) uint8 RGBA image, rows top to bottom.")
      .def_prop_ro("gl_info", [](const RendererBox& pr) { return pr.r.glInfo(); });
#else
  m.attr("has_render") = false;
#endif
}
