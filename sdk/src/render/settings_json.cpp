// An effect file's `render` object to RenderSettings. Every field is optional; unknown fields
// and wrong types are errors naming the JSON path, as the effect loader does.
#include <cmath>

#include <nlohmann/json.hpp>

#include "flurry/render.hpp"

namespace flurry {

namespace {

using json = nlohmann::json;

struct Reader {
  [[noreturn]] static void fail(const std::string& path, const std::string& why) {
    throw InvalidArgument(path, why);
  }

  static void onlyKeys(const json& o, const std::string& path,
                       std::initializer_list<const char*> known) {
    if (!o.is_object()) fail(path, "must be an object");
    for (const auto& [k, v] : o.items()) {
      if (k == "$comment") continue;  // as in the rest of an effect file
      bool ok = false;
      for (const char* n : known) ok = ok || k == n;
      if (!ok) {
        std::string list;
        for (const char* n : known) list += std::string(list.empty() ? "" : ", ") + n;
        fail(path + "." + k, "unknown field (known: " + list + ")");
      }
    }
  }

  static float number(const json& v, const std::string& path) {
    if (!v.is_number()) fail(path, "must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(path, "must be finite");
    return float(d);
  }

  static bool boolean(const json& v, const std::string& path) {
    if (!v.is_boolean()) fail(path, "must be true or false");
    return v.get<bool>();
  }

  static Vec3 vec3(const json& v, const std::string& path) {
    if (!v.is_array() || v.size() != 3) fail(path, "must be [x, y, z]");
    return Vec3(number(v[0], path + "[0]"), number(v[1], path + "[1]"), number(v[2], path + "[2]"));
  }

  // A color or per-channel coefficient: [r, g, b], or one number for all three.
  static Vec3 rgb(const json& v, const std::string& path) {
    if (v.is_number()) return Vec3(number(v, path));
    if (!v.is_array() || v.size() != 3) fail(path, "must be a number or [r, g, b]");
    return vec3(v, path);
  }

  static std::string choice(const json& v, const std::string& path,
                            std::initializer_list<const char*> options) {
    if (!v.is_string()) fail(path, "must be a string");
    const std::string s = v.get<std::string>();
    std::string list;
    for (const char* o : options) {
      if (s == o) return s;
      list += std::string(list.empty() ? "" : ", ") + o;
    }
    fail(path, "must be one of " + list + ", not \"" + s + "\"");
  }
};

void readSprite(const json& v, const std::string& path, const std::filesystem::path& baseDir,
                Sprite& sprite, std::string& image) {
  if (!v.is_string())
    Reader::fail(path, "must be point, disc, spark, snowflake, glow, puff or a PNG path");
  const std::string name = v.get<std::string>();
  if (name == "point")
    sprite = Sprite::Point;
  else if (name == "disc")
    sprite = Sprite::Disc;
  else if (name == "spark")
    sprite = Sprite::Spark;
  else if (name == "snowflake")
    sprite = Sprite::Snowflake;
  else if (name == "glow")
    sprite = Sprite::Glow;
  else if (name == "puff")
    sprite = Sprite::Puff;
  else {
    sprite = Sprite::Image;
    const std::filesystem::path file(name);
    image = (file.is_relative() && !baseDir.empty() ? baseDir / file : file).string();
  }
}

BlendMode readBlend(const json& v, const std::string& path) {
  return Reader::choice(v, path, {"alpha", "additive"}) == "additive" ? BlendMode::Additive
                                                                      : BlendMode::Alpha;
}

float readStretch(const json& v, const std::string& path) {
  const float f = Reader::number(v, path);
  if (!(f >= 0.0f && f <= 10.0f)) Reader::fail(path, "must be within [0, 10] seconds");
  return f;
}

float readMaxStretch(const json& v, const std::string& path) {
  const float f = Reader::number(v, path);
  if (!(f >= 1.0f && f <= 1000.0f)) Reader::fail(path, "must be within [1, 1000]");
  return f;
}

}  // namespace

RenderSettings parseRenderSettings(std::string_view text, const std::filesystem::path& baseDir,
                                   RenderSettings s) {
  using R = Reader;
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InvalidArgument("render", std::string("not valid JSON: ") + e.what());
  }
  const std::string p = "render";
  R::onlyKeys(root, p,
              {"background", "camera", "shading", "litMinPixels", "ambient", "lights", "material",
               "falloff", "blend", "sort", "sprite", "strands", "toneMap", "exposure",
               "transparent", "geometry", "stretch", "maxStretch", "groups"});
  if (root.contains("background")) s.background = R::rgb(root["background"], p + ".background");
  if (root.contains("camera")) {
    const json& c = root["camera"];
    const std::string cp = p + ".camera";
    R::onlyKeys(c, cp, {"target", "distance", "yaw", "pitch", "fov", "near", "far"});
    Camera& cam = s.camera;
    if (c.contains("target")) cam.target = R::vec3(c["target"], cp + ".target");
    if (c.contains("distance")) cam.distance = R::number(c["distance"], cp + ".distance");
    if (c.contains("yaw")) cam.yaw = R::number(c["yaw"], cp + ".yaw");
    if (c.contains("pitch")) cam.pitch = R::number(c["pitch"], cp + ".pitch");
    if (c.contains("fov")) cam.fovY = R::number(c["fov"], cp + ".fov");
    if (c.contains("near")) cam.nearPlane = R::number(c["near"], cp + ".near");
    if (c.contains("far")) cam.farPlane = R::number(c["far"], cp + ".far");
    if (!(cam.distance > 0.0f)) R::fail(cp + ".distance", "must be > 0");
    if (!(cam.pitch > -90.0f && cam.pitch < 90.0f))
      R::fail(cp + ".pitch", "must be within (-90, 90)");
    if (!(cam.fovY > 0.0f && cam.fovY < 180.0f)) R::fail(cp + ".fov", "must be within (0, 180)");
    if (!(cam.nearPlane > 0.0f && cam.farPlane > cam.nearPlane))
      R::fail(cp + ".near", "need 0 < near < far");
  }
  if (root.contains("shading")) s.shading = R::boolean(root["shading"], p + ".shading");
  if (root.contains("litMinPixels")) {
    s.litMinPixels = R::number(root["litMinPixels"], p + ".litMinPixels");
    if (s.litMinPixels < 0.0f) R::fail(p + ".litMinPixels", "must be >= 0");
  }
  if (root.contains("ambient")) s.lighting.ambient = R::rgb(root["ambient"], p + ".ambient");
  if (root.contains("lights")) {
    const json& ls = root["lights"];
    if (!ls.is_array()) R::fail(p + ".lights", "must be an array");
    if (ls.size() > 8) R::fail(p + ".lights", "at most 8 lights");
    s.lighting.lights.clear();
    for (std::size_t i = 0; i < ls.size(); ++i) {
      const std::string lp = p + ".lights[" + std::to_string(i) + "]";
      const json& l = ls[i];
      R::onlyKeys(l, lp, {"type", "direction", "position", "intensity"});
      Light light;
      const std::string type = l.contains("type")
                                   ? R::choice(l["type"], lp + ".type", {"directional", "point"})
                                   : "directional";
      light.type = type == "point" ? Light::Type::Point : Light::Type::Directional;
      const char* where = light.type == Light::Type::Point ? "position" : "direction";
      const char* other = light.type == Light::Type::Point ? "direction" : "position";
      if (l.contains(other)) R::fail(lp + "." + other, "not for a " + type + " light");
      if (!l.contains(where)) R::fail(lp + "." + where, "is required for a " + type + " light");
      light.vector = R::vec3(l[where], lp + "." + where);
      if (light.type == Light::Type::Directional && glm::dot(light.vector, light.vector) == 0.0f)
        R::fail(lp + ".direction", "must not be zero");
      if (l.contains("intensity")) light.intensity = R::rgb(l["intensity"], lp + ".intensity");
      s.lighting.lights.push_back(light);
    }
  }
  if (root.contains("material")) {
    const json& m = root["material"];
    const std::string mp = p + ".material";
    R::onlyKeys(m, mp, {"ka", "kd", "ks", "n"});
    Material& mat = s.lighting.material;
    if (m.contains("ka")) mat.ka = R::rgb(m["ka"], mp + ".ka");
    if (m.contains("kd")) mat.kd = R::rgb(m["kd"], mp + ".kd");
    if (m.contains("ks")) mat.ks = R::rgb(m["ks"], mp + ".ks");
    if (m.contains("n")) {
      mat.n = R::number(m["n"], mp + ".n");
      if (mat.n < 0.0f) R::fail(mp + ".n", "must be >= 0");
    }
  }
  if (root.contains("falloff")) {
    const std::string f = R::choice(root["falloff"], p + ".falloff", {"light", "viewer", "none"});
    s.lighting.falloff = f == "viewer" ? LightFalloff::Viewer
                         : f == "none" ? LightFalloff::None
                                       : LightFalloff::Light;
  }
  if (root.contains("blend")) s.blend = readBlend(root["blend"], p + ".blend");
  if (root.contains("sort")) s.sortForAlpha = R::boolean(root["sort"], p + ".sort");
  if (root.contains("sprite"))
    readSprite(root["sprite"], p + ".sprite", baseDir, s.sprite, s.spriteImage);
  if (root.contains("strands"))
    s.strandStyle = R::choice(root["strands"], p + ".strands", {"ribbon", "line"}) == "line"
                        ? StrandStyle::Line
                        : StrandStyle::Ribbon;
  if (root.contains("toneMap")) {
    const std::string t = R::choice(root["toneMap"], p + ".toneMap", {"none", "reinhard", "aces"});
    s.toneMap = t == "aces" ? ToneMap::Aces : t == "reinhard" ? ToneMap::Reinhard : ToneMap::None;
  }
  if (root.contains("exposure")) {
    s.exposure = R::number(root["exposure"], p + ".exposure");
    if (!(s.exposure > 0.0f && s.exposure <= 100.0f))
      R::fail(p + ".exposure", "must be within (0, 100]");
  }
  if (root.contains("transparent"))
    s.transparent = R::boolean(root["transparent"], p + ".transparent");
  if (root.contains("geometry")) {
    // true / false, or an object: {"show", "color", "opacity", "bounce", "sink", "block"}.
    const json& g = root["geometry"];
    const std::string gp = p + ".geometry";
    SceneGeometry& geo = s.geometry;
    if (g.is_boolean()) {
      geo.show = g.get<bool>();
    } else {
      if (!g.is_object()) R::fail(gp, "must be true, false or an object");
      R::onlyKeys(g, gp, {"show", "color", "opacity", "bounce", "sink", "block"});
      geo.show = g.contains("show") ? R::boolean(g["show"], gp + ".show") : true;
      if (g.contains("color")) geo.color = R::rgb(g["color"], gp + ".color");
      if (g.contains("opacity")) {
        geo.opacity = R::number(g["opacity"], gp + ".opacity");
        if (!(geo.opacity >= 0.0f && geo.opacity <= 1.0f))
          R::fail(gp + ".opacity", "must be within [0, 1]");
      }
      if (g.contains("bounce")) geo.bounce = R::boolean(g["bounce"], gp + ".bounce");
      if (g.contains("sink")) geo.sink = R::boolean(g["sink"], gp + ".sink");
      if (g.contains("block")) geo.block = R::boolean(g["block"], gp + ".block");
    }
  }
  if (root.contains("stretch")) s.stretch = readStretch(root["stretch"], p + ".stretch");
  if (root.contains("maxStretch"))
    s.maxStretch = readMaxStretch(root["maxStretch"], p + ".maxStretch");
  if (root.contains("groups")) {
    // {"GROUP": {"sprite", "blend", "sort", "shading", "stretch", "maxStretch"}, ...}
    const json& gs = root["groups"];
    const std::string gp = p + ".groups";
    if (!gs.is_object()) R::fail(gp, "must be an object: {\"GROUP\": {look}, ...}");
    s.groups.clear();
    for (const auto& [name, g] : gs.items()) {
      if (name == "$comment") continue;
      const std::string lp = gp + "." + name;
      R::onlyKeys(g, lp, {"sprite", "blend", "sort", "shading", "stretch", "maxStretch"});
      GroupLook look;
      look.group = name;
      if (g.contains("sprite")) {
        Sprite sprite{};
        readSprite(g["sprite"], lp + ".sprite", baseDir, sprite, look.spriteImage);
        look.sprite = sprite;
      }
      if (g.contains("blend")) look.blend = readBlend(g["blend"], lp + ".blend");
      if (g.contains("sort")) look.sortForAlpha = R::boolean(g["sort"], lp + ".sort");
      if (g.contains("shading")) look.shading = R::boolean(g["shading"], lp + ".shading");
      if (g.contains("stretch")) look.stretch = readStretch(g["stretch"], lp + ".stretch");
      if (g.contains("maxStretch"))
        look.maxStretch = readMaxStretch(g["maxStretch"], lp + ".maxStretch");
      s.groups.push_back(std::move(look));
    }
  }
  return s;
}

}  // namespace flurry
