#include "render/sprites.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace flurry::detail {

namespace {

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

float segmentDistance(float px, float py, float ax, float ay, float bx, float by) {
  const float dx = bx - ax, dy = by - ay;
  const float t = std::clamp(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0f, 1.0f);
  return std::hypot(px - ax - t * dx, py - ay - t * dy);
}

// Alpha of each shape at (x, y) in [-1, 1]^2.
float discAlpha(float x, float y) {
  // Opaque inside so a lit particle reads as a ball; a soft rim so it does not alias.
  return 1.0f - smoothstep(0.8f, 1.0f, std::hypot(x, y));
}

float sparkAlpha(float x, float y) {
  const float r = std::hypot(x, y);
  const float core = std::exp(-r * r / 0.02f);
  const float glow = 0.5f * std::pow(std::max(0.0f, 1.0f - r), 3.0f);
  const float ax = std::abs(x), ay = std::abs(y);
  const float rays = std::max(std::exp(-ay * ay / 0.0008f) * std::max(0.0f, 1.0f - ax),
                              std::exp(-ax * ax / 0.0008f) * std::max(0.0f, 1.0f - ay));
  return std::clamp(core + glow + 0.9f * rays, 0.0f, 1.0f);
}

float snowflakeAlpha(float x, float y) {
  // Six arms, each with two pairs of side branches at 60 degrees.
  constexpr float w = 0.055f;
  float d = std::hypot(x, y) - 0.12f;  // a small hub
  for (int k = 0; k < 6; ++k) {
    const float a = float(k) * std::numbers::pi_v<float> / 3.0f;
    const float cx = std::cos(a), cy = std::sin(a);
    d = std::min(d, segmentDistance(x, y, 0, 0, 0.92f * cx, 0.92f * cy));
    for (const auto& [at, len] :
         std::array<std::pair<float, float>, 2>{{{0.45f, 0.3f}, {0.7f, 0.18f}}}) {
      const float bx = at * cx, by = at * cy;
      for (float side : {-1.0f, 1.0f}) {
        const float b = a + side * std::numbers::pi_v<float> / 3.0f;
        d = std::min(d,
                     segmentDistance(x, y, bx, by, bx + len * std::cos(b), by + len * std::sin(b)));
      }
    }
  }
  return 1.0f - smoothstep(w * 0.5f, w, d);
}

// A gaussian glow that reaches zero at the quad's edge: no visible square, a bright core.
float glowAlpha(float x, float y) {
  const float r2 = x * x + y * y;
  return std::max(0.0f, std::exp(-r2 * 4.0f) - std::exp(-4.0f)) / (1.0f - std::exp(-4.0f));
}

// A soft puff: a smooth falloff made lumpy by a few fixed lobes, so overlapping puffs read
// as billowing smoke rather than as discs. Fixed: the same bitmap on every run.
float puffAlpha(float x, float y) {
  const float r = std::hypot(x, y);
  const float a = std::atan2(y, x);
  const float lumps = 0.12f * std::sin(3.0f * a + 0.7f) + 0.08f * std::sin(5.0f * a + 2.1f) +
                      0.06f * std::sin(7.0f * a + 4.0f) * r;
  const float edge = std::clamp(1.0f - r / (0.85f + lumps), 0.0f, 1.0f);
  const float inner = 0.85f + 0.15f * std::sin(9.0f * x + 4.0f * y) * std::sin(7.0f * y - 3.0f * x);
  return edge * edge * (3.0f - 2.0f * edge) * inner;
}

}  // namespace

Image spriteBitmap(Sprite sprite, const std::string& path, int size) {
  if (sprite == Sprite::Image) {
    if (path.empty()) throw InvalidArgument("spriteImage", "Sprite::Image needs a PNG path");
    Image img = readPng(path);
    // Flip to bottom-to-top rows so the image is upright on the billboard.
    const std::size_t row = std::size_t(img.width) * 4;
    for (int y = 0; y < img.height / 2; ++y)
      std::swap_ranges(img.rgba.begin() + std::ptrdiff_t(y * row),
                       img.rgba.begin() + std::ptrdiff_t((y + 1) * row),
                       img.rgba.begin() + std::ptrdiff_t((img.height - 1 - y) * row));
    return img;
  }
  Image img;
  img.width = img.height = size;
  img.rgba.assign(std::size_t(size) * size * 4, 255);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const float x = (float(i) + 0.5f) / float(size) * 2.0f - 1.0f;
      const float y = (float(j) + 0.5f) / float(size) * 2.0f - 1.0f;
      float a = 1.0f;
      switch (sprite) {
        case Sprite::Spark:
          a = sparkAlpha(x, y);
          break;
        case Sprite::Snowflake:
          a = snowflakeAlpha(x, y);
          break;
        case Sprite::Glow:
          a = glowAlpha(x, y);
          break;
        case Sprite::Puff:
          a = puffAlpha(x, y);
          break;
        default:
          a = discAlpha(x, y);
          break;
      }
      img.pixel(i, j)[3] = std::uint8_t(std::lround(a * 255.0f));
    }
  return img;
}

}  // namespace flurry::detail
