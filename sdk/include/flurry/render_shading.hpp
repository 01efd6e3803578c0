// The seed's simple shading model, on the CPU, GL-free. flurry::render's shaders compute the
// same formulas per pixel; these functions are the reference the tests check them against.
//
//   I = Ia·ka·C + Σ_lights Ip·(kd·C·(L·N) + ks·(M·V)^n) / R²      per color channel
//
// with C the particle's color (the surface's own color scales ka and kd, as the seed's color
// shading has k_aR, k_aG, k_aB; the highlight keeps the light's color), L the unit vector
// towards the light, N the surface normal, V the unit vector towards the viewer, M the
// mirror direction of L, and R the falloff distance. M·V is computed without M, as the
// seed does: M·V = 2(N·L)(N·V) − V·L.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "flurry/math.hpp"

namespace flurry {

/// A light: Ip per color channel, either at infinity or at a point.
struct Light {
  enum class Type { Directional, Point };
  Type type = Type::Directional;
  /// Directional: the direction towards the light (normalized when used).
  /// Point: the light's position.
  Vec3 vector{0.5f, 1.0f, 0.8f};
  /// Ip, per channel.
  Vec3 intensity{1.0f};
};

/// The material coefficients (per channel), and the specular exponent n.
struct Material {
  Vec3 ka{1.0f};  ///< ambient reflection
  Vec3 kd{0.8f};  ///< diffuse (Lambert) reflection
  Vec3 ks{0.4f};  ///< specular reflection
  float n = 20.0f;
};

/// What R in the 1/R² term measures.
enum class LightFalloff {
  None,    ///< R = 1
  Light,   ///< R = distance from a point light to the particle (directional lights: 1)
  Viewer,  ///< R = distance from the viewer to the particle (the seed's literal reading)
};

/// The lights of a scene and the particles' material.
struct Lighting {
  Vec3 ambient{0.25f};                 ///< Ia, per channel
  std::vector<Light> lights{Light{}};  ///< flurry::render takes up to 8
  Material material;
  LightFalloff falloff = LightFalloff::Light;
};

/// The seed's M·V without M: 2(N·L)(N·V) − V·L (unit vectors).
inline float mirrorCosine(Vec3 n, Vec3 l, Vec3 v) {
  return 2.0f * glm::dot(n, l) * glm::dot(n, v) - glm::dot(v, l);
}

/// (M·V)^n, zero where M points away from V.
inline float specularTerm(float mirrorCos, float n) {
  return mirrorCos > 0.0f ? std::pow(mirrorCos, n) : 0.0f;
}

/// Strands have a tangent T and no single normal: the normal used is the one in the plane of
/// T and L, so L·N = sqrt(1 − (L·T)²), and the mirror directions of L form a cone around T,
/// the nearest of which to V gives M·V = sqrt(1 − (L·T)²)·sqrt(1 − (V·T)²) − (L·T)(V·T).
inline float strandDiffuseCosine(Vec3 t, Vec3 l) {
  const float lt = glm::dot(l, t);
  return std::sqrt(std::max(0.0f, 1.0f - lt * lt));
}
inline float strandMirrorCosine(Vec3 t, Vec3 l, Vec3 v) {
  const float lt = glm::dot(l, t), vt = glm::dot(v, t);
  return std::sqrt(std::max(0.0f, 1.0f - lt * lt)) * std::sqrt(std::max(0.0f, 1.0f - vt * vt)) -
         lt * vt;
}

namespace detail {
// Unit L and 1/R² of one light seen from p.
inline void lightAt(const Light& light, LightFalloff falloff, Vec3 p, Vec3 eye, Vec3& l,
                    float& invR2) {
  float r2 = 1.0f;
  if (light.type == Light::Type::Point) {
    const Vec3 d = light.vector - p;
    l = glm::normalize(d);
    if (falloff == LightFalloff::Light) r2 = glm::dot(d, d);
  } else {
    l = glm::normalize(light.vector);
  }
  if (falloff == LightFalloff::Viewer) r2 = glm::dot(eye - p, eye - p);
  invR2 = 1.0f / std::max(r2, 1e-8f);
}
}  // namespace detail

/// I at point p of a surface with unit normal n and color c, seen from eye.
inline Vec3 shade(const Lighting& s, Vec3 c, Vec3 p, Vec3 n, Vec3 eye) {
  const Vec3 v = glm::normalize(eye - p);
  Vec3 i = s.ambient * s.material.ka * c;
  for (const Light& light : s.lights) {
    Vec3 l;
    float invR2;
    detail::lightAt(light, s.falloff, p, eye, l, invR2);
    const float ln = glm::dot(l, n);
    if (ln <= 0.0f) continue;  // the light is behind the surface: no diffuse, no highlight
    const float spec = specularTerm(mirrorCosine(n, l, v), s.material.n);
    i += light.intensity * (s.material.kd * c * ln + s.material.ks * spec) * invR2;
  }
  return i;
}

/// I at point p of a strand with unit tangent t and color c, seen from eye.
inline Vec3 shadeStrand(const Lighting& s, Vec3 c, Vec3 p, Vec3 t, Vec3 eye) {
  const Vec3 v = glm::normalize(eye - p);
  Vec3 i = s.ambient * s.material.ka * c;
  for (const Light& light : s.lights) {
    Vec3 l;
    float invR2;
    detail::lightAt(light, s.falloff, p, eye, l, invR2);
    const float spec = specularTerm(strandMirrorCosine(t, l, v), s.material.n);
    i += light.intensity * (s.material.kd * c * strandDiffuseCosine(t, l) + s.material.ks * spec) *
         invR2;
  }
  return i;
}

}  // namespace flurry
