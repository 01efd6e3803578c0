// The effect writer's JSON for each value type, and for any described struct (descriptors.hpp):
// saveEffect and the schema and docs generator (effect_docs.cpp) share it. Internal.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "effect/descriptors.hpp"
#include "flurry/field.hpp"

namespace flurry::jsonio {

using ojson = nlohmann::ordered_json;

/// The writer's overloads take this first, so that the templates below find every overload by
/// argument-dependent lookup, wherever it is declared.
struct Writer {};

/// A float as the shortest decimal that the loader (a double, then rounded to float) reads
/// back to the same float; "inf" for an infinity (validation lets no NaN in).
inline ojson write(Writer, float f) {
  if (std::isinf(f)) return f > 0 ? "inf" : "-inf";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  double d = 0;
  std::from_chars(buf, r.ptr, d);
  return float(d) == f ? d : double(f);
}
inline ojson write(Writer, double d) {
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  return d;
}
inline ojson write(Writer, bool b) {
  return b;
}
inline ojson write(Writer, int i) {
  return i;
}
inline ojson write(Writer, std::uint32_t i) {
  return i;
}
inline ojson write(Writer, const std::string& s) {
  return s;
}
inline ojson write(Writer w, Vec3 v) {
  return {write(w, v.x), write(w, v.y), write(w, v.z)};
}
inline ojson write(Writer w, Vec4 v) {
  return {write(w, v.r), write(w, v.g), write(w, v.b), write(w, v.a)};
}

inline ojson write(Writer w, const Fuzzy& f) {
  if (f.distribution == Fuzzy::Distribution::Normal) {
    ojson o = ojson::object();
    o["center"] = write(w, f.center);
    o["spread"] = write(w, f.spread);
    o["distribution"] = "normal";
    return o;
  }
  if (f.spread == 0.0f) return write(w, f.center);
  return {write(w, f.center), write(w, f.spread)};
}

template <class S>
inline void writeFields(Writer w, ojson& o, const S& s);

/// A point as [x, y, z]; a mesh and a union by hand (they hold lists); the rest by descriptor.
inline ojson write(Writer w, const Domain& d) {
  const Domain::Shape& s = d.shape();
  if (const auto* p = std::get_if<PointDomain>(&s)) return write(w, p->p);
  ojson o = ojson::object();
  o["type"] = d.name();
  if (std::visit(
          [&](const auto& x) {
            using S = std::decay_t<decltype(x)>;
            if constexpr (desc::Described<S>) writeFields(w, o, x);
            return desc::Described<S>;
          },
          s)) {
    return o;
  }
  if (const auto* x = std::get_if<MeshDomain>(&s)) {
    ojson vs = ojson::array(), ts = ojson::array();
    for (const Vec3& v : x->mesh->vertices) vs.push_back(write(w, v));
    for (const glm::uvec3& t : x->mesh->triangles) ts.push_back({t.x, t.y, t.z});
    o["vertices"] = std::move(vs), o["triangles"] = std::move(ts);
  } else if (const auto* x = std::get_if<UnionDomain>(&s)) {
    ojson ps = ojson::array();
    for (const Domain& part : x->parts->parts) ps.push_back(write(w, part));
    o["parts"] = std::move(ps);
  }
  return o;
}

/// A sampled field inline (a dense grid), wherever it was read from.
inline ojson write(Writer w, const std::shared_ptr<const VectorField>& f) {
  if (!f) return nullptr;
  ojson o = ojson::object();
  o["origin"] = write(w, f->origin);
  o["voxelSize"] = write(w, f->voxelSize);
  o["dims"] = {f->dims.x, f->dims.y, f->dims.z};
  ojson data = ojson::array();
  for (const Vec3& v : f->data) data.push_back(write(w, v));
  o["data"] = std::move(data);
  return o;
}

template <desc::NamedEnum E>
inline ojson write(Writer, E e) {
  for (const auto& [n, val] : desc::EnumNames<E>::values)
    if (val == e) return n;
  return nullptr;  // not a value of E: the loader would refuse it too
}

template <class T>
inline ojson write(Writer w, const std::vector<T>& v) {
  ojson a = ojson::array();
  for (const T& x : v) a.push_back(write(w, x));
  return a;
}

/// A described struct's fields into `o`, each field left out where it equals the default
/// (a default-constructed S), unless it is required.
template <class S>
inline void writeFields(Writer w, ojson& o, const S& s) {
  const S def{};
  desc::forEachField<S>([&](const auto& f) {
    ojson v = write(w, s.*f.member);
    if (f.required || v != write(w, def.*f.member)) o[f.name] = std::move(v);
  });
}

template <desc::Described S>
inline ojson write(Writer w, const S& s) {
  ojson o = ojson::object();
  writeFields(w, o, s);
  return o;
}

inline ojson write(Writer w, const std::shared_ptr<const EmitterSpec>& s) {
  return s ? write(w, *s) : ojson(nullptr);
}

/// Pretty JSON with arrays of plain values ([x, y, z]) kept on one line.
inline void print(const ojson& j, std::string& out, int indent) {
  const std::string pad(std::size_t(indent + 2), ' ');
  if (j.is_object() && !j.empty()) {
    out += "{\n";
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      out += (first ? "" : ",\n") + pad + ojson(it.key()).dump() + ": ";
      print(it.value(), out, indent + 2);
      first = false;
    }
    out += "\n" + std::string(std::size_t(indent), ' ') + "}";
  } else if (j.is_array() && !j.empty()) {
    auto scalars = [](const ojson& a) {
      return std::none_of(a.begin(), a.end(), [](const ojson& x) { return x.is_structured(); });
    };
    // Inline: [x, y, z], and short lists of them ([[0, 1, 2], [0, 2, 3]]).
    const bool flat =
        scalars(j) || (j.size() <= 8 && std::all_of(j.begin(), j.end(), [&](const ojson& e) {
                         return e.is_array() && scalars(e);
                       }));
    if (flat) {
      out += "[";
      for (std::size_t i = 0; i < j.size(); ++i) {
        if (i) out += ", ";
        print(j[i], out, indent);
      }
      out += "]";
      return;
    }
    out += "[\n";
    for (std::size_t i = 0; i < j.size(); ++i) {
      out += (i ? ",\n" : "") + pad;
      print(j[i], out, indent + 2);
    }
    out += "\n" + std::string(std::size_t(indent), ' ') + "]";
  } else {
    out += j.dump();
  }
}

}  // namespace flurry::jsonio
