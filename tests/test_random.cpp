#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "flurry/random.hpp"
#include "forces_kernel.hpp"  // kernels/forces.h: fl_sincos_real
#include "sampling.hpp"
#include "shape_math.hpp"  // kernels/math.h and domain.h on the CPU

using flurry::Philox4x32;

// Known-answer vectors of Philox4x32-10 from Random123's kat_vectors.
TEST(Philox, KnownAnswers) {
  auto a = Philox4x32::generate(0, 0, 0, 0, 0, 0);
  EXPECT_EQ(a.v[0], 0x6627e8d5u);
  EXPECT_EQ(a.v[1], 0xe169c58du);
  EXPECT_EQ(a.v[2], 0xbc57ac4cu);
  EXPECT_EQ(a.v[3], 0x9b00dbd8u);
  auto b = Philox4x32::generate(0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu,
                                0xffffffffu);
  EXPECT_EQ(b.v[0], 0x408f276du);
  EXPECT_EQ(b.v[1], 0x41c83b0eu);
  EXPECT_EQ(b.v[2], 0xa20bc7c6u);
  EXPECT_EQ(b.v[3], 0x6d5451fdu);
  auto c = Philox4x32::generate(0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u, 0xa4093822u,
                                0x299f31d0u);
  EXPECT_EQ(c.v[0], 0xd16cfe09u);
  EXPECT_EQ(c.v[1], 0x94fdccebu);
  EXPECT_EQ(c.v[2], 0x5001e420u);
  EXPECT_EQ(c.v[3], 0x24126ea1u);
}

TEST(Random, StreamsAreReproducibleAndDistinct) {
  flurry::Random a(42, 7, 3, 1), b(42, 7, 3, 1), c(42, 8, 3, 1), d(43, 7, 3, 1);
  for (int i = 0; i < 10; ++i) {
    const auto x = a.bits();
    EXPECT_EQ(x, b.bits());
    EXPECT_NE(x, c.bits());
    EXPECT_NE(x, d.bits());
  }
}

TEST(Random, UniformAndNormalMoments) {
  flurry::Random r(1, 0, 0, 0);
  const int n = 200000;
  double s = 0, s2 = 0, m = 0, m2 = 0;
  float lo = 1, hi = 0;
  for (int i = 0; i < n; ++i) {
    const float u = r.uniform();
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    s += u;
    s2 += double(u) * u;
    const float g = r.normal();
    ASSERT_TRUE(std::isfinite(g));
    m += g;
    m2 += double(g) * g;
  }
  EXPECT_GE(lo, 0.0f);
  EXPECT_LT(hi, 1.0f);
  // Means within 5 standard errors.
  EXPECT_NEAR(s / n, 0.5, 5 * std::sqrt(1.0 / 12 / n));
  EXPECT_NEAR(s2 / n - (s / n) * (s / n), 1.0 / 12, 0.002);
  EXPECT_NEAR(m / n, 0.0, 5 / std::sqrt(double(n)));
  EXPECT_NEAR(m2 / n, 1.0, 0.02);
}

// Box-Muller's log and cos (kernels/domain.h) are float arithmetic alone, so that a normal
// draw has the same bits on every instruction set, libm and device: checked here against
// double precision on every value a uniform draw can give (multiples of 2^-24 in [0, 1)).
namespace {
// The error of `got` against `exact` in units of the float spacing at `exact`.
double ulps(float got, double exact) {
  const float e = float(exact);
  const double spacing = double(std::nextafter(std::fabs(e), INFINITY)) - double(std::fabs(e));
  return std::fabs(double(got) - exact) / spacing;
}
}  // namespace

TEST(Random, BoxMullersLogIsWithinAnUlpOnEveryUniform) {
  namespace k = flurry::detail::kernel;
  double worst = 0.0;
  for (std::uint32_t b = 0; b < (1u << 24); ++b) {
    const float x = 1.0f - flurry::uniformFloat(b << 8);  // what fl_normal_from takes the log of
    worst = std::max(worst, ulps(k::fl_logf(x), std::log(double(x))));
  }
  EXPECT_LT(worst, 1.0);
  // Any positive normal float, not only those (the function says so).
  flurry::Random r(5, 0, 0, 0);
  for (int i = 0; i < 1000000; ++i) {
    const float x = std::bit_cast<float>(0x00800000u + r.bits() % (0x7f800000u - 0x00800000u));
    ASSERT_LT(ulps(k::fl_logf(x), std::log(double(x))), 1.0) << x;
  }
  EXPECT_EQ(k::fl_logf(1.0f), 0.0f);  // a draw of 0 gives a radius of exactly 0
}

TEST(Random, BoxMullersCosIsWithin3e7OnEveryUniform) {
  namespace k = flurry::detail::kernel;
  double worst = 0.0;
  for (std::uint32_t b = 0; b < (1u << 24); ++b) {
    const float u = flurry::uniformFloat(b << 8);
    float s, c;
    k::fl_sincos_2pi(u, &s, &c);
    const double turn = 2.0 * 3.14159265358979323846 * double(u);
    ASSERT_LE(std::fabs(c), 1.0f) << u;
    worst = std::max(
        {worst, std::fabs(double(c) - std::cos(turn)), std::fabs(double(s) - std::sin(turn))});
  }
  EXPECT_LT(worst, 3e-7);  // as kernels/domain.h says
}

// The kernels' exp (kernels/math.h: decays of a newborn's own step, falloffs, a blast front)
// against double precision on every 61st float whose exp is a normal float, and at the ends.
TEST(Random, KernelsExpIsWithinAnUlp) {
  namespace k = flurry::detail::kernel;
  double worst = 0.0;
  for (std::uint32_t b = 0; b < 0xffffffc0u; b += 61) {
    const float x = std::bit_cast<float>(b);
    if (!(x >= -87.3f && x <= 88.7f)) continue;  // e^x a normal float
    const double u = ulps(k::fl_expf(x), std::exp(double(x)));
    if (u > worst) worst = u;
    ASSERT_LT(u, 1.0) << x;
  }
  EXPECT_GT(worst, 0.5);              // (the loop saw floats rounded: it ran)
  EXPECT_EQ(k::fl_expf(0.0f), 1.0f);  // a rate of 0 keeps a velocity exactly
  EXPECT_EQ(k::fl_expf(-0.0f), 1.0f);
  // Below the normal range: within a step of the subnormals' spacing, then 0.
  for (float x = -87.4f; x > -103.9f; x -= 0.37f)
    EXPECT_NEAR(double(k::fl_expf(x)), std::exp(double(x)), 1.5e-45) << x;
  EXPECT_EQ(k::fl_expf(-104.0f), 0.0f);
  EXPECT_EQ(k::fl_expf(-1e30f), 0.0f);
  EXPECT_EQ(k::fl_expf(-INFINITY), 0.0f);
  EXPECT_EQ(k::fl_expf(89.0f), INFINITY);
  EXPECT_EQ(k::fl_expf(INFINITY), INFINITY);
  EXPECT_TRUE(std::isnan(k::fl_expf(NAN)));
  EXPECT_LT(ulps(k::fl_expf(88.72f), std::exp(double(88.72f))), 1.0);  // (n = 128: two factors)
}

// fl_powf (kernels/math.h): a falloff's fade and a vortex's swirl, on both backends.
TEST(Random, KernelsPowIsWithinTwoUlps) {
  namespace k = flurry::detail::kernel;
  const float powers[] = {0.001f, 0.25f, 0.5f, 0.8f, 1.0f, 1.5f, 2.0f,
                          2.5f,   3.0f,  4.0f, 7.3f, 10.f, 31.7f};
  double worst = 0.0;
  std::size_t checked = 0;
  for (const float y : powers) {
    // Every 997th float in (0, 1] (a falloff's and a vortex's bases), every 9973rd above.
    for (std::uint32_t b = 1; b < 0x7f000000u; b += b < 0x3f800000u ? 997 : 9973) {
      const float x = std::bit_cast<float>(b);
      const double exact = std::pow(double(x), double(y));
      if (!(exact >= 1.17549435e-38 && exact < 3.4e38)) continue;  // a normal float
      const double u = ulps(k::fl_powf(x, y), exact);
      worst = std::max(worst, u);
      ++checked;
      ASSERT_LT(u, 2.0) << x << "^" << y;
    }
  }
  EXPECT_GT(checked, std::size_t(8'000'000));
  EXPECT_GT(worst, 0.5);  // (the loop saw results rounded: it ran)
  // A large exponent keeps y·log2 x's fraction (log2 x in two floats): a few ulp at 100.
  for (float x = 0.05f; x < 1.0f; x += 0.0137f)
    EXPECT_LT(ulps(k::fl_powf(x, 100.0f), std::pow(double(x), 100.0)), 3.0) << x;
  // Below the normal range: within a step of the subnormals' spacing, then 0.
  for (float x = 1e-3f; x > 1e-6f; x *= 0.83f)
    EXPECT_NEAR(double(k::fl_powf(x, 13.5f)), std::pow(double(x), 13.5), 1.5e-45) << x;
  EXPECT_EQ(k::fl_powf(0.5f, 1e20f), 0.0f);
  EXPECT_EQ(k::fl_powf(2.0f, 1e20f), INFINITY);
  // C's pow at the special values.
  EXPECT_EQ(k::fl_powf(0.0f, 0.0f), 1.0f);
  EXPECT_EQ(k::fl_powf(0.0f, 2.0f), 0.0f);
  EXPECT_EQ(k::fl_powf(1.0f, 7.0f), 1.0f);
  EXPECT_EQ(k::fl_powf(1.0f, 1e20f), 1.0f);
  EXPECT_EQ(k::fl_powf(INFINITY, 2.0f), INFINITY);
  EXPECT_EQ(k::fl_powf(NAN, 0.0f), 1.0f);
  EXPECT_TRUE(std::isnan(k::fl_powf(NAN, 2.0f)));
  EXPECT_EQ(k::fl_powf(1e-45f, 0.0f), 1.0f);
  EXPECT_EQ(k::fl_powf(0.25f, 0.5f), 0.5f);  // exact where the result is a float
  EXPECT_EQ(k::fl_powf(0.5f, 3.0f), 0.125f);
}

// fl_sincos_real (kernels/forces.h): a MagneticField's turn and Move's of the up vector, on
// both backends, in double (whose result rounds to float: two of double's ulps are 2^-29 of
// float's).
TEST(Random, KernelsSinCosAreWithinTwoUlpsOfDouble) {
  namespace k = flurry::detail::kernel;
  // In double's ulps at the result; near sin's and cos's zeros, where that spacing shrinks
  // without bound, in units of 1e-17 (the absolute error is what a turn feels there).
  auto ulpsD = [](double got, double want) {
    const double spacing = std::max(std::abs(std::nextafter(want, INFINITY) - want), 1e-17);
    return std::abs(got - want) / spacing;
  };
  double worst = 0.0;
  std::size_t checked = 0;
  auto check = [&](double x) {
    double s, c;
    k::fl_sincos_real(x, &s, &c);
    const double u = std::max(ulpsD(s, std::sin(x)), ulpsD(c, std::cos(x)));
    worst = std::max(worst, u);
    ++checked;
    ASSERT_LE(u, 2.0) << x;
  };
  // Angles a step turns by (to a few turns), densely; then out to 2^20 radians, and the
  // quadrants' edges where k changes.
  for (double x = -20.0; x <= 20.0; x += 0.000731) check(x);
  for (double x = 1e-12; x < 1048576.0; x *= 1.0007) check(x), check(-x);
  for (int q = -4000; q <= 4000; ++q)
    for (const double d : {-1e-9, 0.0, 1e-9}) check(q * 1.5707963267948966 / 2 + d);
  EXPECT_GT(checked, std::size_t(100'000));
  EXPECT_GT(worst, 0.25);  // (the loop saw rounded results: it ran)
  double s, c;
  k::fl_sincos_real(0.0, &s, &c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Past 2^40 radians no turn; infinity and NaN give NaN.
  k::fl_sincos_real(1e15, &s, &c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  for (const double bad : {double(INFINITY), -double(INFINITY), double(NAN)}) {
    k::fl_sincos_real(bad, &s, &c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << bad;
  }
}

TEST(Random, NormalIsTheKernelsBoxMuller) {
  flurry::Random a(9, 1, 2, 3), b(9, 1, 2, 3);
  for (int i = 0; i < 1000; ++i) {
    const float ua = b.uniform(), ub = b.uniform();
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.normal()),
              std::bit_cast<std::uint32_t>(flurry::detail::kernel::fl_normal_from(ua, ub)));
  }
}

// The emitters' batches (vectorised) give each blob point and each normal fuzzy value the
// bits of the scalar function, whatever the batch's length.
TEST(Random, NormalBatchesAreTheScalarBoxMullerBitForBit) {
  namespace k = flurry::detail::kernel;
  constexpr std::size_t n = 1003;
  std::vector<float> u[6];
  flurry::Random r(11, 0, 0, 0);
  for (auto& row : u)
    for (std::size_t i = 0; i < n; ++i) row.push_back(r.uniform());
  const float* rows[6] = {u[0].data(), u[1].data(), u[2].data(),
                          u[3].data(), u[4].data(), u[5].data()};
  const flurry::Vec3 c(1.0f, -2.0f, 3.0f);
  std::vector<float> x(n), y(n), z(n), g(n);
  flurry::detail::sampleBatch(flurry::Domain::blob(c, 0.5f), rows, n, x.data(), y.data(), z.data());
  const flurry::Fuzzy f(2.0f, 0.25f, flurry::Fuzzy::Distribution::Normal);
  flurry::detail::sampleBatch(f, rows, n, g.data());
  for (std::size_t i = 0; i < n; ++i) {
    const flurry::Vec3 p = k::fl_blob_at(c, 0.5f, u[0][i], u[1][i], u[2][i], u[3][i]);
    ASSERT_EQ(std::bit_cast<std::uint32_t>(x[i]), std::bit_cast<std::uint32_t>(p.x)) << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(y[i]), std::bit_cast<std::uint32_t>(p.y)) << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(z[i]), std::bit_cast<std::uint32_t>(p.z)) << i;
    const float e = 2.0f + 0.25f * k::fl_normal_from(u[0][i], u[1][i]);
    ASSERT_EQ(std::bit_cast<std::uint32_t>(g[i]), std::bit_cast<std::uint32_t>(e)) << i;
  }
}
