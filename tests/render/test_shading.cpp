// The seed's simple shading model on the CPU: the worked example of section 17.2.4, and the
// terms of I = Ia·ka + Ip·(kd·(L·N) + ks·(M·V)^n)/R².
#include <gtest/gtest.h>

#include <cmath>

#include "flurry/render_shading.hpp"

using namespace flurry;

namespace {
const Vec3 kN(0.0f, 1.0f, 0.0f);
const Vec3 kL(-0.7071f, 0.7071f, 0.0f);
const Vec3 kV(0.866f, 0.5f, 0.0f);
}  // namespace

TEST(Shading, SeedWorkedExample) {
  EXPECT_NEAR(glm::dot(kN, kL), 0.7071f, 1e-4f);
  EXPECT_NEAR(glm::dot(kN, kV), 0.5f, 1e-4f);
  EXPECT_NEAR(glm::dot(kV, kL), -0.2588f, 1e-4f);
  const float mv = mirrorCosine(kN, kL, kV);
  EXPECT_NEAR(mv, 0.966f, 5e-4f);  // 96.6 % of the maximum: 15 degrees off the mirror direction
  EXPECT_NEAR(specularTerm(mv, 10.0f), 0.707f, 1e-3f);  // 70.7 %
  // 3.14 % in the seed, from M·V rounded along the way; unrounded it is 3.11 %.
  EXPECT_NEAR(specularTerm(mv, 100.0f), 0.0314f, 4e-4f);
  EXPECT_NEAR(specularTerm(mv, 100.0f), 0.03113f, 5e-5f);
}

TEST(Shading, MirrorCosineEqualsTheReflectedVector) {
  // M = 2(N·L)N − L; the shortcut must agree with it for any unit vectors.
  const Vec3 ns[] = {kN, glm::normalize(Vec3(0.3f, 0.8f, -0.2f)), Vec3(0, 0, 1)};
  const Vec3 ls[] = {kL, glm::normalize(Vec3(1, 2, 3)), glm::normalize(Vec3(-1, 0.1f, 0.4f))};
  const Vec3 vs[] = {kV, glm::normalize(Vec3(0.2f, 1, 0.1f)), glm::normalize(Vec3(0, -1, 1))};
  for (Vec3 n : ns)
    for (Vec3 l : ls)
      for (Vec3 v : vs) {
        const Vec3 m = 2.0f * glm::dot(n, l) * n - l;
        EXPECT_NEAR(mirrorCosine(n, l, v), glm::dot(m, v), 1e-5f);
      }
  EXPECT_EQ(specularTerm(-0.5f, 10.0f), 0.0f);  // away from V: no highlight
}

TEST(Shading, FullModelPerChannel) {
  Lighting s;
  s.ambient = Vec3(0.1f, 0.2f, 0.3f);
  s.material.ka = Vec3(1.0f, 0.5f, 0.0f);
  s.material.kd = Vec3(0.5f);
  s.material.ks = Vec3(0.4f);
  s.material.n = 10.0f;
  s.falloff = LightFalloff::Light;
  Light light;
  light.type = Light::Type::Point;
  light.vector = kL * 2.0f;  // 2 units away along L: R² = 4
  light.intensity = Vec3(1.0f, 2.0f, 0.5f);
  s.lights = {light};
  const Vec3 color(1.0f, 0.5f, 0.25f);
  const Vec3 p(0.0f), eye = kV * 5.0f;
  const Vec3 i = shade(s, color, p, kN, eye);
  const float spec = std::pow(0.96593f, 10.0f);
  for (int c = 0; c < 3; ++c) {
    const float expect = s.ambient[c] * s.material.ka[c] * color[c] +
                         light.intensity[c] * (0.5f * color[c] * 0.70711f + 0.4f * spec) / 4.0f;
    EXPECT_NEAR(i[c], expect, 1e-4f) << "channel " << c;
  }
  // Directional lights have no falloff; the viewer reading divides by the eye's distance².
  s.lights[0].type = Light::Type::Directional;
  s.lights[0].vector = kL;
  const Vec3 near = shade(s, color, p, kN, eye);
  s.falloff = LightFalloff::Viewer;
  const Vec3 far = shade(s, color, p, kN, eye);
  const Vec3 amb = s.ambient * s.material.ka * color;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR((far[c] - amb[c]) * 25.0f, near[c] - amb[c], 1e-4f);
}

TEST(Shading, LightBehindTheSurfaceLeavesAmbientOnly) {
  Lighting s;
  s.lights = {Light{Light::Type::Directional, -kN, Vec3(1.0f)}};
  const Vec3 c(0.8f, 0.6f, 0.4f);
  const Vec3 i = shade(s, c, Vec3(0.0f), kN, Vec3(0, 5, 5));
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(i[k], s.ambient[k] * s.material.ka[k] * c[k]);
}

TEST(Shading, StrandTangentModel) {
  const Vec3 t(1.0f, 0.0f, 0.0f);
  // L and V across the strand: full diffuse, and V lies on the cone of mirror directions.
  EXPECT_NEAR(strandDiffuseCosine(t, Vec3(0, 1, 0)), 1.0f, 1e-6f);
  EXPECT_NEAR(strandMirrorCosine(t, Vec3(0, 1, 0), Vec3(0, 0, 1)), 1.0f, 1e-6f);
  // Light along the strand: no diffuse.
  EXPECT_NEAR(strandDiffuseCosine(t, t), 0.0f, 1e-6f);
  // The cone of mirror directions of L around T has M·T = −L·T: V on it gives 1, V mirrored
  // along T does not.
  const Vec3 l = glm::normalize(Vec3(1, 1, 0));
  EXPECT_NEAR(strandMirrorCosine(t, l, glm::normalize(Vec3(-1, 0, 1))), 1.0f, 1e-5f);
  EXPECT_NEAR(strandMirrorCosine(t, l, glm::normalize(Vec3(1, 0, 1))), 0.0f, 1e-5f);
  // It is the seed's M·V for the normal in the plane of T and L when V is in that plane too.
  const Vec3 n = glm::normalize(l - glm::dot(l, t) * t);
  const Vec3 v = glm::normalize(Vec3(-0.3f, 1.0f, 0.0f));
  EXPECT_NEAR(strandMirrorCosine(t, l, v), mirrorCosine(n, l, v), 1e-5f);
}

// ---- The effect file's `render` object -------------------------------------------------------
#include "flurry/render.hpp"

TEST(RenderSettingsJson, ReadsEveryField) {
  const RenderSettings s = parseRenderSettings(R"({
    "camera": {"target": [0, 2, 0], "distance": 12, "yaw": 30, "pitch": 20, "fov": 50},
    "background": [0.1, 0.2, 0.3], "sprite": "tex/flake.png", "blend": "additive",
    "sort": false, "strands": "line", "shading": false, "litMinPixels": 2, "ambient": 0.5,
    "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [1, 0.5, 0.25]}],
    "material": {"ka": [1, 0.9, 0.8], "kd": 0.7, "ks": 0.3, "n": 40}, "falloff": "viewer"})",
                                               "/fx");
  EXPECT_EQ(s.camera.target, Vec3(0, 2, 0));
  EXPECT_EQ(s.camera.distance, 12.0f);
  EXPECT_EQ(s.camera.fovY, 50.0f);
  EXPECT_EQ(s.background, Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(s.sprite, Sprite::Image);
  EXPECT_EQ(s.spriteImage, "/fx/tex/flake.png");
  EXPECT_EQ(s.blend, BlendMode::Additive);
  EXPECT_FALSE(s.sortForAlpha);
  EXPECT_EQ(s.strandStyle, StrandStyle::Line);
  EXPECT_FALSE(s.shading);
  EXPECT_EQ(s.litMinPixels, 2.0f);
  EXPECT_EQ(s.lighting.ambient, Vec3(0.5f));
  ASSERT_EQ(s.lighting.lights.size(), 1u);
  EXPECT_EQ(s.lighting.lights[0].type, Light::Type::Point);
  EXPECT_EQ(s.lighting.lights[0].intensity, Vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(s.lighting.material.ka, Vec3(1, 0.9f, 0.8f));
  EXPECT_EQ(s.lighting.material.n, 40.0f);
  EXPECT_EQ(s.lighting.falloff, LightFalloff::Viewer);
  // Absent fields keep the defaults.
  const RenderSettings d = parseRenderSettings("{}");
  EXPECT_EQ(d.sprite, Sprite::Disc);
  EXPECT_EQ(d.lighting.lights.size(), 1u);
  EXPECT_EQ(d.toneMap, ToneMap::None);
  EXPECT_FALSE(d.transparent);
  EXPECT_FALSE(d.geometry.show);
}

TEST(RenderSettingsJson, ReadsTheLookOptions) {
  const RenderSettings s = parseRenderSettings(R"({"sprite": "glow", "toneMap": "aces",
    "exposure": 1.5, "transparent": true,
    "geometry": {"color": [0.1, 0.2, 0.3], "opacity": 0.5, "sink": false}})");
  EXPECT_EQ(s.sprite, Sprite::Glow);
  EXPECT_EQ(s.toneMap, ToneMap::Aces);
  EXPECT_EQ(s.exposure, 1.5f);
  EXPECT_TRUE(s.transparent);
  EXPECT_TRUE(s.geometry.show);  // an object turns it on unless it says "show": false
  EXPECT_EQ(s.geometry.color, Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(s.geometry.opacity, 0.5f);
  EXPECT_FALSE(s.geometry.sink);
  EXPECT_TRUE(s.geometry.bounce);
  EXPECT_EQ(parseRenderSettings(R"({"sprite": "puff", "toneMap": "reinhard"})").toneMap,
            ToneMap::Reinhard);
  EXPECT_EQ(parseRenderSettings(R"({"sprite": "puff"})").sprite, Sprite::Puff);
  EXPECT_TRUE(parseRenderSettings(R"({"geometry": true})").geometry.show);
  EXPECT_FALSE(parseRenderSettings(R"({"geometry": {"show": false}})").geometry.show);
}

TEST(RenderSettingsJson, ReadsStretchAndGroupLooks) {
  const RenderSettings s = parseRenderSettings(R"({"stretch": 0.05, "maxStretch": 6,
    "$comment": "comments are allowed, as in the rest of the file",
    "groups": {"$comment": "also here", "flames": {"sprite": "glow", "blend": "additive", "shading": false, "$comment": "x"},
               "rain": {"sprite": "drop.png", "stretch": 0.1, "maxStretch": 20, "sort": false}}})",
                                               "/fx");
  EXPECT_EQ(s.stretch, 0.05f);
  EXPECT_EQ(s.maxStretch, 6.0f);
  ASSERT_EQ(s.groups.size(), 2u);
  const GroupLook& f = s.groups[0];
  EXPECT_EQ(f.group, "flames");
  EXPECT_EQ(f.sprite, Sprite::Glow);
  EXPECT_EQ(f.blend, BlendMode::Additive);
  EXPECT_EQ(f.shading, false);
  EXPECT_FALSE(f.stretch.has_value());  // unset: the settings' value applies
  EXPECT_FALSE(f.sortForAlpha.has_value());
  const GroupLook& r = s.groups[1];
  EXPECT_EQ(r.group, "rain");
  EXPECT_EQ(r.sprite, Sprite::Image);
  EXPECT_EQ(r.spriteImage, "/fx/drop.png");
  EXPECT_EQ(r.stretch, 0.1f);
  EXPECT_EQ(r.maxStretch, 20.0f);
  EXPECT_EQ(r.sortForAlpha, false);
  EXPECT_FALSE(r.blend.has_value());
  const RenderSettings d = parseRenderSettings("{}");
  EXPECT_EQ(d.stretch, 0.0f);
  EXPECT_TRUE(d.groups.empty());
}

TEST(RenderSettingsJson, ErrorsNameTheField) {
  auto pathOf = [](const char* json) {
    try {
      parseRenderSettings(json);
    } catch (const InvalidArgument& e) {
      return e.parameter();
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(pathOf(R"({"camera": {"pitch": 95}})"), "render.camera.pitch");
  EXPECT_EQ(pathOf(R"({"camera": {"yaww": 1}})"), "render.camera.yaww");
  EXPECT_EQ(pathOf(R"({"blend": "multiply"})"), "render.blend");
  EXPECT_EQ(pathOf(R"({"lights": [{"type": "point"}]})"), "render.lights[0].position");
  EXPECT_EQ(pathOf(R"({"material": {"kd": [1, 2]}})"), "render.material.kd");
  EXPECT_EQ(pathOf(R"({"ambient": "bright"})"), "render.ambient");
  EXPECT_EQ(pathOf("{not json"), "render");
  EXPECT_EQ(pathOf(R"({"toneMap": "filmic"})"), "render.toneMap");
  EXPECT_EQ(pathOf(R"({"exposure": 0})"), "render.exposure");
  EXPECT_EQ(pathOf(R"({"transparent": 1})"), "render.transparent");
  EXPECT_EQ(pathOf(R"({"geometry": "yes"})"), "render.geometry");
  EXPECT_EQ(pathOf(R"({"geometry": {"opacity": 2}})"), "render.geometry.opacity");
  EXPECT_EQ(pathOf(R"({"geometry": {"colour": [1, 1, 1]}})"), "render.geometry.colour");
  EXPECT_EQ(pathOf(R"({"geometry": {"sink": "no"}})"), "render.geometry.sink");
  EXPECT_EQ(pathOf(R"({"stretch": -1})"), "render.stretch");
  EXPECT_EQ(pathOf(R"({"maxStretch": 0.5})"), "render.maxStretch");
  EXPECT_EQ(pathOf(R"({"groups": []})"), "render.groups");
  EXPECT_EQ(pathOf(R"({"groups": {"a": 1}})"), "render.groups.a");
  EXPECT_EQ(pathOf(R"({"groups": {"a": {"toneMap": "aces"}}})"), "render.groups.a.toneMap");
  EXPECT_EQ(pathOf(R"({"groups": {"a": {"blend": "max"}}})"), "render.groups.a.blend");
  EXPECT_EQ(pathOf(R"({"groups": {"a": {"stretch": "long"}}})"), "render.groups.a.stretch");
  EXPECT_EQ(pathOf(R"({"groups": {"a": {"sprite": 3}}})"), "render.groups.a.sprite");
}
