// Gradient noise with its analytic gradient, and the divergence-free curl noise built from
// it (Bridson, Hourihan, Nordenstam: "Curl-noise for procedural fluid flow", 2007).
#pragma once

#include <cmath>
#include <cstdint>

#include "flurry/math.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

// A hash of integer lattice coordinates (and a seed) to a gradient among the 12 edge
// directions of a cube: no table, so the same function runs in an OpenCL kernel.
inline std::uint32_t latticeHash(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t seed) {
  std::uint32_t h = seed ^ 0x9E3779B9u;
  h ^= std::uint32_t(x) * 0x85EBCA6Bu;
  h = (h << 13) | (h >> 19);
  h ^= std::uint32_t(y) * 0xC2B2AE35u;
  h = (h << 13) | (h >> 19);
  h ^= std::uint32_t(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

inline Vec3 latticeGradient(std::uint32_t h) {
  switch (h % 12u) {
    case 0: return {1, 1, 0};
    case 1: return {-1, 1, 0};
    case 2: return {1, -1, 0};
    case 3: return {-1, -1, 0};
    case 4: return {1, 0, 1};
    case 5: return {-1, 0, 1};
    case 6: return {1, 0, -1};
    case 7: return {-1, 0, -1};
    case 8: return {0, 1, 1};
    case 9: return {0, -1, 1};
    case 10: return {0, 1, -1};
    default: return {0, -1, -1};
  }
}

/// Perlin gradient noise at p with quintic fade; `gradient` receives its exact derivative.
inline float gradientNoise(Vec3 p, std::uint32_t seed, Vec3& gradient) {
  const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
  const std::int32_t ix = std::int32_t(fx), iy = std::int32_t(fy), iz = std::int32_t(fz);
  const Vec3 f(p.x - fx, p.y - fy, p.z - fz);
  auto fade = [](float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); };
  auto dfade = [](float t) { return 30.0f * t * t * (t * (t - 2.0f) + 1.0f); };
  const Vec3 u(fade(f.x), fade(f.y), fade(f.z));
  const Vec3 du(dfade(f.x), dfade(f.y), dfade(f.z));
  float value = 0.0f;
  gradient = Vec3(0.0f);
  for (int c = 0; c < 8; ++c) {
    const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
    const Vec3 g = latticeGradient(latticeHash(ix + ox, iy + oy, iz + oz, seed));
    const Vec3 d(f.x - float(ox), f.y - float(oy), f.z - float(oz));
    const float n = glm::dot(g, d);
    const float wx = ox ? u.x : 1.0f - u.x, wy = oy ? u.y : 1.0f - u.y, wz = oz ? u.z : 1.0f - u.z;
    const float sx = ox ? du.x : -du.x, sy = oy ? du.y : -du.y, sz = oz ? du.z : -du.z;
    const float w = wx * wy * wz;
    value += w * n;
    // d/dp (w·n) = n·dw/dp + w·g
    gradient += g * w + Vec3(sx * wy * wz, wx * sy * wz, wx * wy * sz) * n;
  }
  return value;
}

/// The curl of a vector potential of three noise fields: divergence-free by construction.
/// Octaves double the frequency and halve the amplitude.
inline Vec3 curlNoise(Vec3 p, int octaves = 1) {
  Vec3 curl(0.0f);
  float scale = 1.0f, freq = 1.0f;
  for (int o = 0; o < octaves; ++o) {
    Vec3 g1, g2, g3;
    const Vec3 q = p * freq;
    gradientNoise(q, 0x1234u + 3u * o, g1);
    gradientNoise(q + Vec3(31.416f, 47.853f, 12.793f), 0x5678u + 3u * o, g2);
    gradientNoise(q + Vec3(-61.77f, 19.19f, 83.41f), 0x9ABCu + 3u * o, g3);
    // The derivatives are with respect to q = p·freq: ∂/∂p = freq·∂/∂q.
    curl += Vec3(g3.y - g2.z, g1.z - g3.x, g2.x - g1.y) * (scale * freq);
    scale *= 0.5f;
    freq *= 2.0f;
  }
  return curl;
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
