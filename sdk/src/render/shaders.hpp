// GLSL 330 sources. The lighting functions mirror flurry/render_shading.hpp line for line.
#pragma once

namespace flurry::detail::glsl {

inline constexpr int kMaxLights = 8;

inline constexpr const char* kLighting = R"(
const int MAX_LIGHTS = 8;
uniform int uLightCount;
uniform int uLightType[MAX_LIGHTS];   // 0 directional, 1 point
uniform vec3 uLightVec[MAX_LIGHTS];   // direction towards the light (unit), or position
uniform vec3 uLightI[MAX_LIGHTS];     // Ip
uniform vec3 uAmbient;                // Ia
uniform vec3 uKa, uKd, uKs;
uniform float uN;
uniform int uFalloff;                 // 0 none, 1 light distance, 2 viewer distance
uniform vec3 uEye;

void lightAt(int k, vec3 p, out vec3 l, out float invR2) {
  float r2 = 1.0;
  if (uLightType[k] == 1) {
    vec3 d = uLightVec[k] - p;
    l = normalize(d);
    if (uFalloff == 1) r2 = dot(d, d);
  } else {
    l = uLightVec[k];
  }
  if (uFalloff == 2) r2 = dot(uEye - p, uEye - p);
  invR2 = 1.0 / max(r2, 1e-8);
}

float specularTerm(float mirrorCos) { return mirrorCos > 0.0 ? pow(mirrorCos, uN) : 0.0; }

// I = Ia ka C + sum Ip (kd C (L.N) + ks (M.V)^n) / R^2, with M.V = 2(N.L)(N.V) - V.L
vec3 shade(vec3 c, vec3 p, vec3 n) {
  vec3 v = normalize(uEye - p);
  vec3 i = uAmbient * uKa * c;
  for (int k = 0; k < uLightCount; ++k) {
    vec3 l; float invR2;
    lightAt(k, p, l, invR2);
    float ln = dot(l, n);
    if (ln <= 0.0) continue;
    float spec = specularTerm(2.0 * ln * dot(n, v) - dot(v, l));
    i += uLightI[k] * (uKd * c * ln + uKs * spec) * invR2;
  }
  return i;
}

// The tangent-based equivalent for strands.
vec3 shadeStrand(vec3 c, vec3 p, vec3 t) {
  vec3 v = normalize(uEye - p);
  vec3 i = uAmbient * uKa * c;
  for (int k = 0; k < uLightCount; ++k) {
    vec3 l; float invR2;
    lightAt(k, p, l, invR2);
    float lt = dot(l, t), vt = dot(v, t);
    float sl = sqrt(max(0.0, 1.0 - lt * lt)), sv = sqrt(max(0.0, 1.0 - vt * vt));
    float spec = specularTerm(sl * sv - lt * vt);
    i += uLightI[k] * (uKd * c * sl + uKs * spec) * invR2;
  }
  return i;
}
)";

// Shared by the billboard and point vertex shaders: pixels per world unit at a view depth.
inline constexpr const char* kProjection = R"(
uniform mat4 uView, uProj;
uniform vec2 uViewport;
uniform float uLitMinPixels;
uniform bool uShading;
float pixelsPerUnit(float depth) { return uProj[1][1] * 0.5 * uViewport.y / max(depth, 1e-6); }
)";

inline constexpr const char* kBillboardVs = R"(
layout(location = 0) in vec2 aCorner;
layout(location = 1) in vec4 aCenterRadius;
layout(location = 2) in vec4 aColor;
layout(location = 3) in vec3 aVelocity;  // (0, 0, 0) unless the sprites are stretched
uniform float uStretch;     // seconds of path a sprite covers; 0: round
uniform float uMaxStretch;  // the most a sprite's length may be, in widths
out vec2 vUV;         // x along the streak, in half sizes from its middle; y across
flat out float vHalfStreak;  // half the streak's length, in half sizes
flat out vec2 vDir;   // the streak's screen direction (x when round)
flat out vec4 vColor;
flat out vec3 vCenter;
flat out float vRadius;
flat out int vMode;  // 0: sub-pixel, 1: unshaded sprite, 2: shaded sprite
void main() {
  vec4 c = uView * vec4(aCenterRadius.xyz, 1.0);
  float depth = max(-c.z, 1e-6);
  float ppu = pixelsPerUnit(depth);
  float rpx = aCenterRadius.w * ppu;
  float halfSize = aCenterRadius.w;
  // The streak: the projection's derivative along the view-space velocity, over uStretch
  // seconds, in view units at this depth (screen x = x / depth, so d/dt = (vx + x vz / depth)
  // / depth).
  vec3 v = mat3(uView) * aVelocity;
  vec2 streak = uStretch * (v.xy + c.xy * v.z / depth);
  float len = length(streak);
  vec2 dir = len > 1e-9 ? streak / len : vec2(1.0, 0.0);
  vColor = aColor;
  if (rpx < 0.5) {
    // One pixel wide, its alpha the disc's coverage of that pixel; a streak's pixels are
    // covered across its width instead.
    halfSize = 0.5 / ppu;
    float streakPx = min(len * ppu, 1.0);
    vColor.a *= mix(3.14159265 * rpx * rpx, min(1.0, 2.0 * rpx), streakPx);
    vMode = 0;
  } else {
    vMode = (uShading && rpx >= uLitMinPixels) ? 2 : 1;
  }
  len = min(len, (uMaxStretch - 1.0) * 2.0 * halfSize);
  vec2 side = vec2(-dir.y, dir.x);
  // Along dir the quad covers the sprite swept along the streak, which trails the particle:
  // its caps are the sprite's two halves, its middle the sprite's centre line across.
  // Unstretched it is the plain billboard.
  vec2 offset = dir * (aCorner.x * (halfSize + 0.5 * len) - 0.5 * len) + side * aCorner.y * halfSize;
  vHalfStreak = 0.5 * len / halfSize;
  vUV = vec2(aCorner.x * (1.0 + vHalfStreak), aCorner.y);
  vDir = dir;
  vCenter = aCenterRadius.xyz;
  vRadius = aCenterRadius.w;
  gl_Position = uProj * vec4(c.xy + offset, c.z, 1.0);
}
)";

inline constexpr const char* kBillboardFs = R"(
in vec2 vUV;
flat in float vHalfStreak;
flat in vec2 vDir;
flat in vec4 vColor;
flat in vec3 vCenter;
flat in float vRadius;
flat in int vMode;
uniform sampler2D uSprite;
uniform mat3 uViewToWorld;
uniform bool uFlat;  // glow, puff: one normal facing the eye, so no sprite reads as a ball
out vec4 oColor;
void main() {
  if (vMode == 0) {
    oColor = vColor;
    return;
  }
  // The sprite swept along the streak: its coordinate across the middle is its centre line.
  vec2 uv = vec2(sign(vUV.x) * max(abs(vUV.x) - vHalfStreak, 0.0), vUV.y);
  vec4 t = texture(uSprite, uv * 0.5 + 0.5);
  float a = vColor.a * t.a;
  if (a <= 0.0) discard;
  vec3 base = vColor.rgb * t.rgb;
  if (vMode == 2 && uFlat) {
    vec3 n = normalize(uEye - vCenter);
    base = shade(base, vCenter, n);
  } else if (vMode == 2) {
    // A sphere's normal under the billboard (a capsule's when stretched); outside the
    // disc, the rim's. uv turned back to screen axes.
    vec2 q = uv.x * vDir + uv.y * vec2(-vDir.y, vDir.x);
    float r2 = dot(q, q);
    vec3 nv = r2 < 1.0 ? vec3(q, sqrt(1.0 - r2)) : vec3(q * inversesqrt(r2), 0.0);
    vec3 n = normalize(uViewToWorld * nv);
    base = shade(base, vCenter + vRadius * n, n);
  }
  oColor = vec4(base, a);
}
)";

inline constexpr const char* kPointVs = R"(
layout(location = 1) in vec4 aCenterRadius;
layout(location = 2) in vec4 aColor;
flat out vec4 vColor;
flat out float vSize;
void main() {
  vec4 c = uView * vec4(aCenterRadius.xyz, 1.0);
  float rpx = aCenterRadius.w * pixelsPerUnit(-c.z);
  vColor = aColor;
  if (rpx < 0.5) vColor.a *= 3.14159265 * rpx * rpx;
  // One pixel wider than the disc, so its anti-aliased rim fits inside the point.
  vSize = max(1.0, 2.0 * rpx);
  gl_PointSize = vSize > 1.5 ? vSize + 1.0 : vSize;
  gl_Position = uProj * c;
}
)";

// GL rasterises wide points as squares, multisampled or not: the fragment shader cuts the
// disc out, its rim's alpha the pixel's coverage, so points are round and anti-aliased.
inline constexpr const char* kPointFs = R"(
flat in vec4 vColor;
flat in float vSize;
out vec4 oColor;
void main() {
  float a = vColor.a;
  if (vSize > 1.5) {
    float rpx = length(gl_PointCoord * 2.0 - 1.0) * 0.5 * (vSize + 1.0);
    a *= clamp(0.5 * vSize - rpx + 0.5, 0.0, 1.0);
    if (a <= 0.0) discard;
  }
  oColor = vec4(vColor.rgb, a);
}
)";

// Scene geometry: lines and faint faces in one colour per vertex.
inline constexpr const char* kGeometryVs = R"(
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec4 aColor;
uniform mat4 uView, uProj;
out vec4 vColor;
void main() {
  vColor = aColor;
  gl_Position = uProj * uView * vec4(aPos, 1.0);
}
)";

inline constexpr const char* kGeometryFs = R"(
in vec4 vColor;
out vec4 oColor;
void main() { oColor = vColor; }
)";

// The tone map: a full-screen triangle reading the resolved HDR image.
inline constexpr const char* kToneMapVs = R"(
out vec2 vUV;
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  vUV = p * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

inline constexpr const char* kToneMapFs = R"(
in vec2 vUV;
uniform sampler2D uHdr;
uniform int uCurve;  // 1 Reinhard, 2 ACES
uniform float uExposure;
uniform bool uTransparent;
out vec4 oColor;
void main() {
  vec4 h = texture(uHdr, vUV);
  float a = clamp(h.a, 0.0, 1.0);
  // On a transparent background the colour accumulated premultiplied: map the straight one.
  vec3 c = max(uTransparent ? (a > 0.0 ? h.rgb / a : vec3(0.0)) : h.rgb, vec3(0.0)) * uExposure;
  if (uCurve == 1) {
    c = c / (1.0 + c);
  } else {
    c = clamp((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), 0.0, 1.0);
  }
  oColor = vec4(c, uTransparent ? a : 1.0);
}
)";

inline constexpr const char* kStrandVs = R"(
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aTangent;
layout(location = 2) in vec2 aRadiusSide;  // radius, side (-1, +1; 0 for lines)
layout(location = 3) in vec4 aColor;
uniform bool uLines;
uniform vec3 uEye;
out vec3 vWorld;
out vec3 vTangent;
out vec4 vColor;
out float vLit;
void main() {
  vec4 c = uView * vec4(aPos, 1.0);
  float ppu = pixelsPerUnit(-c.z);
  float rpx = aRadiusSide.x * ppu;
  float r = aRadiusSide.x;
  vColor = aColor;
  if (uLines) {
    vColor.a *= min(1.0, 2.0 * rpx);
  } else if (rpx < 0.5) {
    // At least a pixel wide; its alpha the strand's share of that pixel.
    r = 0.5 / ppu;
    vColor.a *= 2.0 * rpx;
  }
  vec3 world = aPos;
  if (!uLines) {
    vec3 side = cross(aTangent, uEye - aPos);
    // Seen end-on the ribbon has no facing side: use the camera's right.
    if (dot(side, side) < 1e-12) side = vec3(uView[0][0], uView[1][0], uView[2][0]);
    world += normalize(side) * r * aRadiusSide.y;
  }
  vLit = (uShading && !uLines && rpx >= uLitMinPixels) ? 1.0 : 0.0;
  vWorld = world;
  vTangent = aTangent;
  gl_Position = uProj * uView * vec4(world, 1.0);
}
)";

inline constexpr const char* kStrandFs = R"(
in vec3 vWorld;
in vec3 vTangent;
in vec4 vColor;
in float vLit;
out vec4 oColor;
void main() {
  vec3 col = vColor.rgb;
  if (vLit > 0.0) col = mix(col, shadeStrand(col, vWorld, normalize(vTangent)), vLit);
  oColor = vec4(col, vColor.a);
}
)";

}  // namespace flurry::detail::glsl
