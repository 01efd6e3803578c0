#include <algorithm>
#include <cmath>

#include "effect/check_fields.hpp"
#include "emission_plan.hpp"
#include "flurry/emitter.hpp"
#include "flurry/error.hpp"
#include "kernel_compat.hpp"

namespace flurry {

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

// Each field against its descriptor (effect/check_fields.hpp), then what no single field
// says.

void DeathEmitter::validate(const std::string& where) const {
  if (source.empty()) throw InvalidArgument(where + ".source", "names no group");
  desc::checkFields(*this, where);
  if (count.center < 0) throw InvalidArgument(where + ".count", "must be >= 0");
  if (count.center + count.spread > 1e6f)
    throw InvalidArgument(where + ".count", "more than a million newborns a death");
  if (on == Trigger::Birth && cause != -1)
    throw InvalidArgument(where + ".cause",
                          "a birth has no cause: -1 (births emit whatever kills)");
  Emitter e;  // the types are an emitter's
  e.types = types;
  e.validate(where);
}

namespace {
// What an emitter and a prime emitter share beyond their fields: when and along what path.
template <class E>
void checkCounting(const E& e, const std::string& where) {
  auto fail = [&](const std::string& field, const std::string& why) {
    throw InvalidArgument(where + "." + field, why);
  };
  if (std::isnan(e.stop) || e.stop < e.start) fail("stop", "must be >= start");
  for (std::size_t i = 0; i < e.bursts.size(); ++i)
    if (e.bursts[i].repeat > 1 && e.bursts[i].interval <= 0)
      fail("bursts[" + std::to_string(i) + "].interval", "must be > 0 to repeat");
  for (std::size_t i = 1; i < e.path.size(); ++i)
    if (e.path[i].time <= e.path[i - 1].time)
      fail("path[" + std::to_string(i) + "].time", "keyframe times must increase");
  if (e.pathLoop && e.path.size() < 2) fail("pathLoop", "a looping path needs at least two keys");
}
}  // namespace

void Emitter::validate(const std::string& where) const {
  desc::checkFields(*this, where);
  checkCounting(*this, where);
  if (types.empty())
    throw InvalidArgument(where + ".types", "an emitter needs at least one particle type");
  double total = 0;
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i].lifetime.center <= 0)
      throw InvalidArgument(where + ".types[" + std::to_string(i) + "].lifetime", "must be > 0");
    total += types[i].weight;
  }
  if (!(total > 0)) throw InvalidArgument(where + ".types", "the weights add up to 0");
}

void EmitterSpec::validate(const std::string& where) const {
  desc::checkFields(*this, where);
  emitter.validate(where + ".emitter");
  if (lifetime.center <= 0) throw InvalidArgument(where + ".lifetime", "must be > 0");
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
  desc::checkFields(*this, where);
  checkCounting(*this, where);
  child.validate(where + ".child");
}

}  // namespace flurry
