// Validation from the descriptors (descriptors.hpp): each field of a described struct against
// its Limit, parts and lists of parts field by field, so that a field's valid values are
// stated once, beside its name, unit and doc, for validation, the reader, the schema and the
// docs. What no single field says (stop >= start, a key order) stays with each validate().
// Internal: not installed.
#pragma once

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "effect/descriptors.hpp"
#include "flurry/error.hpp"

namespace flurry::desc {

inline std::string numberText(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

/// What a number refused by `l` must be.
inline std::string limitText(const Limit& l) {
  const bool low = l.min > -kInf, high = l.max < kInf;
  const std::string min = numberText(l.min);
  if (low && high)
    return "must be in " + std::string(l.minOpen ? "(" : "[") + min + ", " + numberText(l.max) +
           "]";
  const std::string above = (l.minOpen ? "> " : ">= ") + min;
  if (low)
    return l.infinite ? "must be " + above + " (infinity: no limit)"
                      : "must be finite and " + above;
  return "not finite";
}

/// Throws InvalidArgument(path, limitText(l)) unless `l` lets x in.
inline void checkNumber(double x, const Limit& l, const std::string& path) {
  bool ok = std::isfinite(x) || (l.infinite && x > 0);
  if (l.min > -kInf) ok = ok && (l.minOpen ? x > l.min : x >= l.min);
  if (l.max < kInf) ok = ok && x <= l.max;
  if (!ok) throw InvalidArgument(path, limitText(l));
}

template <class T>
struct IsVector : std::false_type {};
template <class T>
struct IsVector<std::vector<T>> : std::true_type {};

/// Checks every field of `x` (at JSON path `path`) against its descriptor; throws
/// InvalidArgument naming the first refused one ("actions[2].Vortex.coreRadius").
template <class S>
void checkFields(const S& x, const std::string& path) {
  forEachField<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    const T& v = x.*f.member;
    const std::string at = path + "." + f.name;
    if constexpr (Described<T>) {
      checkFields(v, at);  // a part: its own fields' limits
    } else if constexpr (IsVector<T>::value) {
      if constexpr (Described<typename T::value_type>)
        for (std::size_t i = 0; i < v.size(); ++i)
          checkFields(v[i], at + "[" + std::to_string(i) + "]");
    } else if constexpr (requires { v.validate(at.c_str()); }) {
      v.validate(at.c_str());  // a fuzzy value: its own rules
    } else if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (f.limit.checked) checkNumber(double(v), f.limit, at);
    } else if constexpr (std::is_same_v<T, Vec4>) {
      if (f.limit.checked &&
          !(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w)))
        throw InvalidArgument(at, "not finite");
    } else if constexpr (std::is_same_v<T, Vec3>) {
      if (!f.limit.checked) return;
      if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)))
        throw InvalidArgument(at, "not finite");
      if (f.limit.nonZero && !(v.x * v.x + v.y * v.y + v.z * v.z > 0))
        throw InvalidArgument(at, "zero length");
      const auto min = float(f.limit.min);
      if (f.limit.min > -kInf && !(v.x >= min && v.y >= min && v.z >= min))
        throw InvalidArgument(at, "must be >= " + numberText(f.limit.min));
    } else if constexpr (NamedEnum<T>) {
      std::string names;
      for (const auto& [name, value] : EnumNames<T>::values) {
        if (value == v) return;
        names += (names.empty() ? "" : ", ") + std::string(name);
      }
      throw InvalidArgument(at, "must be one of " + names);
    }
  });
}

}  // namespace flurry::desc
