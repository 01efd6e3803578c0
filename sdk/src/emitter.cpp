#include <algorithm>
#include <cmath>

#include "emission_plan.hpp"
#include "flurry/emitter.hpp"
#include "flurry/error.hpp"
#include "kernel_compat.hpp"

namespace flurry {

namespace {
bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
}  // namespace

namespace detail {
Vec3 pathPositionAt(Vec3 position, Vec3 velocity, double start, const std::vector<Keyframe>& path,
                    bool loop, double t, std::size_t& key) {
  // kernels/path.h: the device's motion too.
  if (path.empty()) return kernel::fl_path_linear(position, velocity, start, t);
  if (loop && t > path.back().time)
    t = kernel::fl_path_wrap(t, path.front().time, path.back().time);
  if (t <= path.front().time) return path.front().position;
  if (t >= path.back().time) return path.back().position;
  // The first key later than t (1 <= key < size, as t is inside the path): a short walk on
  // from the last one found when t is not before it, else a binary search. Times increase,
  // so both find the same key.
  const auto later = [](double x, const Keyframe& k) { return x < k.time; };
  std::size_t b = key;
  if (b == 0 || b >= path.size() || t < path[b - 1].time) {
    b = std::size_t(std::upper_bound(path.begin(), path.end(), t, later) - path.begin());
  } else {
    for (int walked = 0; !(t < path[b].time); ++b)
      if (++walked > 8) {
        b = std::size_t(std::upper_bound(path.begin() + std::ptrdiff_t(b), path.end(), t, later) -
                        path.begin());
        break;
      }
  }
  key = b;
  return kernel::fl_path_between(t, path[b - 1].time, path[b - 1].position, path[b].time,
                                 path[b].position);
}
}  // namespace detail

Vec3 Emitter::positionAt(double t) const {
  std::size_t key = 0;  // no hint: a binary search
  return detail::pathPositionAt(position, velocity, start, path, pathLoop, t, key);
}

void DeathEmitter::validate(const std::string& where) const {
  if (source.empty()) throw InvalidArgument(where + ".source", "names no group");
  count.validate((where + ".count").c_str());
  if (count.center < 0) throw InvalidArgument(where + ".count", "must be >= 0");
  if (count.center + count.spread > 1e6f)
    throw InvalidArgument(where + ".count", "more than a million newborns a death");
  if (!std::isfinite(inheritVelocity))
    throw InvalidArgument(where + ".inheritVelocity", "not finite");
  if (cause < -1) throw InvalidArgument(where + ".cause", "must be an action's index or -1");
  if (on == Trigger::Birth && cause != -1)
    throw InvalidArgument(where + ".cause",
                          "a birth has no cause: -1 (births emit whatever kills)");
  Emitter e;  // the types are an emitter's
  e.types = types;
  e.validate(where);
}

void Emitter::validate(const std::string& where) const {
  auto fail = [&](const std::string& field, const std::string& why) {
    throw InvalidArgument(where + "." + field, why);
  };
  if (!std::isfinite(rate) || rate < 0) fail("rate", "must be finite and >= 0");
  if (!finite(position)) fail("position", "not finite");
  if (!finite(velocity)) fail("velocity", "not finite");
  if (!std::isfinite(start)) fail("start", "not finite");
  if (std::isnan(stop) || stop < start) fail("stop", "must be >= start");
  for (std::size_t i = 0; i < bursts.size(); ++i) {
    const Burst& b = bursts[i];
    const std::string f = "bursts[" + std::to_string(i) + "]";
    if (!std::isfinite(b.time)) fail(f + ".time", "not finite");
    if (!std::isfinite(b.interval) || b.interval < 0) fail(f + ".interval", "must be >= 0");
    if (b.repeat > 1 && b.interval <= 0) fail(f + ".interval", "must be > 0 to repeat");
  }
  for (std::size_t i = 0; i < path.size(); ++i) {
    const std::string f = "path[" + std::to_string(i) + "]";
    if (!std::isfinite(path[i].time) || !finite(path[i].position)) fail(f, "not finite");
    if (i > 0 && path[i].time <= path[i - 1].time)
      fail(f + ".time", "keyframe times must increase");
  }
  if (pathLoop && path.size() < 2) fail("pathLoop", "a looping path needs at least two keys");
  if (types.empty()) fail("types", "an emitter needs at least one particle type");
  double total = 0;
  for (std::size_t i = 0; i < types.size(); ++i) {
    const ParticleType& t = types[i];
    const std::string f = "types[" + std::to_string(i) + "]";
    if (!std::isfinite(t.weight) || t.weight < 0) fail(f + ".weight", "must be finite and >= 0");
    total += t.weight;
    const std::string fs[] = {f + ".alpha", f + ".size", f + ".mass", f + ".lifetime",
                              f + ".charge"};
    const Fuzzy* vals[] = {&t.alpha, &t.size, &t.mass, &t.lifetime, &t.charge};
    for (int k = 0; k < 5; ++k) vals[k]->validate((where + "." + fs[k]).c_str());
    if (t.lifetime.center <= 0) fail(f + ".lifetime", "must be > 0");
  }
  if (!(total > 0)) fail("types", "the weights add up to 0");
  if (!std::isfinite(spacing) || spacing < 0) fail("spacing", "must be finite and >= 0");
  normalSpeed.validate((where + ".normalSpeed").c_str());
}

void EmitterSpec::validate(const std::string& where) const {
  emitter.validate(where + ".emitter");
  lifetime.validate((where + ".lifetime").c_str());
  if (lifetime.center <= 0) throw InvalidArgument(where + ".lifetime", "must be > 0");
  if (!finite(acceleration)) throw InvalidArgument(where + ".acceleration", "not finite");
  if (!std::isfinite(drag) || drag < 0) throw InvalidArgument(where + ".drag", "must be >= 0");
  if (!std::isfinite(inheritVelocity))
    throw InvalidArgument(where + ".inheritVelocity", "not finite");
  if (deathChildren > 0 && !next)
    throw InvalidArgument(where + ".next", "deathChildren > 0 needs a next level");
  // Showers of showers, but not forever: a cycle of levels would never end.
  int depth = 0;
  for (const EmitterSpec* s = next.get(); s; s = s->next.get())
    if (++depth > 16) throw InvalidArgument(where + ".next", "more than 16 levels (a cycle?)");
  if (next) next->validate(where + ".next");
}

Vec3 PrimeEmitter::positionAt(double t) const {
  std::size_t key = 0;
  return detail::pathPositionAt(position, velocity, start, path, pathLoop, t, key);
}

void PrimeEmitter::validate(const std::string& where) const {
  Emitter e;  // the counting and motion fields are an emitter's
  e.rate = rate;
  e.bursts = bursts;
  e.position = position;
  e.velocity = velocity;
  e.path = path;
  e.pathLoop = pathLoop;
  e.start = start;
  e.stop = stop;
  e.validate(where);
  if (maxEmitters < 1) throw InvalidArgument(where + ".maxEmitters", "must be >= 1");
  child.validate(where + ".child");
}

}  // namespace flurry
