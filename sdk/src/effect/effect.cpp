// The effect-file loader: JSON (nlohmann) to an Effect, validating every field as it goes so
// that an error names the file, the JSON path of the bad field and why. Unknown fields are
// errors with a suggestion: a typo must not silently become a default.
#include "flurry/effect.hpp"

#include "effect/descriptors.hpp"
#include "effect/effect_parts.hpp"
#include "effect/obj_mesh.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>

namespace flurry {

EffectError::EffectError(std::string file, std::string path, std::string why)
    : InvalidArgument(std::move(path), why), file_(std::move(file)), why_(std::move(why)) {
  message_ = file_;
  if (!parameter().empty()) message_ += (message_.empty() ? "" : ": ") + parameter();
  message_ += (message_.empty() ? "" : ": ") + why_;
}

bool attributeFromName(std::string_view name, Attribute& out) {
  for (int i = 0; i < int(Attribute::Count); ++i)
    if (attributeName(Attribute(i)) == name) {
      out = Attribute(i);
      return true;
    }
  return false;
}

namespace {

using json = nlohmann::json;

constexpr int kMaxDepth = 24;  // nested next levels and unions
constexpr std::size_t kMaxCapacity = std::size_t(1) << 30;
constexpr std::size_t kMaxInlineSamples = std::size_t(1) << 24;  // dense fields, mesh vertices

// ---- small helpers --------------------------------------------------------------------------

std::string byteCount(std::size_t n) {
  if (n >= (std::size_t(1) << 20) && n % (std::size_t(1) << 20) == 0)
    return std::to_string(n >> 20) + " MiB";
  return std::to_string(n) + " bytes";
}

std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same =
          std::tolower((unsigned char)a[i - 1]) == std::tolower((unsigned char)b[j - 1]);
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

/// "; did you mean "x"?" for the nearest candidate, if it is near enough to be a typo.
std::string suggestion(std::string_view got, const std::vector<std::string>& candidates) {
  const std::string* best = nullptr;
  std::size_t bestD = std::numeric_limits<std::size_t>::max();
  for (const std::string& c : candidates) {
    const std::size_t d = editDistance(got, c);
    if (d < bestD) bestD = d, best = &c;
  }
  if (!best) return {};
  const std::size_t limit = std::max<std::size_t>(2, std::min(got.size(), best->size()) / 3);
  return bestD <= limit ? "; did you mean \"" + *best + "\"?" : std::string();
}

std::string kindOf(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

using detail::index;
using detail::join;

/// Effect and group names become parts of output file names (fountain.0010.ply): keep them
/// to characters that are safe in any file system and cannot climb out of a folder.
bool safeName(std::string_view s) {
  if (s.empty() || s.size() > 128 || s[0] == '.' || s[0] == '-') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum((unsigned char)c) || c == '_' || c == '-' || c == '.';
  });
}
constexpr const char* kNameRule =
    "must be 1 to 128 letters, digits, '_', '-' or '.', not starting with '.' or '-'";

/// Nesting depth of a JSON value, without recursion (the render object is kept as text, and
/// nlohmann's serializer recurses).
std::size_t depthOf(const json& root) {
  std::size_t deepest = 0;
  std::vector<std::pair<const json*, std::size_t>> stack{{&root, 1}};
  while (!stack.empty()) {
    const auto [j, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    if (j->is_structured())
      for (const json& c : *j) stack.emplace_back(&c, d + 1);
  }
  return deepest;
}

/// The loader's state: which file, how to reach external data, how deep we are.
struct Loader {
  std::string file;
  const EffectLoadOptions* options;
  mutable int depth = 0;  // nesting of next levels and unions, bounded against deep input

  [[noreturn]] void fail(const std::string& path, const std::string& why) const {
    throw EffectError(file, path, why);
  }

  /// Rethrows a core InvalidArgument as an EffectError. `path` is the JSON path of the object
  /// that was validated; the core's parameter is rewritten to a path under it where it can be.
  [[noreturn]] void rethrow(const std::string& path, const InvalidArgument& e,
                            std::string_view corePrefix = {}) const {
    const std::string& p = e.parameter();
    std::string why = e.what();
    if (why.size() > p.size() + 2 && why.compare(0, p.size(), p) == 0)
      why = why.substr(p.size() + 2);
    if (!corePrefix.empty() && p.compare(0, corePrefix.size(), corePrefix) == 0) {
      // The core named the field relative to the object: "sphere.outerRadius" ->
      // "shape.outerRadius".
      std::string rest = p.substr(corePrefix.size());
      if (!rest.empty() && rest[0] == '.') rest = rest.substr(1);
      fail(rest.empty() ? path : join(path, rest), why);
    }
    if (corePrefix.empty() && p.compare(0, path.size(), path) == 0) fail(p, why);
    fail(path, p.empty() ? why : p + ": " + why);
  }
};

/// An object being read: records the keys asked for, so that finish() can report any other
/// key as unknown, with the nearest known name.
class Obj {
 public:
  Obj(const json& j, std::string path, const Loader& L) : j_(j), path_(std::move(path)), L_(L) {
    if (!j.is_object()) L.fail(path_, "expected an object, got " + kindOf(j));
  }
  const std::string& path() const { return path_; }
  std::string at(const char* key) const { return join(path_, key); }
  const Loader& loader() const { return L_; }

  /// The value of `key`, or null if absent (absent and null are the same: the default).
  const json* get(const char* key) {
    known_.emplace_back(key);
    const auto it = j_.find(key);
    if (it == j_.end() || it->is_null()) return nullptr;
    return &*it;
  }
  bool has(const char* key) const {
    const auto it = j_.find(key);
    return it != j_.end() && !it->is_null();
  }
  const json& require(const char* key, const char* what = nullptr) {
    const json* v = get(key);
    if (!v) L_.fail(at(key), what ? std::string("missing (") + what + ")" : "missing (required)");
    return *v;
  }
  template <class T>
  void opt(const char* key, T& out);
  template <class T>
  void req(const char* key, T& out, const char* what = nullptr);

  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      const std::string& k = it.key();
      if (k == "$comment") continue;  // documentation inside the file
      if (std::find(known_.begin(), known_.end(), k) != known_.end()) continue;
      L_.fail(join(path_, k), "unknown field" + suggestion(k, known_));
    }
  }

 private:
  const json& j_;
  std::string path_;
  const Loader& L_;
  std::vector<std::string> known_;
};

// ---- values ---------------------------------------------------------------------------------

double readNumber(const json& j, const std::string& path, const Loader& L, bool allowInf) {
  if (j.is_string() && allowInf) {
    const auto& s = j.get_ref<const std::string&>();
    if (s == "inf" || s == "infinity") return std::numeric_limits<double>::infinity();
    if (s == "-inf" || s == "-infinity") return -std::numeric_limits<double>::infinity();
    L.fail(path, "expected a number or \"inf\", got the string \"" + s + "\"");
  }
  if (!j.is_number()) L.fail(path, "expected a number, got " + kindOf(j));
  const double v = j.get<double>();
  if (!std::isfinite(v)) L.fail(path, "not finite");
  return v;
}

void read(const json& j, const std::string& path, const Loader& L, double& out) {
  out = readNumber(j, path, L, true);
}
void read(const json& j, const std::string& path, const Loader& L, float& out) {
  const double v = readNumber(j, path, L, true);
  if (std::isfinite(v) && std::abs(v) > double(std::numeric_limits<float>::max()))
    L.fail(path, "out of range for a float");
  out = float(v);
}
void read(const json& j, const std::string& path, const Loader& L, bool& out) {
  if (!j.is_boolean()) L.fail(path, "expected true or false, got " + kindOf(j));
  out = j.get<bool>();
}
void read(const json& j, const std::string& path, const Loader& L, std::string& out) {
  if (!j.is_string()) L.fail(path, "expected a string, got " + kindOf(j));
  out = j.get<std::string>();
}

/// An integer in [lo, hi]; a float is accepted when it is integral (1e3).
std::uint64_t readInteger(const json& j, const std::string& path, const Loader& L, std::uint64_t lo,
                          std::uint64_t hi) {
  const std::string range =
      "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!j.is_number()) L.fail(path, "expected " + range + ", got " + kindOf(j));
  std::uint64_t v = 0;
  if (j.is_number_unsigned()) {
    v = j.get<std::uint64_t>();
  } else if (j.is_number_integer()) {
    const std::int64_t s = j.get<std::int64_t>();
    if (s < 0) L.fail(path, "must be " + range);
    v = std::uint64_t(s);
  } else {
    const double d = j.get<double>();
    if (!std::isfinite(d) || d != std::floor(d) || d < 0 || d >= 18446744073709551616.0)
      L.fail(path, "must be " + range);
    v = std::uint64_t(d);
  }
  if (v < lo || v > hi) L.fail(path, "must be " + range);
  return v;
}

void read(const json& j, const std::string& path, const Loader& L, std::uint32_t& out) {
  out = std::uint32_t(readInteger(j, path, L, 0, 0xFFFFFFFFu));
}
void read(const json& j, const std::string& path, const Loader& L, int& out) {
  // Signed: a field's own validation says which values it takes (DeathEmitter.cause: -1).
  if (j.is_number_integer() && !j.is_number_unsigned() && j.get<std::int64_t>() < 0) {
    const std::int64_t v = j.get<std::int64_t>();
    if (v < std::numeric_limits<int>::min())
      L.fail(path, "must be an integer in [" + std::to_string(std::numeric_limits<int>::min()) +
                       ", " + std::to_string(std::numeric_limits<int>::max()) + "]");
    out = int(v);
    return;
  }
  out = int(readInteger(j, path, L, 0, std::numeric_limits<int>::max()));
}
void read(const json& j, const std::string& path, const Loader& L, std::uint64_t& out) {
  out = readInteger(j, path, L, 0, std::numeric_limits<std::uint64_t>::max());
}

const json& arrayOf(const json& j, const std::string& path, const Loader& L, std::size_t n,
                    const char* what) {
  if (!j.is_array() || (n && j.size() != n))
    L.fail(path, std::string("expected ") + what + ", got " +
                     (j.is_array() ? "an array of " + std::to_string(j.size()) : kindOf(j)));
  return j;
}

void read(const json& j, const std::string& path, const Loader& L, Vec3& out) {
  arrayOf(j, path, L, 3, "[x, y, z]");
  for (int i = 0; i < 3; ++i) read(j[std::size_t(i)], index(path, i), L, out[i]);
}

void read(const json& j, const std::string& path, const Loader& L, Vec4& out) {
  if (!j.is_array() || (j.size() != 3 && j.size() != 4))
    L.fail(path, "expected [r, g, b] or [r, g, b, a], got " +
                     (j.is_array() ? "an array of " + std::to_string(j.size()) : kindOf(j)));
  out.w = 1.0f;
  for (std::size_t i = 0; i < j.size(); ++i) read(j[i], index(path, i), L, out[int(i)]);
}

template <class T>
void Obj::opt(const char* key, T& out) {
  if (const json* v = get(key)) read(*v, at(key), L_, out);
}
template <class T>
void Obj::req(const char* key, T& out, const char* what) {
  read(require(key, what), at(key), L_, out);
}

/// Reads a described struct's fields (desc::Describe<S>) into `out`, which holds its
/// defaults: each field in descriptor order, required ones named when missing.
template <class S>
void readFields(Obj& o, S& out) {
  desc::forEachField<S>([&](const auto& f) {
    if (f.required)
      o.req(f.name, out.*f.member, f.required);
    else
      o.opt(f.name, out.*f.member);
  });
}

/// 3, [3, 0.5], {"center": 3, "spread": 0.5 | "percent": 10, "distribution": "normal"}.
void read(const json& j, const std::string& path, const Loader& L, Fuzzy& out) {
  if (j.is_number()) {
    read(j, path, L, out.center);
    out.spread = 0;
  } else if (j.is_array()) {
    arrayOf(j, path, L, 2, "a number, [center, spread] or an object");
    read(j[0], index(path, 0), L, out.center);
    read(j[1], index(path, 1), L, out.spread);
  } else if (j.is_object()) {
    Obj o(j, path, L);
    o.req("center", out.center);
    out.spread = 0;
    o.opt("spread", out.spread);
    if (const json* p = o.get("percent")) {
      if (o.has("spread")) L.fail(o.at("percent"), "give spread or percent, not both");
      float pct = 0;
      read(*p, o.at("percent"), L, pct);
      if (!(pct >= 0)) L.fail(o.at("percent"), "must be >= 0");
      out = Fuzzy::percent(out.center, pct);
    }
    std::string d = "uniform";
    o.opt("distribution", d);
    if (d == "uniform")
      out.distribution = Fuzzy::Distribution::Uniform;
    else if (d == "normal")
      out.distribution = Fuzzy::Distribution::Normal;
    else
      L.fail(o.at("distribution"),
             "expected \"uniform\" or \"normal\"" + suggestion(d, {"uniform", "normal"}));
    o.finish();
  } else {
    L.fail(path, "expected a number, [center, spread] or an object, got " + kindOf(j));
  }
  try {
    out.validate(path.c_str());
  } catch (const InvalidArgument& e) {
    L.rethrow(path, e);
  }
}

struct DepthGuard {
  const Loader& L;
  DepthGuard(const Loader& l, const std::string& path) : L(l) {
    if (++L.depth > kMaxDepth) {
      --L.depth;
      L.fail(path, "nested more than " + std::to_string(kMaxDepth) + " levels deep");
    }
  }
  ~DepthGuard() { --L.depth; }
};

const std::vector<std::string> kDomainTypes = {"point", "line", "triangle", "plane",    "rectangle",
                                               "disc",  "box",  "sphere",   "cylinder", "cone",
                                               "blob",  "mesh", "union"};

Domain readDomain(const json& j, const std::string& path, const Loader& L);

/// {"type": "mesh", "obj": "file.obj"}: a Wavefront OBJ file, relative to the effect file's
/// folder. An error names the field, the file and its line.
Domain readObjDomain(Obj& o) {
  const Loader& L = o.loader();
  std::string file;
  o.req("obj", file);
  if (o.has("vertices") || o.has("triangles"))
    L.fail(o.at("obj"), "give either \"obj\" or \"vertices\" and \"triangles\", not both");
  std::filesystem::path p(file);
  if (p.is_relative() && !L.options->baseDir.empty()) p = L.options->baseDir / p;
  const std::string where = o.at("obj");
  std::error_code ec;
  // A regular file only: a folder cannot be read, and a device (/dev/stdin) may never end.
  const auto st = std::filesystem::status(p, ec);
  if (std::filesystem::is_directory(st)) L.fail(where, p.string() + ": is a directory");
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    L.fail(where, p.string() + ": not a regular file");
  std::ifstream in(p, std::ios::binary);
  if (!in) L.fail(where, p.string() + ": cannot open the file");
  std::string text;
  const std::size_t limit = L.options->maxFileBytes;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, std::size_t(in.gcount()));
    if (text.size() > limit) L.fail(where, p.string() + ": larger than " + byteCount(limit));
  }
  if (in.bad()) L.fail(where, p.string() + ": cannot read the file");
  detail::ObjMesh m;
  try {
    m = detail::parseObj(text, kMaxInlineSamples);
  } catch (const detail::ObjError& e) {
    L.fail(where, p.string() + ":" + std::to_string(e.line()) + ": " + e.why());
  }
  try {
    return Domain::mesh(std::move(m.vertices), std::move(m.triangles));
  } catch (const InvalidArgument& e) {
    // "mesh.triangles[k]": a degenerate face; name the line it came from.
    const std::string& param = e.parameter();
    const std::string prefix = "mesh.triangles[";
    std::size_t k = std::string::npos;
    if (param.compare(0, prefix.size(), prefix) == 0)
      std::from_chars(param.data() + prefix.size(), param.data() + param.size(), k);
    const std::string why = std::string(e.what()).substr(param.size() + 2);
    if (k < m.triangleLines.size())
      L.fail(where, p.string() + ":" + std::to_string(m.triangleLines[k]) + ": " + why);
    L.fail(where, p.string() + ": " + e.what());
  }
}

Domain readDomainObject(Obj& o, const std::string& type) {
  const Loader& L = o.loader();
  std::optional<Domain> described;
  desc::forEachDomainKind([&](auto tag) {
    using S = typename decltype(tag)::type;
    if (described || type != desc::Describe<S>::name) return;
    S s{};  // zeros: a shape's optional fields default to the origin, radius 0
    readFields(o, s);
    described = desc::Describe<S>::make(s);
  });
  if (described) return std::move(*described);
  if (type == "mesh") {
    if (o.get("obj")) return readObjDomain(o);
    const json& vs = o.require("vertices", "[[x, y, z], ...], or \"obj\": a file");
    const std::string vp = o.at("vertices");
    arrayOf(vs, vp, L, 0, "an array of [x, y, z]");
    if (vs.size() > kMaxInlineSamples) L.fail(vp, "too many vertices");
    std::vector<Vec3> vertices(vs.size());
    for (std::size_t i = 0; i < vs.size(); ++i) read(vs[i], index(vp, i), L, vertices[i]);
    const json& ts = o.require("triangles");
    const std::string tp = o.at("triangles");
    arrayOf(ts, tp, L, 0, "an array of [i, j, k]");
    if (ts.size() > kMaxInlineSamples) L.fail(tp, "too many triangles");
    std::vector<glm::uvec3> tris(ts.size());
    for (std::size_t i = 0; i < ts.size(); ++i) {
      arrayOf(ts[i], index(tp, i), L, 3, "[i, j, k]");
      for (int k = 0; k < 3; ++k) {
        const std::string ip = index(index(tp, i), std::size_t(k));
        if (vertices.empty()) L.fail(ip, "the mesh has no vertices");
        tris[i][k] =
            std::uint32_t(readInteger(ts[i][std::size_t(k)], ip, L, 0, vertices.size() - 1));
      }
    }
    return Domain::mesh(std::move(vertices), std::move(tris));
  }
  // union
  const json& ps = o.require("parts");
  const std::string pp = o.at("parts");
  arrayOf(ps, pp, L, 0, "an array of domains");
  if (ps.empty()) L.fail(pp, "a union needs at least one part");
  std::vector<Domain> parts;
  for (std::size_t i = 0; i < ps.size(); ++i) parts.push_back(readDomain(ps[i], index(pp, i), L));
  return Domain::unite(std::move(parts));
}

void read(const json& j, const std::string& path, const Loader& L, Domain& out) {
  out = readDomain(j, path, L);
}

/// [x, y, z] is a point; otherwise {"type": "sphere", ...}.
Domain readDomain(const json& j, const std::string& path, const Loader& L) {
  if (j.is_array()) {
    Vec3 p;
    read(j, path, L, p);
    return Domain::point(p);
  }
  DepthGuard guard(L, path);
  Obj o(j, path, L);
  std::string type;
  o.req("type", type,
        "one of point, line, triangle, plane, rectangle, disc, box, sphere, "
        "cylinder, cone, blob, mesh, union");
  if (std::find(kDomainTypes.begin(), kDomainTypes.end(), type) == kDomainTypes.end())
    L.fail(o.at("type"), "unknown domain \"" + type + "\"" + suggestion(type, kDomainTypes));
  Domain d;
  try {
    d = readDomainObject(o, type);
  } catch (const EffectError&) {
    throw;
  } catch (const InvalidArgument& e) {
    L.rethrow(path, e, type);
  }
  o.finish();
  return d;
}

template <class T, class F>
void readArray(const json& j, const std::string& path, const Loader& L, std::vector<T>& out,
               F&& each) {
  arrayOf(j, path, L, 0, "an array");
  out.clear();
  for (std::size_t i = 0; i < j.size(); ++i) {
    T t{};
    each(j[i], index(path, i), t);
    out.push_back(std::move(t));
  }
}

template <desc::Described S>
void read(const json& j, const std::string& path, const Loader& L, S& out) {
  Obj o(j, path, L);
  readFields(o, out);
  o.finish();
}

template <desc::Described T>
void read(const json& j, const std::string& path, const Loader& L, std::vector<T>& out) {
  readArray(j, path, L, out, [&](const json& e, const std::string& p, T& t) { read(e, p, L, t); });
}

void read(const json& j, const std::string& path, const Loader& L, std::vector<ParticleType>& out) {
  readArray(j, path, L, out,
            [&](const json& e, const std::string& p, ParticleType& t) { read(e, p, L, t); });
  if (out.empty()) L.fail(path, "an emitter needs at least one particle type");
}

template <desc::NamedEnum E>
void read(const json& j, const std::string& path, const Loader& L, E& out) {
  std::string s;
  read(j, path, L, s);
  std::vector<std::string> all;
  std::string list;
  for (const auto& [n, val] : desc::EnumNames<E>::values) {
    if (n == s) {
      out = val;
      return;
    }
    all.emplace_back(n);
    list += (list.empty() ? "" : ", ") + std::string(n);
  }
  L.fail(path, "\"" + s + "\" is not one of " + list + suggestion(s, all));
}

/// A described emitter kind read, then validated by its own validate() at its JSON path.
template <class E>
E readValidated(const json& j, const std::string& path, const Loader& L) {
  E e;
  read(j, path, L, e);
  try {
    e.validate(path);
  } catch (const InvalidArgument& x) {
    L.rethrow(path, x);
  }
  return e;
}

Emitter readEmitter(const json& j, const std::string& path, const Loader& L) {
  return readValidated<Emitter>(j, path, L);
}

/// A prime emitter's levels nest: bounded like domains.
void read(const json& j, const std::string& path, const Loader& L, EmitterSpec& out) {
  DepthGuard guard(L, path);
  Obj o(j, path, L);
  readFields(o, out);
  o.finish();
}
void read(const json& j, const std::string& path, const Loader& L,
          std::shared_ptr<const EmitterSpec>& out) {
  auto s = std::make_shared<EmitterSpec>();
  read(j, path, L, *s);
  out = std::move(s);
}

DeathEmitter readDeathEmitter(const json& j, const std::string& path, const Loader& L) {
  return readValidated<DeathEmitter>(j, path, L);
}

// Death emitters name a group of the effect, and their cause an action of its list as the
// file writes it: a mode2d group's inserted Constrain2D moves the actions after it on by one.
void linkDeathEmitters(Effect& fx, const json& groups, const Loader& L) {
  for (std::size_t i = 0; i < fx.groups.size(); ++i)
    for (std::size_t k = 0; k < fx.groups[i].deathEmitters.size(); ++k) {
      DeathEmitter& de = fx.groups[i].deathEmitters[k];
      const std::string path = index(join(index("groups", i), "deathEmitters"), k);
      std::size_t src = 0;
      std::string names;
      while (src < fx.groups.size() && fx.groups[src].name != de.source)
        names += (names.empty() ? "" : ", ") + fx.groups[src++].name;
      if (src == fx.groups.size())
        L.fail(join(path, "source"),
               "no group named \"" + de.source + "\" in this effect (its groups: " + names + ")");
      if (de.cause < 0) continue;
      const json& g = groups[src];
      const std::size_t written = g.contains("actions") ? g["actions"].size() : 0;
      if (std::size_t(de.cause) >= written)
        L.fail(join(path, "cause"), "group \"" + de.source + "\" has " + std::to_string(written) +
                                        " actions: the cause is one's index, or -1 for all");
      const std::vector<Action>& list = fx.groups[src].actions.actions();
      const std::int32_t asWritten = de.cause;
      if (list.size() == written + 1)  // mode2d inserted its Constrain2D
        for (std::size_t a = 0; a <= std::size_t(de.cause); ++a)
          if (std::holds_alternative<Constrain2D>(list[a])) {
            ++de.cause;
            break;
          }
      if (de.on == DeathEmitter::Trigger::Collision &&
          !std::holds_alternative<Bounce>(list[std::size_t(de.cause)]))
        L.fail(join(path, "cause"), "action " + std::to_string(asWritten) + " of group \"" +
                                        de.source +
                                        "\" is not a Bounce: collisions come from "
                                        "Bounce actions (or -1 for all of them)");
    }
}

PrimeEmitter readPrime(const json& j, const std::string& path, const Loader& L) {
  return readValidated<PrimeEmitter>(j, path, L);
}

// ---- actions --------------------------------------------------------------------------------

/// The actions an effect file can hold, by name (all but Callback).
const std::vector<std::string> kActionTypes = [] {
  std::vector<std::string> names;
  desc::forEachAction(
      [&](auto a) { names.emplace_back(desc::Describe<typename decltype(a)::type>::name); });
  return names;
}();

std::shared_ptr<const VectorField> readField(const json& j, const std::string& path,
                                             const Loader& L) {
  Obj o(j, path, L);
  if (o.has("vdb")) {
    std::string file, grid;
    o.req("vdb", file);
    o.opt("grid", grid);
    o.finish();
    if (!L.options->fieldResolver)
      L.fail(o.at("vdb"), "an OpenVDB field needs flurry::vdb; this program was built without it");
    std::filesystem::path p(file);
    if (p.is_relative() && !L.options->baseDir.empty()) p = L.options->baseDir / p;
    VectorField f;
    try {
      f = L.options->fieldResolver(p, grid);
    } catch (const std::exception& e) {
      L.fail(o.at("vdb"), e.what());
    }
    try {
      f.validate(path.c_str());
    } catch (const InvalidArgument& e) {
      L.rethrow(path, e);
    }
    return std::make_shared<const VectorField>(std::move(f));
  }
  auto f = std::make_shared<VectorField>();
  o.opt("origin", f->origin);
  o.opt("voxelSize", f->voxelSize);
  const json& dims = o.require("dims", "[nx, ny, nz], or \"vdb\": a file");
  arrayOf(dims, o.at("dims"), L, 3, "[nx, ny, nz]");
  std::uint64_t total = 1;
  for (int k = 0; k < 3; ++k) {
    f->dims[k] = int(readInteger(dims[std::size_t(k)], index(o.at("dims"), std::size_t(k)), L, 1,
                                 kMaxInlineSamples));
    total *= std::uint64_t(f->dims[k]);
    if (total > kMaxInlineSamples)
      L.fail(o.at("dims"), "more than " + std::to_string(kMaxInlineSamples) +
                               " samples: keep large fields in a VDB file");
  }
  const json& data = o.require("data", "[[x, y, z], ...], x fastest");
  const std::string dp = o.at("data");
  arrayOf(data, dp, L, 0, "an array of [x, y, z]");
  if (data.size() != total)
    L.fail(dp,
           "has " + std::to_string(data.size()) + " samples; dims need " + std::to_string(total));
  f->data.resize(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) read(data[i], index(dp, i), L, f->data[i]);
  o.finish();
  try {
    f->validate(path.c_str());
  } catch (const InvalidArgument& e) {
    L.rethrow(path, e);
  }
  return f;
}

void read(const json& j, const std::string& path, const Loader& L,
          std::shared_ptr<const VectorField>& out) {
  out = readField(j, path, L);
}

/// The action named `type` (a known name), its fields read from `o` by its descriptor.
Action readActionBody(Obj& o, const std::string& type) {
  std::optional<Action> out;
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    if (out || type != desc::Describe<A>::name) return;
    A a;
    readFields(o, a);
    out = std::move(a);
  });
  return std::move(*out);
}

/// Fails at `typePath` unless `type` names an action an effect file can hold.
void checkActionType(const std::string& type, const std::string& typePath, const Loader& L) {
  if (type == "Callback")
    L.fail(typePath, "a Callback runs C++ code and cannot be described in an effect file");
  if (std::find(kActionTypes.begin(), kActionTypes.end(), type) == kActionTypes.end())
    L.fail(typePath, "unknown action \"" + type + "\"" + suggestion(type, kActionTypes));
}

/// A Sink's deprecated "killInside" (the classic API's switch, once a field beside "mode"):
/// false reads as mode "outside"; with any mode but "inside" it is refused as ambiguous.
void readSinkKillInside(Obj& o, Sink& s) {
  const json* k = o.get("killInside");
  bool inside = true;
  if (k) read(*k, o.at("killInside"), o.loader(), inside);
  if (inside) return;
  if (s.mode != Sink::Mode::Inside)
    o.loader().fail(o.at("killInside"), "deprecated, and contradicts \"mode\": use \"mode\" alone");
  s.mode = Sink::Mode::Outside;
}

Action readAction(const json& j, const std::string& path, const Loader& L) {
  Obj o(j, path, L);
  std::string type;
  o.req("type", type, "the action's name, e.g. \"Gravity\"");
  checkActionType(type, o.at("type"), L);
  Action a = readActionBody(o, type);
  if (auto* s = std::get_if<Sink>(&a)) readSinkKillInside(o, *s);
  o.finish();
  return a;
}

/// Appends `a` (the JSON actions[i]) to `list`, rewriting the core's "actions[i].Name.field"
/// to the JSON path "groups[g].actions[i].field".
void addAction(ActionList& list, const Action& a, const std::string& path, const Loader& L) {
  try {
    list.add(a);
  } catch (const InvalidArgument& e) {
    const std::string prefix = "actions[" + std::to_string(list.size()) + "]." + actionName(a);
    L.rethrow(path, e, prefix);
  }
}

// ---- warnings -------------------------------------------------------------------------------

template <class A>
bool hasAction(const std::vector<Action>& actions) {
  return std::any_of(actions.begin(), actions.end(),
                     [](const Action& a) { return std::holds_alternative<A>(a); });
}

/// Whether an emitter keeps emitting for ever (so a group it fills must also lose particles).
bool emitsForever(const Emitter& e) {
  // A path ends (the emitter then stays put); a velocity moves it for ever.
  return std::isinf(e.stop) && (e.rate > 0 || (e.spacing > 0 && e.velocity != Vec3(0.0f)));
}

/// About how many emitters a prime emitter's showers keep alive at once in steady state:
/// each level lives its mean lifetime, fed by the rate (and the largest burst at once)
/// times the deathChildren of the levels above it.
double liveEmitters(const PrimeEmitter& e) {
  double feed = e.rate, burst = 0.0, live = 0.0;
  for (const Burst& b : e.bursts) burst = std::max(burst, double(b.count));
  int depth = 0;
  for (const EmitterSpec* s = &e.child; s && depth < 64; s = s->next.get(), ++depth) {
    live += feed * std::max(0.0f, s->lifetime.center) + burst;
    feed *= s->deathChildren;
    burst *= s->deathChildren;
  }
  return live;
}

/// Every warning about a group (see EffectWarning): what its file asks for that cannot happen
/// as written. `actions` is its action list in file order (before a 2-D constraint is
/// inserted), so that indices are JSON indices. A new check is one more block here.
void warnGroup(const EffectGroup& g, const std::vector<Action>& actions, const std::string& path,
               std::vector<EffectWarning>& out) {
  const std::string ap = join(path, "actions");
  auto warn = [&](std::string p, std::string why) {
    out.push_back({std::move(p), std::move(why)});
  };
  // Emitters that emit nothing, and groups nothing fills.
  for (std::size_t i = 0; i < g.emitters.size(); ++i) {
    const Emitter& e = g.emitters[i];
    const bool moves = e.velocity != Vec3(0.0f) || e.path.size() >= 2;
    if (e.rate == 0 && e.bursts.empty() && !(e.spacing > 0 && moves))
      warn(index(join(path, "emitters"), i),
           "emits nothing: its rate is 0 and it has no bursts (nor a spacing while it moves)");
  }
  for (std::size_t i = 0; i < g.primeEmitters.size(); ++i) {
    const PrimeEmitter& e = g.primeEmitters[i];
    if (e.rate == 0 && e.bursts.empty())
      warn(index(join(path, "primeEmitters"), i),
           "spawns no emitters: its rate is 0 and it has no bursts");
    const double live = liveEmitters(e);
    if (live > e.maxEmitters)
      warn(index(join(path, "primeEmitters"), i),
           "keeps about " + std::to_string(std::llround(std::min(live, 1e18))) +
               " emitters alive at once (rate and largest burst times each level's lifetime "
               "and deathChildren), more than its maxEmitters of " +
               std::to_string(e.maxEmitters) + ": spawns past it are dropped");
  }
  const bool filled = !g.emitters.empty() || !g.primeEmitters.empty() || !g.deathEmitters.empty();
  if (!filled) {
    warn(path, "has no emitters or prime emitters: the group stays empty");
    return;  // the rest is about what happens to particles
  }
  // Move integrates positions and advances ages: without it nothing moves or ages.
  if (!hasAction<Move>(actions)) {
    warn(ap, "has no Move: particles never move or age");
    for (std::size_t k = 0; k < actions.size(); ++k) {
      const Action& a = actions[k];
      // (Every particle of an effect file has a lifetime: a particle type's default is 5 s.)
      if (std::holds_alternative<KillOld>(a))
        warn(index(ap, k), "never kills: without a Move particles never age");
      else if (std::holds_alternative<ColorOverLife>(a) || std::holds_alternative<SizeOverLife>(a))
        warn(index(ap, k), "stays at its first key: without a Move particles never age");
    }
  }
  // A continuous emitter and nothing that removes particles: the group fills up, then every
  // newborn is dropped. (Hair groups end their strands by themselves.)
  const bool forever =
      std::any_of(g.emitters.begin(), g.emitters.end(), emitsForever) ||
      std::any_of(g.primeEmitters.begin(), g.primeEmitters.end(),
                  [](const PrimeEmitter& e) { return std::isinf(e.stop) && e.rate > 0; });
  if (!g.hair.enabled && forever && !hasAction<KillOld>(actions) && !hasAction<Sink>(actions) &&
      !hasAction<SinkVelocity>(actions))
    warn(ap,
         "nothing removes particles (no KillOld, Sink or SinkVelocity): the group fills to "
         "its capacity of " +
             std::to_string(g.capacity) + " and then drops every newborn");
}

// ---- groups and the effect ------------------------------------------------------------------

EffectGroup readGroup(const json& j, const std::string& path, const Loader& L,
                      const std::vector<EffectGroup>& before,
                      std::vector<EffectWarning>& warnings) {
  Obj o(j, path, L);
  EffectGroup g;
  g.name = "group" + std::to_string(before.size());
  o.opt("name", g.name);
  if (!safeName(g.name)) L.fail(o.at("name"), kNameRule);
  for (const EffectGroup& b : before)
    if (b.name == g.name) L.fail(o.at("name"), "a group named \"" + g.name + "\" already exists");
  g.capacity = std::size_t(readInteger(o.require("capacity", "the most particles the group holds"),
                                       o.at("capacity"), L, 1, kMaxCapacity));
  if (const json* es = o.get("emitters")) {
    arrayOf(*es, o.at("emitters"), L, 0, "an array of emitters");
    for (std::size_t i = 0; i < es->size(); ++i)
      g.emitters.push_back(readEmitter((*es)[i], index(o.at("emitters"), i), L));
  }
  if (const json* ps = o.get("primeEmitters")) {
    arrayOf(*ps, o.at("primeEmitters"), L, 0, "an array of prime emitters");
    for (std::size_t i = 0; i < ps->size(); ++i)
      g.primeEmitters.push_back(readPrime((*ps)[i], index(o.at("primeEmitters"), i), L));
  }
  if (const json* ds = o.get("deathEmitters")) {
    arrayOf(*ds, o.at("deathEmitters"), L, 0, "an array of death emitters");
    for (std::size_t i = 0; i < ds->size(); ++i)
      g.deathEmitters.push_back(readDeathEmitter((*ds)[i], index(o.at("deathEmitters"), i), L));
  }

  // 2-D mode: `true` is the z = 0 plane.
  std::optional<Constrain2D> plane;
  if (const json* m = o.get("mode2d")) {
    const std::string mp = o.at("mode2d");
    if (m->is_boolean()) {
      if (m->get<bool>()) plane = Constrain2D{};
    } else {
      Obj mo(*m, mp, L);
      Constrain2D c;
      mo.opt("point", c.point);
      mo.opt("normal", c.normal);
      mo.finish();
      const float n = glm::length(c.normal);
      if (!(n > 1e-12f) || !std::isfinite(n)) L.fail(mo.at("normal"), "must be a non-zero vector");
      c.normal /= n;
      plane = c;
    }
  }

  ActionList actions;
  std::vector<Action> parsed;
  if (const json* as = o.get("actions")) {
    const std::string ap = o.at("actions");
    arrayOf(*as, ap, L, 0, "an array of actions");
    for (std::size_t i = 0; i < as->size(); ++i) {
      Action a = readAction((*as)[i], index(ap, i), L);
      // In a 2-D group a segment deflects within the group's plane unless told otherwise.
      if (plane && std::holds_alternative<Bounce>(a) && !(*as)[i].contains("planeNormal"))
        std::get<Bounce>(a).planeNormal = plane->normal;
      addAction(actions, a, index(ap, i), L);
      parsed.push_back(std::move(a));
    }
  }
  const std::vector<Action> asWritten = parsed;  // for the warnings' JSON indices
  const bool hasConstrain = hasAction<Constrain2D>(parsed);
  if (plane && !hasConstrain) {
    // Project after the forces, before deflectors, absorbers and Move read the motion.
    auto it = std::find_if(parsed.begin(), parsed.end(), [](const Action& a) {
      return std::holds_alternative<Bounce>(a) || std::holds_alternative<Sink>(a) ||
             std::holds_alternative<Move>(a);
    });
    parsed.insert(it, *plane);
    actions = ActionList();
    for (const Action& a : parsed) addAction(actions, a, o.at("mode2d"), L);
  }
  // How Move integrates the forces, and sub-stepping (properties of the action list).
  if (const json* v = o.get("integrator")) {
    std::string name;
    read(*v, o.at("integrator"), L, name);
    const Integrator all[] = {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler,
                              Integrator::VelocityVerlet, Integrator::RK4, Integrator::Exact};
    std::vector<std::string> names;
    bool found = false;
    for (Integrator i : all) {
      names.emplace_back(integratorName(i));
      if (name == names.back()) {
        found = true;
        try {
          actions.setIntegrator(i);
        } catch (const InvalidArgument& e) {
          L.rethrow(o.at("integrator"), e, "integrator");
        }
      }
    }
    if (!found)
      L.fail(o.at("integrator"), "unknown integrator \"" + name + "\"" + suggestion(name, names));
  }
  if (const json* v = o.get("substeps")) {
    Obj so(*v, o.at("substeps"), L);
    Substeps sub;
    so.opt("maxStep", sub.maxStep);
    so.opt("maxDistance", sub.maxDistance);
    if (const json* m = so.get("maxSubsteps"))
      sub.maxSubsteps = std::uint32_t(readInteger(*m, so.at("maxSubsteps"), L, 1, 1u << 16));
    so.finish();
    try {
      actions.setSubsteps(sub);
    } catch (const InvalidArgument& e) {
      L.rethrow(so.path(), e, "substeps");
    }
  }
  g.actions = std::move(actions);

  if (const json* h = o.get("hair")) {
    const std::string hp = o.at("hair");
    if (h->is_boolean()) {
      g.hair.enabled = h->get<bool>();
    } else {
      Obj ho(*h, hp, L);
      g.hair.enabled = true;
      ho.opt("enabled", g.hair.enabled);
      if (const json* v = ho.get("every"))
        g.hair.every = std::uint32_t(readInteger(*v, ho.at("every"), L, 1, 1u << 20));
      if (const json* v = ho.get("maxVertices"))
        g.hair.maxVertices = std::uint32_t(readInteger(*v, ho.at("maxVertices"), L, 2, 1u << 20));
      ho.finish();
    }
  }
  if (const json* b = o.get("budget")) {
    std::string name;
    read(*b, o.at("budget"), L, name);
    const std::vector<std::string> names = {"dropNewest", "dropOldest", "scaleEmission"};
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end())
      L.fail(o.at("budget"), "unknown budget policy \"" + name + "\"" + suggestion(name, names));
    g.budget = BudgetPolicy(it - names.begin());
  }
  if (const json* t = o.get("trail")) {
    Obj to(*t, o.at("trail"), L);
    if (const json* v = to.get("length"))
      g.trail.length =
          std::uint32_t(readInteger(*v, to.at("length"), L, 0, TrailOptions::kMaxLength));
    to.opt("width", g.trail.width);
    to.opt("taper", g.trail.taper);
    to.opt("fade", g.trail.fade);
    to.finish();
    try {
      g.trail.validate();
    } catch (const InvalidArgument& e) {
      L.rethrow(to.path(), e, "trail");
    }
  }
  if (const json* r = o.get("require")) {
    const std::string rp = o.at("require");
    arrayOf(*r, rp, L, 0, "an array of attribute names");
    std::vector<std::string> names;
    for (int i = 0; i < int(Attribute::Count); ++i) names.emplace_back(attributeName(Attribute(i)));
    for (std::size_t i = 0; i < r->size(); ++i) {
      std::string s;
      read((*r)[i], index(rp, i), L, s);
      Attribute a;
      if (!attributeFromName(s, a))
        L.fail(index(rp, i), "unknown attribute \"" + s + "\"" + suggestion(s, names));
      g.require.insert(a);
    }
  }
  o.finish();
  warnGroup(g, asWritten, path, warnings);
  if (const json* as = o.get("actions"))
    for (std::size_t i = 0; i < as->size(); ++i)
      if (std::holds_alternative<Sink>(asWritten[i]) && (*as)[i].contains("killInside"))
        warnings.push_back({join(index(join(path, "actions"), i), "killInside"),
                            "deprecated: say \"mode\": \"inside\" or \"outside\""});
  return g;
}

Effect readEffect(const json& j, const Loader& L, const std::string& defaultName) {
  Obj o(j, "", L);
  Effect fx;
  fx.name = defaultName;
  if (const json* v = o.get("version")) {
    if (readInteger(*v, o.at("version"), L, 0, 1000) != 1)
      L.fail(o.at("version"), "this Flurry reads effect format version 1");
  }
  o.opt("name", fx.name);
  if (!safeName(fx.name)) L.fail(o.at("name"), kNameRule);
  o.opt("description", fx.description);
  if (fx.description.find('\n') != std::string::npos)
    L.fail(o.at("description"), "must be one line");
  o.opt("dt", fx.dt);
  if (!(fx.dt > 0 && fx.dt <= 10)) L.fail(o.at("dt"), "must be in (0, 10] seconds");
  o.opt("seed", fx.seed);
  if (const json* v = o.get("frames"))
    fx.frames = int(readInteger(*v, o.at("frames"), L, 1, 100'000'000));
  if (const json* v = o.get("space")) {
    if (!v->is_string() || (*v != "world" && *v != "local"))
      L.fail(o.at("space"), "expected \"world\" or \"local\"");
    fx.space = *v == "local" ? Space::Local : Space::World;
  }
  const json& gs = o.require("groups", "an array of groups");
  arrayOf(gs, "groups", L, 0, "an array of groups");
  if (gs.empty()) L.fail("groups", "an effect needs at least one group");
  for (std::size_t i = 0; i < gs.size(); ++i)
    fx.groups.push_back(readGroup(gs[i], index("groups", i), L, fx.groups, fx.warnings));
  linkDeathEmitters(fx, gs, L);
  if (const json* r = o.get("render")) {
    if (!r->is_object()) L.fail(o.at("render"), "expected an object, got " + kindOf(*r));
    if (depthOf(*r) > 64) L.fail(o.at("render"), "nested more than 64 levels deep");
    fx.render = r->dump();
    // The renderer's own parser checks it now, so that an error names this file.
    if (L.options->renderChecker) {
      try {
        L.options->renderChecker(fx.render, L.options->baseDir);
      } catch (const InvalidArgument& e) {
        L.rethrow(o.at("render"), e);
      } catch (const Error& e) {
        L.fail(o.at("render"), e.what());
      }
    }
  }
  o.finish();
  return fx;
}

}  // namespace

namespace {

/// Counts what the JSON document would hold, without building it (a SAX pass allocates
/// nothing but a string at a time), to estimate the memory its DOM needs.
struct SizeCounter : nlohmann::json_sax<json> {
  std::size_t values = 0, members = 0, stringBytes = 0, largest = 0;
  std::vector<std::size_t> open;  // elements of each open container

  bool value() {
    ++values;
    if (!open.empty()) largest = std::max(largest, ++open.back());
    return true;
  }
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t& s) override {
    stringBytes += s.size();
    return value();
  }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    value();
    open.push_back(0);
    return true;
  }
  bool key(string_t& k) override {
    ++members;
    stringBytes += k.size();
    return true;
  }
  bool end_object() override {
    open.pop_back();
    return true;
  }
  bool start_array(std::size_t) override { return start_object(0); }
  bool end_array() override { return end_object(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;  // the DOM parse reports it, with its position
  }
};

/// Makes sure the memory the document's DOM needs is there before building it: nlohmann's
/// destructor allocates (a stack as long as the largest array), so running out of memory
/// in the middle of a parse would end in std::terminate. Throws std::bad_alloc, having built
/// nothing, when it is not.
void reserveForDom(std::string_view text) {
  SizeCounter c;
  if (!json::sax_parse(text.begin(), text.end(), &c, nlohmann::detail::input_format_t::json, false,
                       true))
    return;
  // A value's slot, a container's storage with growth slack, an object member's map node and
  // key, the strings, and the destructor's stack (generous: it is a probe, not a budget).
  const std::size_t bytes = c.values * 64 + c.members * 128 + c.stringBytes * 2 + c.largest * 48;
  // Through a volatile pointer: the compiler may not elide an allocation it cannot see used.
  void* volatile probe = std::malloc(bytes);
  if (!probe) throw std::bad_alloc();
  std::free(probe);
}

}  // namespace

Effect parseEffect(std::string_view text, const std::string& fileName,
                   const EffectLoadOptions& options) {
  try {
    reserveForDom(text);
  } catch (const std::bad_alloc&) {
    throw EffectError(fileName, "", "out of memory: the file is too large to parse here");
  }
  json j;
  try {
    // Comments (// and /* */) are allowed: effect files are written by hand.
    j = json::parse(text.begin(), text.end(), nullptr, true, true);
  } catch (const json::exception& e) {
    // parse_error (with line and column), or out_of_range for a number like 1e400.
    std::string why = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> from "parse".
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw EffectError(fileName, "", why);
  }
  Loader L{fileName, &options, 0};
  // The default name is the file's stem, made safe for output file names.
  std::string stem = std::filesystem::path(fileName).stem().string();
  for (char& c : stem)
    if (!std::isalnum((unsigned char)c) && c != '-' && c != '.') c = '_';
  if (!safeName(stem)) stem = "effect";
  try {
    return readEffect(j, L, stem);
  } catch (const EffectError&) {
    throw;
  } catch (const json::exception& e) {
    // A JSON access the loader did not guard: report, do not crash.
    throw EffectError(fileName, "", std::string("malformed: ") + e.what());
  }
}

namespace detail {

namespace {
/// Parses one part's JSON text, reporting a syntax error at `path`.
json parsePart(std::string_view text, const std::string& fileName, const std::string& path) {
  try {
    return json::parse(text.begin(), text.end(), nullptr, true, true);
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw EffectError(fileName, path, why);
  }
}
}  // namespace

void checkEffectActionType(const std::string& type, const std::string& fileName,
                           const std::string& path) {
  const EffectLoadOptions none;
  const Loader L{fileName, &none, 0};
  checkActionType(type, join(path, "type"), L);
}

ActionList parseEffectActions(std::string_view actions, const std::string& fileName,
                              const std::string& path, const EffectLoadOptions& options) {
  const json j = parsePart(actions, fileName, path);
  const Loader L{fileName, &options, 0};
  try {
    arrayOf(j, path, L, 0, "an array of actions");
    ActionList list;
    for (std::size_t i = 0; i < j.size(); ++i)
      addAction(list, readAction(j[i], index(path, i), L), index(path, i), L);
    return list;
  } catch (const json::exception& e) {
    throw EffectError(fileName, path, std::string("malformed: ") + e.what());
  }
}

namespace {
// One part of an effect (an emitter, a death emitter) from its own JSON text, by `read`.
template <class Read>
auto parseEffectPart(std::string_view text, const std::string& fileName, const std::string& path,
                     const EffectLoadOptions& options, Read read) {
  const json j = parsePart(text, fileName, path);
  const Loader L{fileName, &options, 0};
  try {
    return read(j, path, L);
  } catch (const json::exception& e) {
    throw EffectError(fileName, path, std::string("malformed: ") + e.what());
  }
}
}  // namespace

Emitter parseEffectEmitter(std::string_view emitter, const std::string& fileName,
                           const std::string& path, const EffectLoadOptions& options) {
  return parseEffectPart(emitter, fileName, path, options, readEmitter);
}

DeathEmitter parseEffectDeathEmitter(std::string_view deathEmitter, const std::string& fileName,
                                     const std::string& path, const EffectLoadOptions& options) {
  return parseEffectPart(deathEmitter, fileName, path, options, readDeathEmitter);
}

}  // namespace detail

Effect loadEffect(const std::filesystem::path& file, EffectLoadOptions options) {
  namespace fs = std::filesystem;
  const std::string name = file.string();
  std::error_code ec;
  const fs::file_status st = fs::status(file, ec);
  if (fs::is_directory(st)) throw EffectError(name, "", "is a directory");
  const std::size_t limit = options.maxFileBytes;
  const std::string tooLarge = "larger than " + byteCount(limit) + ", the limit for an effect file";
  if (fs::is_regular_file(st)) {
    const std::uintmax_t size = fs::file_size(file, ec);
    if (!ec && size > limit) throw EffectError(name, "", tooLarge);
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw EffectError(name, "", "cannot open the file");
  // Read in chunks up to the limit: a pipe or a device (/dev/zero) has no size to check first.
  std::string text;
  char chunk[1 << 16];
  while (in) {
    in.read(chunk, sizeof chunk);
    const std::size_t got = std::size_t(in.gcount());
    if (got > limit - text.size()) throw EffectError(name, "", tooLarge);
    text.append(chunk, got);
  }
  if (in.bad()) throw EffectError(name, "", "cannot read the file");
  if (options.baseDir.empty()) options.baseDir = file.parent_path();
  Effect fx = parseEffect(text, name, options);
  fx.file = file;
  return fx;
}

}  // namespace flurry
