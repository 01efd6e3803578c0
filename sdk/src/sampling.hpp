// Drawing from domains and fuzzy values in batches, for emission.
//
// Random numbers are compute-bound (Philox is ~2 ns per uniform here), so emission draws them
// for a whole batch of newborns at once, one Philox block per particle per loop, and every
// shape samples a batch from arrays of uniforms with branch-free, libm-free formulas the
// compiler vectorises. Domain::sample() is the same code with a batch of one, so a
// particle's attributes do not depend on which path drew them. Uniform number k of a stream
// is always word k % 4 of Philox block k / 4 (the flurry::Random order), on every backend.
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "flurry/domain.hpp"
#include "flurry/fuzzy.hpp"
#include "flurry/random.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
// Compiled once per instruction set, like the fused pass that samples for its random
// actions (isa_namespace.hpp): each build calls its own copies.
inline namespace FLURRY_ISA_NAMESPACE {

constexpr float kTwoPiF = 6.28318530717958647692f;

/// sin(2πu) and cos(2πu) for u in [0, 1), |error| < 3e-7: quadrant reduction and Cephes'
/// minimax polynomials on [-π/4, π/4]; the quadrant is applied with bit operations.
inline void sinCos2Pi(float u, float& s, float& c) {
  const float x = 4.0f * u;
  const std::int32_t q = std::int32_t(x + 0.5f);  // nearest quadrant, u >= 0
  const float r = (x - float(q)) * 1.57079632679489662f;
  const float r2 = r * r;
  const float sr =
      r + r * r2 * (-1.6666654611e-1f + r2 * (8.3321608736e-3f + r2 * -1.9515295891e-4f));
  const float cr =
      1.0f - 0.5f * r2 +
      r2 * r2 * (4.166664568298827e-2f + r2 * (-1.388731625493765e-3f + r2 * 2.443315711809948e-5f));
  const std::uint32_t swap = 0u - std::uint32_t(q & 1);  // odd quadrants swap sin and cos
  const std::uint32_t sb = std::bit_cast<std::uint32_t>(sr), cb = std::bit_cast<std::uint32_t>(cr);
  const std::uint32_t sSign = std::uint32_t(q & 2) << 30;
  const std::uint32_t cSign = std::uint32_t((q + 1) & 2) << 30;
  s = std::bit_cast<float>(((sb & ~swap) | (cb & swap)) ^ sSign);
  c = std::bit_cast<float>(((cb & ~swap) | (sb & swap)) ^ cSign);
}

/// Cube root of x >= 0 to about 1 ulp: an exponent-bits guess refined by Newton's method.
inline float cbrtNonNegative(float x) {
  const std::uint32_t i = std::bit_cast<std::uint32_t>(x);
  float y = std::bit_cast<float>(std::uint32_t(float(i) * (1.0f / 3.0f)) + 0x2a5137a0u);
  for (int k = 0; k < 4; ++k) y -= (y - x / (y * y)) * (1.0f / 3.0f);
  return x > 0.0f ? y : 0.0f;
}

/// Two unit vectors completing unit n to an orthonormal basis (Duff et al., JCGT 2017).
inline void orthonormalBasis(Vec3 n, Vec3& b1, Vec3& b2) {
  const float s = std::copysign(1.0f, n.z);
  const float a = -1.0f / (s + n.z);
  const float b = n.x * n.y * a;
  b1 = Vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = Vec3(b, s + n.y * n.y * a, -n.y);
}

/// Uniform numbers a shape consumes per sample (at most kMaxDomainDraws).
int drawCount(const Domain& d);
inline constexpr int kMaxDomainDraws = 16;
/// Uniform numbers a fuzzy value consumes per sample (0 if constant, 2 if normal).
inline int drawCount(const Fuzzy& f) {
  return f.spread == 0.0f ? 0 : f.distribution == Fuzzy::Distribution::Normal ? 2 : 1;
}

/// Samples n points of `d` into x, y, z from the uniform arrays u[0 .. drawCount(d)).
void sampleBatch(const Domain& d, const float* const* u, std::size_t n, float* x, float* y,
                 float* z);
/// Samples n fuzzy values into out from u[0 .. drawCount(f)).
void sampleBatch(const Fuzzy& f, const float* const* u, std::size_t n, float* out);

/// Fills words[0..3][i] with Philox block `block` of the stream (seed, firstId + i, c1, c2)
/// for i < n, and converts them to uniforms in [0, 1).
void uniformBatch(std::uint64_t seed, std::uint32_t firstId, std::uint32_t c1, std::uint32_t c2,
                  std::uint32_t block, std::size_t n, float* u0, float* u1, float* u2, float* u3);

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
