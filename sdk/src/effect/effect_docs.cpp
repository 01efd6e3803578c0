// What is generated from the descriptors (descriptors.hpp) besides the reader and writer: the
// JSON Schema of effect files (docs/effect.schema.json), the reference tables of the docs
// (docs/effect-reference.md) and the fuzzer's dictionary (tests/fuzz/effect.dict). The tool
// tests/effect/flurry_effect_docs prints them; tests fail when the committed files differ.
//
// The effect's and groups' own fields, and the mesh and union domains, have no descriptors yet:
// they are listed here, once, for the schema and the dictionary.
#include <cctype>
#include <set>

#include "effect/effect_docs.hpp"
#include "effect/json_writer.hpp"
#include "flurry/group.hpp"

namespace flurry::detail {

namespace {

using jsonio::ojson;
using jsonio::Writer;

ojson defRef(const std::string& name) {
  return {{"$ref", "#/$defs/" + name}};
}

// ---- schema of one field --------------------------------------------------------------------

ojson numberSchema(const desc::Limit& l, bool integer) {
  if (!l.checked) return integer ? ojson{{"type", "integer"}, {"minimum", 0}} : defRef("number");
  ojson n = {{"type", integer ? "integer" : "number"}};
  if (l.min > -desc::kInf) n[l.minOpen ? "exclusiveMinimum" : "minimum"] = l.min;
  if (l.max < desc::kInf) n["maximum"] = l.max;
  if (l.infinite) return {{"anyOf", {n, {{"enum", {"inf", "infinity"}}}}}};
  return n;
}

template <class T>
struct Tag {};

ojson schemaOf(Tag<float>, const desc::Limit& l) {
  return numberSchema(l, false);
}
ojson schemaOf(Tag<double>, const desc::Limit& l) {
  return numberSchema(l, false);
}
ojson schemaOf(Tag<int>, const desc::Limit& l) {
  return numberSchema(l, true);
}
ojson schemaOf(Tag<std::uint32_t>, const desc::Limit& l) {
  return numberSchema(l, true);
}
ojson schemaOf(Tag<bool>, const desc::Limit&) {
  return {{"type", "boolean"}};
}
ojson schemaOf(Tag<std::string>, const desc::Limit&) {
  return {{"type", "string"}};
}
ojson schemaOf(Tag<Vec3>, const desc::Limit& l) {
  return defRef(l.nonZero ? "direction" : "vec3");
}
ojson schemaOf(Tag<Vec4>, const desc::Limit&) {
  return defRef("color");
}
ojson schemaOf(Tag<Fuzzy>, const desc::Limit&) {
  return defRef("fuzzy");
}
ojson schemaOf(Tag<Domain>, const desc::Limit&) {
  return defRef("domain");
}
ojson schemaOf(Tag<std::shared_ptr<const VectorField>>, const desc::Limit&) {
  return defRef("sampledField");
}
ojson schemaOf(Tag<std::shared_ptr<const EmitterSpec>>, const desc::Limit&) {
  return defRef("EmitterSpec");
}
template <desc::NamedEnum E>
ojson schemaOf(Tag<E>, const desc::Limit&) {
  ojson names = ojson::array();
  for (const auto& [n, v] : desc::EnumNames<E>::values) names.push_back(n);
  return {{"enum", names}};
}
template <desc::Described S>
ojson schemaOf(Tag<S>, const desc::Limit&) {
  return defRef(desc::Describe<S>::name);
}
template <class T>
ojson schemaOf(Tag<std::vector<T>>, const desc::Limit& l) {
  return {{"type", "array"}, {"items", schemaOf(Tag<T>{}, l)}};
}

template <class F>
std::string describeField(const F& f) {
  std::string d = f.doc;
  if (*f.unit) d += std::string(" (") + f.unit + ")";
  return d;
}

/// An object schema of a described struct's fields; `type`: the action's name, as "type".
template <class S>
ojson objectSchema(const char* type) {
  ojson props = ojson::object(), required = ojson::array();
  if (type) {
    props["type"] = {{"const", type}};
    required.push_back("type");
  }
  props["$comment"] = {{"type", "string"}};
  const S def{};
  desc::forEachField<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    ojson p = schemaOf(Tag<T>{}, f.limit);
    // A $ref with siblings is fine in draft 2020-12.
    p["description"] = describeField(f);
    if (f.required)
      required.push_back(f.name);
    else if (ojson d = jsonio::write(Writer{}, def.*f.member); !d.is_null())
      p["default"] = std::move(d);
    props[f.name] = std::move(p);
  });
  ojson o = {{"type", "object"}, {"description", desc::Describe<S>::doc}};
  o["properties"] = std::move(props);
  if (!required.empty()) o["required"] = std::move(required);
  o["additionalProperties"] = false;
  return o;
}

// ---- domains: a mesh and a union hold lists, listed here; the other shapes are described --

struct DomainKind {
  const char* name;
  std::vector<std::pair<const char*, const char*>> fields;  // key, $def of its items (null: a path)
  std::vector<const char*> required;
};
const std::vector<DomainKind>& domainKinds() {
  static const std::vector<DomainKind> kinds = {
      {"mesh", {{"vertices", "vec3"}, {"triangles", "triangleIndices"}}, {"vertices", "triangles"}},
      // The same mesh read from a Wavefront OBJ file (relative to the effect file).
      {"mesh", {{"obj", nullptr}}, {"obj"}},
      {"union", {{"parts", "domain"}}, {"parts"}},
  };
  return kinds;
}

ojson domainSchema() {
  ojson any = ojson::array({defRef("vec3")});
  desc::forEachDomainKind([&](auto tag) {
    using S = typename decltype(tag)::type;
    any.push_back(objectSchema<S>(desc::Describe<S>::name));
  });
  for (const DomainKind& k : domainKinds()) {
    ojson props = {{"type", {{"const", k.name}}}, {"$comment", {{"type", "string"}}}};
    for (const auto& [key, def] : k.fields) {
      props[key] = def ? ojson{{"type", "array"}, {"items", defRef(def)}}
                       : ojson{{"type", "string"}, {"description", "a file path"}};
    }
    ojson required = {"type"};
    for (const char* r : k.required) required.push_back(r);
    any.push_back({{"type", "object"},
                   {"properties", props},
                   {"required", required},
                   {"additionalProperties", false}});
  }
  return {{"description", "[x, y, z] (a point), or {\"type\": kind, ...}"}, {"anyOf", any}};
}

template <class... S>
void addDefs(ojson& defs) {
  ((defs[desc::Describe<S>::name] = objectSchema<S>(nullptr)), ...);
}

ojson vecSchema(std::size_t lo, std::size_t hi) {
  return {{"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", lo}, {"maxItems", hi}};
}

}  // namespace

std::string effectSchema() {
  ojson defs = ojson::object();
  defs["number"] = {
      {"anyOf", {{{"type", "number"}}, {{"enum", {"inf", "-inf", "infinity", "-infinity"}}}}}};
  defs["vec3"] = vecSchema(3, 3);
  defs["direction"] = vecSchema(3, 3);
  defs["direction"]["description"] = "a non-zero vector";
  defs["color"] = vecSchema(3, 4);
  defs["color"]["description"] = "[r, g, b] or [r, g, b, a]";
  defs["triangleIndices"] = {{"type", "array"},
                             {"items", {{"type", "integer"}, {"minimum", 0}}},
                             {"minItems", 3},
                             {"maxItems", 3}};
  defs["fuzzy"] = {
      {"description", "a number, [center, spread], or {center, spread | percent, distribution}"},
      {"anyOf",
       {defRef("number"),
        vecSchema(2, 2),
        {{"type", "object"},
         {"properties",
          {{"center", defRef("number")},
           {"spread", defRef("number")},
           {"percent", defRef("number")},
           {"distribution", {{"enum", {"uniform", "normal"}}}},
           {"$comment", {{"type", "string"}}}}},
         {"required", {"center"}},
         {"additionalProperties", false}}}}};
  defs["domain"] = domainSchema();
  defs["sampledField"] = {
      {"description", "a dense grid (data x fastest), or {\"vdb\": file, \"grid\": name}"},
      {"anyOf",
       {{{"type", "object"},
         {"properties",
          {{"origin", defRef("vec3")},
           {"voxelSize", defRef("number")},
           {"dims", {{"type", "array"}, {"items", {{"type", "integer"}, {"minimum", 1}}}}},
           {"data", {{"type", "array"}, {"items", defRef("vec3")}}},
           {"$comment", {{"type", "string"}}}}},
         {"required", {"dims", "data"}},
         {"additionalProperties", false}},
        {{"type", "object"},
         {"properties",
          {{"vdb", {{"type", "string"}}},
           {"grid", {{"type", "string"}}},
           {"$comment", {{"type", "string"}}}}},
         {"required", {"vdb"}},
         {"additionalProperties", false}}}}};
  addDefs<Falloff, ColorOverLife::Key, SizeOverLife::Key, Burst, Keyframe, ParticleType, Emitter,
          EmitterSpec, PrimeEmitter, DeathEmitter>(defs);
  ojson actions = ojson::array();
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    const std::string name = desc::Describe<A>::name;
    defs["action." + name] = objectSchema<A>(desc::Describe<A>::name);
    actions.push_back(defRef("action." + name));
  });
  defs["action"] = {{"oneOf", actions}};

  ojson integrators = ojson::array();
  for (Integrator i : {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler,
                       Integrator::VelocityVerlet, Integrator::RK4, Integrator::Exact})
    integrators.push_back(integratorName(i));
  ojson attributes = ojson::array();
  for (int i = 0; i < int(Attribute::Count); ++i)
    attributes.push_back(std::string(attributeName(Attribute(i))));
  const ojson comment = {{"type", "string"}};
  auto object = [](ojson props) {
    props["$comment"] = {{"type", "string"}};
    return ojson{
        {"type", "object"}, {"properties", std::move(props)}, {"additionalProperties", false}};
  };
  auto arrayOf = [](ojson items) { return ojson{{"type", "array"}, {"items", std::move(items)}}; };
  auto integer = [](int min) { return ojson{{"type", "integer"}, {"minimum", min}}; };
  const ojson nonNegative = {{"type", "number"}, {"minimum", 0}};
  ojson g = ojson::object();
  g["name"] = {{"type", "string"}};
  g["capacity"] = integer(1);
  g["capacity"]["description"] = "the most particles the group holds";
  g["emitters"] = arrayOf(defRef("Emitter"));
  g["primeEmitters"] = arrayOf(defRef("PrimeEmitter"));
  g["deathEmitters"] = arrayOf(defRef("DeathEmitter"));
  g["actions"] = arrayOf(defRef("action"));
  ojson plane = object({{"point", defRef("vec3")}, {"normal", defRef("direction")}});
  g["mode2d"] = {{"anyOf", ojson::array({{{"type", "boolean"}}, plane})}};
  g["integrator"] = {{"enum", integrators}};
  g["substeps"] =
      object({{"maxStep", nonNegative}, {"maxDistance", nonNegative}, {"maxSubsteps", integer(1)}});
  ojson hair = object(
      {{"enabled", {{"type", "boolean"}}}, {"every", integer(1)}, {"maxVertices", integer(2)}});
  g["hair"] = {{"anyOf", ojson::array({{{"type", "boolean"}}, hair})}};
  g["budget"] = {{"enum", {"dropNewest", "dropOldest", "scaleEmission"}}};
  g["trail"] = object({{"length", integer(0)},
                       {"width", nonNegative},
                       {"taper", nonNegative},
                       {"fade", nonNegative}});
  g["trail"]["properties"]["length"]["maximum"] = flurry::TrailOptions::kMaxLength;
  g["require"] = arrayOf({{"enum", attributes}});
  defs["group"] = object(std::move(g));
  defs["group"]["required"] = {"capacity"};

  ojson schema = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"$id", "https://flurry.invalid/effect.schema.json"},
      {"title", "Flurry effect file"},
      {"description",
       "Generated from sdk/src/effect/descriptors.hpp by flurry_effect_docs schema: do not edit."},
      {"type", "object"},
      {"properties",
       {{"version", {{"const", 1}}},
        {"name", {{"type", "string"}}},
        {"description", {{"type", "string"}}},
        {"dt", {{"type", "number"}, {"exclusiveMinimum", 0}, {"maximum", 10}}},
        {"seed", {{"type", "integer"}, {"minimum", 0}}},
        {"frames", {{"type", "integer"}, {"minimum", 1}}},
        {"space", {{"enum", {"world", "local"}}}},
        {"groups", {{"type", "array"}, {"minItems", 1}, {"items", defRef("group")}}},
        {"render", {{"type", "object"}, {"description", "docs/rendering.md"}}},
        {"$comment", comment}}},
      {"required", {"groups"}},
      {"additionalProperties", false}};
  schema["$defs"] = std::move(defs);
  return schema.dump(2) + "\n";
}

// ---- the reference tables -------------------------------------------------------------------

namespace {

std::string limitText(const desc::Limit& l) {
  if (!l.checked) return "";
  if (l.nonZero) return "non-zero";
  auto num = [](double x) {
    std::string s = ojson(x).dump();
    if (s.size() > 2 && s.ends_with(".0")) s.resize(s.size() - 2);
    return s;
  };
  std::string t;
  if (l.min > -desc::kInf && l.max < desc::kInf)
    t = "[" + num(l.min) + ", " + num(l.max) + "]";
  else if (l.min > -desc::kInf)
    t = (l.minOpen ? "> " : "≥ ") + num(l.min);
  else
    t = "finite";
  if (l.infinite) t += ", or inf";
  return t;
}

std::string typeText(Tag<float>) {
  return "number";
}
std::string typeText(Tag<double>) {
  return "number";
}
std::string typeText(Tag<int>) {
  return "integer";
}
std::string typeText(Tag<std::uint32_t>) {
  return "integer";
}
std::string typeText(Tag<bool>) {
  return "boolean";
}
std::string typeText(Tag<std::string>) {
  return "string";
}
std::string typeText(Tag<Vec3>) {
  return "[x, y, z]";
}
std::string typeText(Tag<Vec4>) {
  return "[r, g, b, a]";
}
std::string typeText(Tag<Fuzzy>) {
  return "fuzzy";
}
std::string typeText(Tag<Domain>) {
  return "[domain](#domains)";
}
std::string typeText(Tag<std::shared_ptr<const VectorField>>) {
  return "sampled field";
}
std::string typeText(Tag<std::shared_ptr<const EmitterSpec>>) {
  return "[EmitterSpec](#emitterspec)";
}
template <desc::NamedEnum E>
std::string typeText(Tag<E>) {
  std::string t;
  for (const auto& [n, v] : desc::EnumNames<E>::values)
    t += (t.empty() ? "" : " \\| ") + std::string("`\"") + n + "\"`";
  return t;
}
template <desc::Described S>
std::string typeText(Tag<S>) {
  std::string n = desc::Describe<S>::name, anchor;
  for (char c : n) anchor += char(std::tolower((unsigned char)c));
  return "[" + n + "](#" + anchor + ")";
}
template <class T>
std::string typeText(Tag<std::vector<T>>) {
  return "array of " + typeText(Tag<T>{});
}

template <class S>
std::string table(const std::string& heading) {
  std::string out =
      heading + " `" + desc::Describe<S>::name + "`\n\n" + desc::Describe<S>::doc + "\n\n";
  if (std::tuple_size_v<std::decay_t<decltype(desc::Describe<S>::fields)>> == 0)
    return out + "No fields.\n\n";
  out += "| field | type | default | unit | valid | |\n| --- | --- | --- | --- | --- | --- |\n";
  const S def{};
  desc::forEachField<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    std::string d;
    if (f.required) {
      d = "**required**";
    } else {
      std::string text;
      jsonio::print(jsonio::write(Writer{}, def.*f.member), text, 0);
      d = text.find('\n') == std::string::npos ? "`" + text + "`" : "see the struct";
    }
    out += std::string("| `") + f.name + "` | " + typeText(Tag<T>{}) + " | " + d + " | " + f.unit +
           " | " + limitText(f.limit) + " | " + f.doc + " |\n";
  });
  return out + "\n";
}

}  // namespace

std::string effectReference() {
  std::string out =
      "# Effect file reference\n\n"
      "<!-- Generated from sdk/src/effect/descriptors.hpp: do not edit. Regenerate with\n"
      "     build/release/tests/effect/flurry_effect_docs reference > docs/effect-reference.md "
      "-->\n\n"
      "Every field of every action and emitter part of an [effect file](effect-format.md): its "
      "default (the struct's own), unit and valid values. A field may be left out (its default) "
      "unless marked required. Numbers may be written `\"inf\"` where infinity is valid.\n\n"
      "## Actions\n\n"
      "Each action is `{\"type\": \"Name\", ...fields}`; `Callback` runs C++ code and cannot be "
      "written in an effect file.\n\n";
  desc::forEachAction([&](auto tag) { out += table<typename decltype(tag)::type>("###"); });
  out += "## Parts of actions\n\n";
  out += table<Falloff>("###") + table<ColorOverLife::Key>("###") + table<SizeOverLife::Key>("###");
  out += "## Emitters\n\n";
  out += table<Emitter>("###") + table<ParticleType>("###") + table<Burst>("###") +
         table<Keyframe>("###") + table<PrimeEmitter>("###") + table<EmitterSpec>("###") +
         table<DeathEmitter>("###");
  out +=
      "## Domains\n\n"
      "A domain is `[x, y, z]` (a point) or `{\"type\": \"kind\", ...fields}`; besides the "
      "kinds below, `mesh` (`vertices` [[x, y, z], ...], `triangles` [[i, j, k], ...], or "
      "`obj`: a Wavefront OBJ file, relative to the effect file, whose `v` and `f` lines are "
      "read, polygons fanned into triangles) and "
      "`union` (`parts`: domains) hold lists.\n\n";
  desc::forEachDomainKind([&](auto tag) { out += table<typename decltype(tag)::type>("###"); });
  out.pop_back();  // one newline at the end
  return out;
}

// ---- the fuzz dictionary --------------------------------------------------------------------

std::string fuzzDictionary() {
  std::set<std::string> keys = {
      // the effect, groups, fuzzy values, sampled fields: no descriptors yet
      "version",       "name",        "description", "dt",         "seed",         "frames",
      "space",         "groups",      "render",      "capacity",   "emitters",     "primeEmitters",
      "deathEmitters", "actions",     "mode2d",      "integrator", "substeps",     "maxStep",
      "maxDistance",   "maxSubsteps", "hair",        "enabled",    "every",        "maxVertices",
      "require",       "type",        "center",      "spread",     "percent",      "distribution",
      "origin",        "voxelSize",   "dims",        "data",       "vdb",          "grid",
      "normal",        "point",       "trail",       "length",     "width",        "taper",
      "fade",          "budget",      "dropNewest",  "dropOldest", "scaleEmission"};
  std::set<std::string> values = {"world", "local", "uniform", "normal", "inf",
                                  "-inf",  "true",  "false",   "null"};
  for (const DomainKind& k : domainKinds()) {
    values.insert(k.name);
    for (const auto& [key, def] : k.fields) keys.insert(key);
  }
  auto described = [&]<class S>(Tag<S>) {
    desc::forEachField<S>([&](const auto& f) {
      keys.insert(f.name);
      using T = typename std::decay_t<decltype(f)>::Type;
      if constexpr (desc::NamedEnum<T>)
        for (const auto& [n, v] : desc::EnumNames<T>::values) values.insert(n);
    });
  };
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    values.insert(desc::Describe<A>::name);
    described(Tag<A>{});
  });
  described(Tag<Falloff>{}), described(Tag<ColorOverLife::Key>{});
  described(Tag<SizeOverLife::Key>{}), described(Tag<Burst>{}), described(Tag<Keyframe>{});
  described(Tag<ParticleType>{}), described(Tag<Emitter>{}), described(Tag<EmitterSpec>{});
  described(Tag<PrimeEmitter>{}), described(Tag<DeathEmitter>{});
  desc::forEachDomainKind([&](auto tag) {
    using S = typename decltype(tag)::type;
    values.insert(desc::Describe<S>::name);
    described(Tag<S>{});
  });
  for (int i = 0; i < int(Attribute::Count); ++i)
    values.insert(std::string(attributeName(Attribute(i))));
  for (Integrator i : {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler,
                       Integrator::VelocityVerlet, Integrator::RK4, Integrator::Exact})
    values.insert(integratorName(i));

  std::string out =
      "# libFuzzer dictionary for effect files: field names, type names, tokens.\n"
      "# Generated from sdk/src/effect/descriptors.hpp: do not edit. Regenerate with\n"
      "#   build/release/tests/effect/flurry_effect_docs dict > tests/fuzz/effect.dict\n";
  for (const std::string& k : keys) out += "\"\\\"" + k + "\\\":\"\n";
  for (const std::string& v : values) out += "\"\\\"" + v + "\\\"\"\n";
  for (const char* t : {"{", "}", "[", "]", ",", "1e38", "-1", "0", "1e400", "//", "/*", "*/"})
    out += std::string("\"") + t + "\"\n";
  return out;
}

}  // namespace flurry::detail
