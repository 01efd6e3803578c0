// Domain: uniform sampling (chi-square on bins of equal measure, with a negative control that
// proves the check can fail), containment of samples, nearest points and normals at known
// points, measures, and the factories' validation.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "flurry/domain.hpp"
#include "flurry/error.hpp"
#include "flurry/random.hpp"
#include "shape_math.hpp"  // kernels/domain.h on the CPU

namespace {

using flurry::Domain;
using flurry::Random;
using flurry::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kSeed = 0x5EEDF1A7C0FFEEull;
constexpr int kSamples = 40000;

// ---- chi-square machinery --------------------------------------------------------------------

// The 0.999 quantile of chi-square with k degrees of freedom (Wilson–Hilferty: (X/k)^(1/3) is
// close to normal with mean 1 - 2/(9k) and variance 2/(9k)); z is the normal 0.999 quantile.
double chiSquare999(int k) {
  const double z = 3.090232306167813;
  const double h = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

// Index of x in [0, 1) cut into n equal bins; NaN and the ends clamp (rounding at borders).
int bin(double x, int n) {
  if (!(x >= 0.0)) return 0;
  return std::min(int(x * n), n - 1);
}

struct ChiSquare {
  double statistic, threshold;
  bool uniform() const { return statistic < threshold; }
};

// Draws n points, drops each into one of `bins` bins that the uniform distribution fills
// equally, and compares the counts with their expectation.
ChiSquare chiSquare(int bins, int n, const std::function<Vec3()>& draw,
                    const std::function<int(Vec3)>& binOf) {
  std::vector<int> counts(bins, 0);
  for (int i = 0; i < n; ++i) {
    const int b = binOf(draw());
    if (b < 0 || b >= bins)
      return {std::numeric_limits<double>::infinity(), chiSquare999(bins - 1)};
    ++counts[b];
  }
  const double expected = double(n) / bins;
  double x2 = 0.0;
  for (int c : counts) x2 += (c - expected) * (c - expected) / expected;
  return {x2, chiSquare999(bins - 1)};
}

void expectUniform(const Domain& d, std::uint32_t stream, int bins,
                   const std::function<int(Vec3)>& binOf) {
  Random rng(kSeed, stream, 0, 0);
  const ChiSquare c = chiSquare(
      bins, kSamples, [&] { return d.sample(rng); }, binOf);
  EXPECT_TRUE(c.uniform()) << d.name() << ": chi-square " << c.statistic << " >= " << c.threshold
                           << " (" << bins - 1 << " dof)";
}

// ---- geometry the tests compute on their own (not with the SDK's helpers) --------------------

struct Frame {
  Vec3 origin, w, e1, e2;  // w: unit axis
};

Frame frame(Vec3 origin, Vec3 axis) {
  Frame f{origin, glm::normalize(axis), {}, {}};
  const Vec3 helper = std::abs(f.w.x) < 0.6f ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  f.e1 = glm::normalize(glm::cross(f.w, helper));
  f.e2 = glm::cross(f.w, f.e1);
  return f;
}

// Axial coordinate, distance from the axis, and azimuth in [0, 1).
struct Cyl {
  double a, rho, phi01;
};

Cyl cyl(const Frame& f, Vec3 p) {
  const Vec3 d = p - f.origin;
  const double a = glm::dot(d, f.w), x = glm::dot(d, f.e1), y = glm::dot(d, f.e2);
  double phi = std::atan2(y, x) / (2.0 * kPi);
  if (phi < 0.0) phi += 1.0;
  return {a, std::sqrt(x * x + y * y), phi};
}

// Coordinates (s, t) of p in origin + s*u + t*v, by the normal equations (double).
void coords(Vec3 origin, Vec3 u, Vec3 v, Vec3 p, double& s, double& t) {
  const Vec3 r = p - origin;
  const double uu = glm::dot(u, u), uv = glm::dot(u, v), vv = glm::dot(v, v);
  const double ru = glm::dot(r, u), rv = glm::dot(r, v);
  const double det = uu * vv - uv * uv;
  s = (vv * ru - uv * rv) / det;
  t = (uu * rv - uv * ru) / det;
}

double normalCdf(double x) {
  return 0.5 * std::erfc(-x / std::sqrt(2.0));
}

#define EXPECT_VEC_NEAR(a, b, tol)                                                              \
  do {                                                                                          \
    const Vec3 va_ = (a), vb_ = (b);                                                            \
    EXPECT_LE(glm::length(va_ - vb_), (tol))                                                    \
        << "(" << va_.x << ", " << va_.y << ", " << va_.z << ") vs (" << vb_.x << ", " << vb_.y \
        << ", " << vb_.z << ")";                                                                \
  } while (0)

// ---- the checker itself ----------------------------------------------------------------------

TEST(ChiSquare, WilsonHilfertyMatchesTables) {
  // Tabulated 0.999 quantiles; the approximation is within 1% from 10 degrees of freedom up
  // (slightly high, i.e. conservative, at the low end).
  EXPECT_NEAR(chiSquare999(10) / 29.588, 1.0, 0.01);
  EXPECT_NEAR(chiSquare999(63) / 103.442, 1.0, 0.01);
  EXPECT_NEAR(chiSquare999(100) / 149.449, 1.0, 0.01);
}

// A disc sampled with r = u*R crowds the center: the same bins must reject it.
TEST(ChiSquare, RejectsNonUniformDisc) {
  Random rng(kSeed, 900, 0, 0);
  const float R = 2.0f;
  auto naive = [&] {
    const float r = rng.uniform() * R, phi = float(2.0 * kPi) * rng.uniform();
    return Vec3(r * std::cos(phi), r * std::sin(phi), 0.0f);
  };
  const Frame f = frame(Vec3(0.0f), Vec3(0, 0, 1));
  auto binOf = [&](Vec3 p) {
    const Cyl c = cyl(f, p);
    return bin(c.rho * c.rho / (R * R), 8) * 8 + bin(c.phi01, 8);
  };
  const ChiSquare c = chiSquare(64, kSamples, naive, binOf);
  EXPECT_FALSE(c.uniform()) << c.statistic << " < " << c.threshold;
  // The real disc passes the very same check.
  expectUniform(Domain::disc(Vec3(0.0f), Vec3(0, 0, 1), R), 901, 64, binOf);
}

// Directions with uniform theta (instead of uniform cos theta) crowd the poles.
TEST(ChiSquare, RejectsNonUniformSphereDirections) {
  Random rng(kSeed, 902, 0, 0);
  auto naive = [&] {
    const float th = float(kPi) * rng.uniform(), phi = float(2.0 * kPi) * rng.uniform();
    return Vec3(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
  };
  auto binOf = [](Vec3 p) { return bin((p.z / glm::length(p) + 1.0) / 2.0, 16); };
  EXPECT_FALSE(chiSquare(16, kSamples, naive, binOf).uniform());
  expectUniform(Domain::sphere(Vec3(0.0f), 1.0f, 1.0f), 903, 16, binOf);
}

// ---- uniform sampling, every domain ----------------------------------------------------------

TEST(DomainSampling, PointAndPlaneReturnTheirPoint) {
  Random rng(kSeed, 1, 0, 0);
  const Domain point = Domain::point(Vec3(1, 2, 3));
  const Domain plane = Domain::plane(Vec3(4, 5, 6), Vec3(0, 0, 1));
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(point.sample(rng), Vec3(1, 2, 3));
    EXPECT_EQ(plane.sample(rng), Vec3(4, 5, 6));
  }
}

TEST(DomainSampling, LineUniformByLength) {
  const Vec3 p0(1, -2, 0.5f), p1(-3, 4, 2);
  const Domain d = Domain::line(p0, p1);
  expectUniform(d, 2, 40, [&](Vec3 p) {
    return bin(glm::dot(p - p0, p1 - p0) / glm::dot(p1 - p0, p1 - p0), 40);
  });
}

TEST(DomainSampling, TriangleUniformByArea) {
  // The barycentric grid cuts the triangle into n² congruent sub-triangles: cell (i, j) =
  // floor(n * barycentric), upright or inverted by whether the fractional parts sum past 1.
  constexpr int n = 6;
  std::vector<int> cell(2 * n * n, -1);  // (inverted, i, j) -> bin; -1: no such cell
  int cells = 0;
  for (int inv = 0; inv < 2; ++inv)
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j + inv <= n - 1; ++j) cell[(inv * n + i) * n + j] = cells++;
  ASSERT_EQ(cells, n * n);

  const Vec3 p0(0.5f, 1, -1), p1(3, 0, 0), p2(1, 2.5f, 2);
  const Domain d = Domain::triangle(p0, p1, p2);
  expectUniform(d, 3, n * n, [&](Vec3 p) {
    double s, t;
    coords(p0, p1 - p0, p2 - p0, p, s, t);
    const int i = std::clamp(int(std::floor(s * n)), 0, n - 1);
    const int j = std::clamp(int(std::floor(t * n)), 0, n - 1 - i);
    int inv = (s * n - i) + (t * n - j) > 1.0;
    if (i + j + inv > n - 1) inv = 0;  // a rounding step past the hypotenuse
    return cell[(inv * n + i) * n + j];
  });
}

TEST(DomainSampling, RectangleUniformWithSkewedEdges) {
  const Vec3 o(1, 1, 1), u(2, 0, 0.5f), v(1, 1.5f, 0);
  const Domain d = Domain::rectangle(o, u, v);
  expectUniform(d, 4, 64, [&](Vec3 p) {
    double s, t;
    coords(o, u, v, p, s, t);
    return bin(s, 8) * 8 + bin(t, 8);
  });
}

TEST(DomainSampling, DiscAndAnnulusUniformByArea) {
  const Vec3 c(1, 2, 3), n(1, -1, 2);
  const Frame f = frame(c, n);
  for (float ri : {0.0f, 0.7f}) {
    const float ro = 1.5f;
    const Domain d = Domain::disc(c, n, ro, ri);
    expectUniform(d, 5, 64, [&](Vec3 p) {
      const Cyl q = cyl(f, p);
      return bin((q.rho * q.rho - ri * ri) / (ro * ro - ri * ri), 8) * 8 + bin(q.phi01, 8);
    });
  }
}

TEST(DomainSampling, BoxUniformByVolume) {
  const Vec3 lo(-1, 0, 2), hi(2, 0.5f, 4);
  const Domain d = Domain::box(hi, lo);  // corners in either order
  expectUniform(d, 6, 64, [&](Vec3 p) {
    const Vec3 t = (p - lo) / (hi - lo);
    return (bin(t.x, 4) * 4 + bin(t.y, 4)) * 4 + bin(t.z, 4);
  });
}

TEST(DomainSampling, SphereUniformByVolumeAndOnSurface) {
  const Vec3 c(1, -2, 3);
  const Frame f = frame(c, Vec3(0, 0, 1));
  for (float ri : {0.0f, 1.2f, 2.0f}) {
    const float ro = 2.0f;
    const Domain d = Domain::sphere(c, ro, ri);
    const bool shell = ri == ro;
    const int rbins = shell ? 1 : 4;
    expectUniform(d, 7, rbins * 64, [&](Vec3 p) {
      const Cyl q = cyl(f, p);
      const double r = glm::length(p - c);
      const int rb = shell ? 0 : bin((r * r * r - ri * ri * ri) / (ro * ro * ro - ri * ri * ri), 4);
      return (rb * 8 + bin((q.a / r + 1.0) / 2.0, 8)) * 8 + bin(q.phi01, 8);
    });
  }
}

TEST(DomainSampling, CylinderUniformByVolumeAndOnSurface) {
  const Vec3 p0(0, 1, 0), p1(2, 3, -1);
  const Frame f = frame(p0, p1 - p0);
  const double L = glm::length(p1 - p0);
  for (float ri : {0.0f, 0.5f, 1.0f}) {
    const float ro = 1.0f;
    const Domain d = Domain::cylinder(p0, p1, ro, ri);
    const bool shell = ri == ro;
    const int rbins = shell ? 1 : 4;
    expectUniform(d, 8, rbins * 64, [&](Vec3 p) {
      const Cyl q = cyl(f, p);
      const int rb = shell ? 0 : bin((q.rho * q.rho - ri * ri) / (ro * ro - ri * ri), 4);
      return (rb * 8 + bin(q.a / L, 8)) * 8 + bin(q.phi01, 8);
    });
  }
}

TEST(DomainSampling, ConeUniformByVolumeAndOnLateralSurface) {
  const Vec3 apex(1, 0, 0), base(1, -1, 2);
  const Frame f = frame(apex, base - apex);
  const double L = glm::length(base - apex);
  for (float ri : {0.0f, 0.6f, 1.5f}) {
    const float ro = 1.5f;
    const Domain d = Domain::cone(apex, base, ro, ri);
    const bool shell = ri == ro;
    const int rbins = shell ? 1 : 4;
    expectUniform(d, 9, rbins * 64, [&](Vec3 p) {
      const Cyl q = cyl(f, p);
      const double t = q.a / L;
      // Volume up to t grows with t³ (lateral area with t²); at height t the cross-section
      // is the annulus ri*t..ro*t, equal-area bins in (rho/t)².
      const double along = shell ? t * t : t * t * t;
      const double rt = t > 0.0 ? q.rho / t : 0.0;
      const int rb = shell ? 0 : bin((rt * rt - ri * ri) / (ro * ro - ri * ri), 4);
      return (rb * 8 + bin(along, 8)) * 8 + bin(q.phi01, 8);
    });
  }
}

TEST(DomainSampling, BlobIsGaussianPerAxis) {
  const Vec3 c(1, 2, -3);
  const float sd = 0.5f;
  const Domain d = Domain::blob(c, sd);
  expectUniform(d, 10, 125, [&](Vec3 p) {
    const Vec3 z = (p - c) / sd;
    return (bin(normalCdf(z.x), 5) * 5 + bin(normalCdf(z.y), 5)) * 5 + bin(normalCdf(z.z), 5);
  });
  // contains() is the ball of radius stddev: P(chi-square(3) <= 1) = 0.198748.
  Random rng(kSeed, 11, 0, 0);
  int in = 0;
  for (int i = 0; i < kSamples; ++i) in += d.contains(d.sample(rng));
  const double p = 0.198748, sigma = std::sqrt(p * (1 - p) / kSamples);
  EXPECT_NEAR(double(in) / kSamples, p, 5 * sigma);
}

// ---- samples lie in the domain -------------------------------------------------------------

struct Case {
  Domain d;
  float scale;
};

std::vector<Case> solids() {
  return {{Domain::box(Vec3(-1, 0, 2), Vec3(2, 0.5f, 4)), 3.0f},
          {Domain::sphere(Vec3(1, -2, 3), 2.0f), 2.0f},
          {Domain::sphere(Vec3(1, -2, 3), 2.0f, 1.5f), 2.0f},
          {Domain::cylinder(Vec3(0, 1, 0), Vec3(2, 3, -1), 1.0f), 3.0f},
          {Domain::cylinder(Vec3(0, 1, 0), Vec3(2, 3, -1), 1.0f, 0.8f), 3.0f},
          {Domain::cone(Vec3(1, 0, 0), Vec3(1, -1, 2), 1.5f), 3.0f},
          {Domain::cone(Vec3(1, 0, 0), Vec3(1, -1, 2), 1.5f, 1.0f), 3.0f}};
}

std::vector<Case> surfaces() {
  return {{Domain::line(Vec3(1, -2, 0.5f), Vec3(-3, 4, 2)), 7.0f},
          {Domain::triangle(Vec3(0.5f, 1, -1), Vec3(3, 0, 0), Vec3(1, 2.5f, 2)), 3.0f},
          {Domain::rectangle(Vec3(1, 1, 1), Vec3(2, 0, 0.5f), Vec3(1, 1.5f, 0)), 3.0f},
          {Domain::disc(Vec3(1, 2, 3), Vec3(1, -1, 2), 1.5f, 0.7f), 1.5f},
          {Domain::disc(Vec3(1, 2, 3), Vec3(1, -1, 2), 1.5f, 1.5f), 1.5f},
          {Domain::plane(Vec3(1, 2, 3), Vec3(1, 1, 1)), 1.0f},
          {Domain::point(Vec3(1, 2, 3)), 1.0f},
          {Domain::sphere(Vec3(1, -2, 3), 2.0f, 2.0f), 2.0f},
          {Domain::cylinder(Vec3(0, 1, 0), Vec3(2, 3, -1), 1.0f, 1.0f), 3.0f},
          {Domain::cone(Vec3(1, 0, 0), Vec3(1, -1, 2), 1.5f, 1.5f), 3.0f}};
}

TEST(DomainSampling, SolidSamplesAreContained) {
  std::uint32_t id = 20;
  for (const Case& c : solids()) {
    Random rng(kSeed, id++, 0, 0);
    int outside = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3 p = c.d.sample(rng);
      // A rounding step past the border is allowed, nothing more.
      outside += !(c.d.contains(p) || c.d.distance(p) <= 1e-5f * c.scale);
    }
    EXPECT_EQ(outside, 0) << c.d.name();
  }
}

TEST(DomainSampling, SurfaceSamplesLieOnTheSurface) {
  std::uint32_t id = 40;
  for (const Case& c : surfaces()) {
    Random rng(kSeed, id++, 0, 0);
    float worst = 0.0f;
    for (int i = 0; i < 20000; ++i) worst = std::max(worst, c.d.distance(c.d.sample(rng)));
    EXPECT_LT(worst, 1e-4f * c.scale) << c.d.name();
  }
}

// For shapes that sample their own surface, closestPoint must beat (or tie) every sample and
// come within sampling resolution of the best one: a brute-force check of the nearest point.
TEST(DomainClosestPoint, NoSampleIsNearerThanClosestPoint) {
  std::uint32_t id = 60;
  for (const Case& c : surfaces()) {
    if (std::string(c.d.name()) == "plane" || std::string(c.d.name()) == "point") continue;
    Random rng(kSeed, id++, 0, 0);
    std::vector<Vec3> pts(4000);
    for (Vec3& p : pts) p = c.d.sample(rng);
    for (int q = 0; q < 40; ++q) {
      const Vec3 p = pts[q * 7] + Vec3(rng.normal(), rng.normal(), rng.normal()) * c.scale;
      float best = std::numeric_limits<float>::infinity();
      for (const Vec3& s : pts) best = std::min(best, glm::length(p - s));
      const float d = c.d.distance(p);
      EXPECT_LE(d, best + 1e-4f * c.scale) << c.d.name();
      EXPECT_GE(d, best - 0.1f * c.scale) << c.d.name();
      // closestPoint lies on the shape.
      EXPECT_LT(c.d.distance(c.d.closestPoint(p)), 1e-4f * c.scale) << c.d.name();
    }
  }
}

// Solids: the nearest boundary point lies on the boundary, and the normal is a unit vector.
TEST(DomainClosestPoint, SolidsClosestPointIsOnTheBoundary) {
  Random rng(kSeed, 80, 0, 0);
  for (const Case& c : solids()) {
    for (int i = 0; i < 200; ++i) {
      const Vec3 p = Vec3(rng.normal(), rng.normal(), rng.normal()) * (2.0f * c.scale);
      const Vec3 q = c.d.closestPoint(p);
      EXPECT_LT(c.d.distance(q), 1e-4f * c.scale) << c.d.name();
      // Just outside along the normal is outside, just inside is inside.
      const Vec3 n = c.d.normal(p);
      EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f) << c.d.name();
      const float eps = 1e-3f * c.scale;
      EXPECT_FALSE(c.d.contains(q + n * eps)) << c.d.name();
    }
  }
}

// ---- known points ------------------------------------------------------------------------------

TEST(DomainKnownPoints, Sphere) {
  const Domain d = Domain::sphere(Vec3(0.0f), 2.0f);
  EXPECT_FLOAT_EQ(d.distance(Vec3(5, 0, 0)), 3.0f);
  EXPECT_VEC_NEAR(d.normal(Vec3(5, 0, 0)), Vec3(1, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0.5f, 0, 0)), Vec3(2, 0, 0), 1e-6f);  // inside
  EXPECT_VEC_NEAR(d.normal(Vec3(0, -0.5f, 0)), Vec3(0, -1, 0), 1e-6f);
  EXPECT_TRUE(d.contains(Vec3(0, 1.9f, 0)));
  EXPECT_FALSE(d.contains(Vec3(0, 2.1f, 0)));

  const Domain shell = Domain::sphere(Vec3(0.0f), 2.0f, 1.0f);
  EXPECT_VEC_NEAR(shell.closestPoint(Vec3(1.2f, 0, 0)), Vec3(1, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(shell.normal(Vec3(1.2f, 0, 0)), Vec3(-1, 0, 0), 1e-6f);  // out of the material
  EXPECT_FLOAT_EQ(shell.distance(Vec3(0.0f)), 1.0f);
  EXPECT_FALSE(shell.contains(Vec3(0.5f, 0, 0)));
  EXPECT_TRUE(shell.contains(Vec3(0, 0, 1.5f)));

  const Domain surface = Domain::sphere(Vec3(0.0f), 2.0f, 2.0f);
  EXPECT_FALSE(surface.contains(Vec3(0, 0, 2)));
  EXPECT_FLOAT_EQ(surface.distance(Vec3(0, 0.5f, 0)), 1.5f);
  EXPECT_VEC_NEAR(surface.normal(Vec3(0, 0.5f, 0)), Vec3(0, 1, 0), 1e-6f);
}

TEST(DomainKnownPoints, Box) {
  const Domain d = Domain::box(Vec3(2, 4, 6), Vec3(0, 0, 0));
  // Inside: the nearest face is x = 2.
  EXPECT_FLOAT_EQ(d.distance(Vec3(1.5f, 2, 3)), 0.5f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(1.5f, 2, 3)), Vec3(2, 2, 3), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(1.5f, 2, 3)), Vec3(1, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(1, 2, 0.2f)), Vec3(0, 0, -1), 1e-6f);
  // Outside a face and outside a corner.
  EXPECT_FLOAT_EQ(d.distance(Vec3(1, 2, -1)), 1.0f);
  EXPECT_VEC_NEAR(d.normal(Vec3(1, 2, -1)), Vec3(0, 0, -1), 1e-6f);
  EXPECT_NEAR(d.distance(Vec3(3, 5, 7)), std::sqrt(3.0f), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(3, 5, 7)), glm::normalize(Vec3(1, 1, 1)), 1e-6f);
  EXPECT_TRUE(d.contains(Vec3(0, 0, 0)));
  EXPECT_FALSE(d.contains(Vec3(0, -0.01f, 0)));
}

TEST(DomainKnownPoints, Triangle) {
  const Domain d = Domain::triangle(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0));
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(1, -1, 1)), Vec3(1, 0, 0), 1e-6f);  // above an edge
  EXPECT_NEAR(d.distance(Vec3(1, -1, 1)), std::sqrt(2.0f), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0.5f, 0.5f, 3)), Vec3(0.5f, 0.5f, 0), 1e-6f);  // face
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(3, -1, 0)), Vec3(2, 0, 0), 1e-6f);             // vertex
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(2, 2, -1)), Vec3(1, 1, 0), 1e-6f);             // hypotenuse
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(-1, -1, 0)), Vec3(0, 0, 0), 1e-6f);
  // A plane piece's normal is its own, on either side.
  EXPECT_VEC_NEAR(d.normal(Vec3(0.5f, 0.5f, -3)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_FALSE(d.contains(Vec3(0.5f, 0.5f, 0)));
  EXPECT_DOUBLE_EQ(d.measure(), 2.0);
}

TEST(DomainKnownPoints, RectangleWithSkewedEdges) {
  const Domain d = Domain::rectangle(Vec3(0.0f), Vec3(2, 0, 0), Vec3(1, 1, 0));
  // Above the interior, on the s = 1 edge.
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(2.5f, 0.5f, 1)), Vec3(2.5f, 0.5f, 0), 1e-6f);
  EXPECT_FLOAT_EQ(d.distance(Vec3(2.5f, 0.5f, 1)), 1.0f);
  // Beyond the slanted edge (2,0)-(3,1): the nearest point is (2.75, 0.75), not the
  // (2.5, 0.5) that clamping s and t separately would give.
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(3, 0.5f, 0)), Vec3(2.75f, 0.75f, 0), 1e-6f);
  EXPECT_NEAR(d.distance(Vec3(3, 0.5f, 0)), std::sqrt(0.125f), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(3, 0.5f, -2)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_DOUBLE_EQ(d.measure(), 2.0);
}

TEST(DomainKnownPoints, DiscAndPlane) {
  const Domain ring = Domain::disc(Vec3(0.0f), Vec3(0, 0, 5), 2.0f, 1.0f);
  EXPECT_NEAR(ring.distance(Vec3(0, 0, 3)), std::sqrt(10.0f), 1e-6f);  // on the axis
  EXPECT_VEC_NEAR(ring.closestPoint(Vec3(3, 0, 1)), Vec3(2, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(ring.closestPoint(Vec3(1.5f, 0, -2)), Vec3(1.5f, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(ring.closestPoint(Vec3(0, 0.5f, 0)), Vec3(0, 1, 0), 1e-6f);
  EXPECT_VEC_NEAR(ring.normal(Vec3(1.5f, 0, -2)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_NEAR(ring.measure(), 3.0 * kPi, 1e-6);

  const Domain plane = Domain::plane(Vec3(0, 0, 1), Vec3(0, 0, 2));
  EXPECT_FLOAT_EQ(plane.distance(Vec3(3, 4, 5)), 4.0f);
  EXPECT_VEC_NEAR(plane.closestPoint(Vec3(3, 4, 5)), Vec3(3, 4, 1), 1e-6f);
  EXPECT_VEC_NEAR(plane.normal(Vec3(3, 4, -5)), Vec3(0, 0, 1), 1e-6f);  // normalised
  EXPECT_TRUE(plane.contains(Vec3(3, 4, 5)));  // the side the normal points into
  EXPECT_FALSE(plane.contains(Vec3(0, 0, 0)));
  EXPECT_EQ(plane.measure(), 0.0);
}

TEST(DomainKnownPoints, CylinderCapVersusSide) {
  const Domain d = Domain::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1.0f);
  // Outside beyond a cap, beside the side, past the rim.
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0, 5)), Vec3(0, 0, 4), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(0, 0, 5)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(3, 0, 2)), Vec3(1, 0, 2), 1e-6f);
  EXPECT_FLOAT_EQ(d.distance(Vec3(3, 0, 2)), 2.0f);
  EXPECT_VEC_NEAR(d.normal(Vec3(3, 0, 2)), Vec3(1, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(2, 0, 5)), Vec3(1, 0, 4), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(2, 0, 5)), glm::normalize(Vec3(1, 0, 1)), 1e-6f);
  // Inside: the side is nearer, then the cap is.
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0.8f, 2)), Vec3(0, 1, 2), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(0, 0.8f, 2)), Vec3(0, 1, 0), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0, 3.9f)), Vec3(0, 0, 4), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(0, 0, 0.1f)), Vec3(0, 0, -1), 1e-6f);
  EXPECT_NEAR(d.measure(), 4.0 * kPi, 1e-5);

  const Domain hollow = Domain::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1.0f, 0.5f);
  EXPECT_FLOAT_EQ(hollow.distance(Vec3(0, 0, 2)), 0.5f);  // on the axis, in the hole
  EXPECT_VEC_NEAR(hollow.normal(Vec3(0.2f, 0, 2)), Vec3(-1, 0, 0), 1e-6f);
  EXPECT_FALSE(hollow.contains(Vec3(0.2f, 0, 2)));
  EXPECT_TRUE(hollow.contains(Vec3(0.7f, 0, 2)));

  // The curved surface alone has no caps: beyond the end, the rim is nearest.
  const Domain tube = Domain::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1.0f, 1.0f);
  EXPECT_NEAR(tube.distance(Vec3(0, 0, 5)), std::sqrt(2.0f), 1e-6f);
  EXPECT_FLOAT_EQ(tube.distance(Vec3(0, 0.25f, 2)), 0.75f);
  EXPECT_VEC_NEAR(tube.normal(Vec3(0, 0.25f, 2)), Vec3(0, 1, 0), 1e-6f);
  EXPECT_FALSE(tube.contains(Vec3(0, 0.5f, 2)));
  EXPECT_NEAR(tube.measure(), 8.0 * kPi, 1e-5);
}

TEST(DomainKnownPoints, Cone) {
  // Apex at the origin, base of radius 2 at z = 2: a 45-degree cone.
  const Domain d = Domain::cone(Vec3(0, 0, 0), Vec3(0, 0, 2), 2.0f);
  const Vec3 lateral = glm::normalize(Vec3(1, 0, -1));
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(2, 0, 0)), Vec3(1, 0, 1), 1e-6f);
  EXPECT_NEAR(d.distance(Vec3(2, 0, 0)), std::sqrt(2.0f), 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(2, 0, 0)), lateral, 1e-6f);
  EXPECT_VEC_NEAR(d.normal(Vec3(1.2f, 0, 1.4f)), lateral, 1e-6f);        // inside, lateral nearest
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0, 3)), Vec3(0, 0, 2), 1e-6f);  // below the base
  EXPECT_VEC_NEAR(d.normal(Vec3(0, 0, 3)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0, 1.9f)), Vec3(0, 0, 2), 1e-6f);  // inside
  EXPECT_VEC_NEAR(d.normal(Vec3(0, 0, 1.9f)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_VEC_NEAR(d.closestPoint(Vec3(0, 0, -1)), Vec3(0, 0, 0), 1e-6f);  // behind the apex
  EXPECT_TRUE(d.contains(Vec3(0.9f, 0, 1)));
  EXPECT_FALSE(d.contains(Vec3(1.1f, 0, 1)));
  EXPECT_NEAR(d.measure(), 8.0 * kPi / 3.0, 1e-5);

  const Domain hollow = Domain::cone(Vec3(0, 0, 0), Vec3(0, 0, 2), 2.0f, 1.0f);
  // On the axis the inner cone (rho = z/2) is z/sqrt(5) away; the base is an annulus.
  EXPECT_NEAR(hollow.distance(Vec3(0, 0, 1.6f)), 1.6f / std::sqrt(5.0f), 1e-6f);
  EXPECT_NEAR(hollow.distance(Vec3(0, 0, 0.5f)), 0.5f / std::sqrt(5.0f), 1e-6f);
  EXPECT_NEAR(hollow.distance(Vec3(1.5f, 0, 1.9f)), 0.1f, 1e-6f);
  EXPECT_VEC_NEAR(hollow.normal(Vec3(1.5f, 0, 1.9f)), Vec3(0, 0, 1), 1e-6f);
  EXPECT_VEC_NEAR(hollow.normal(Vec3(0.3f, 0, 1)), glm::normalize(Vec3(-2, 0, 1)), 1e-6f);
  EXPECT_FALSE(hollow.contains(Vec3(0.3f, 0, 1)));
  EXPECT_TRUE(hollow.contains(Vec3(0.7f, 0, 1)));

  const Domain surface = Domain::cone(Vec3(0, 0, 0), Vec3(0, 0, 2), 2.0f, 2.0f);
  EXPECT_NEAR(surface.distance(Vec3(0, 0, 1.9f)), 1.9f / std::sqrt(2.0f), 1e-6f);  // no base
  EXPECT_NEAR(surface.measure(), kPi * 2.0 * std::sqrt(8.0), 1e-5);
}

TEST(DomainKnownPoints, PointLineAndBlob) {
  const Domain pt = Domain::point(Vec3(1, 1, 1));
  EXPECT_FLOAT_EQ(pt.distance(Vec3(1, 4, 5)), 5.0f);
  EXPECT_VEC_NEAR(pt.normal(Vec3(1, 4, 5)), Vec3(0, 0.6f, 0.8f), 1e-6f);
  EXPECT_NEAR(glm::length(pt.normal(Vec3(1, 1, 1))), 1.0f, 1e-6f);
  EXPECT_FALSE(pt.contains(Vec3(1, 1, 1)));

  const Domain seg = Domain::line(Vec3(0, 0, 0), Vec3(2, 0, 0));
  EXPECT_FLOAT_EQ(seg.distance(Vec3(1, 1, 0)), 1.0f);
  EXPECT_VEC_NEAR(seg.normal(Vec3(1, 1, 0)), Vec3(0, 1, 0), 1e-6f);
  EXPECT_VEC_NEAR(seg.closestPoint(Vec3(3, 0, 0)), Vec3(2, 0, 0), 1e-6f);
  EXPECT_VEC_NEAR(seg.normal(Vec3(3, 0, 0)), Vec3(1, 0, 0), 1e-6f);
  const Vec3 onIt = seg.normal(Vec3(1, 0, 0));  // on the segment: any perpendicular unit
  EXPECT_NEAR(glm::length(onIt), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(onIt, Vec3(1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_DOUBLE_EQ(seg.measure(), 2.0);

  const Domain blob = Domain::blob(Vec3(0.0f), 0.5f);
  EXPECT_TRUE(blob.contains(Vec3(0.4f, 0, 0)));
  EXPECT_FALSE(blob.contains(Vec3(0.6f, 0, 0)));
}

// ---- measures against Monte Carlo over a bounding box --------------------------------------

TEST(DomainMeasure, SolidsAgreeWithContainsByMonteCarlo) {
  Random rng(kSeed, 90, 0, 0);
  for (const Case& c : solids()) {
    const Domain bounds = Domain::box(Vec3(-4.0f), Vec3(5.0f));  // holds every solid case
    const int n = 40000;
    int in = 0;
    for (int i = 0; i < n; ++i) in += c.d.contains(bounds.sample(rng));
    const double p = c.d.measure() / bounds.measure();
    EXPECT_NEAR(double(in) / n, p, 5.0 * std::sqrt(p * (1 - p) / n)) << c.d.name();
  }
}

TEST(DomainMeasure, ExactValues) {
  EXPECT_NEAR(Domain::sphere(Vec3(0.0f), 2.0f).measure(), 32.0 * kPi / 3.0, 1e-5);
  EXPECT_NEAR(Domain::sphere(Vec3(0.0f), 2.0f, 1.0f).measure(), 28.0 * kPi / 3.0, 1e-5);
  EXPECT_NEAR(Domain::sphere(Vec3(0.0f), 2.0f, 2.0f).measure(), 16.0 * kPi, 1e-5);
  EXPECT_DOUBLE_EQ(Domain::box(Vec3(0.0f), Vec3(1, 2, 3)).measure(), 6.0);
  EXPECT_NEAR(Domain::disc(Vec3(0.0f), Vec3(0, 1, 0), 2.0f).measure(), 4.0 * kPi, 1e-5);
  EXPECT_EQ(Domain::point(Vec3(0.0f)).measure(), 0.0);
}

TEST(Domain, NamesAndPlanarity) {
  const Vec3 o(0.0f), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const std::vector<std::pair<Domain, std::string>> all = {
      {Domain::point(o), "point"},
      {Domain::line(o, x), "line"},
      {Domain::triangle(o, x, y), "triangle"},
      {Domain::plane(o, z), "plane"},
      {Domain::rectangle(o, x, y), "rectangle"},
      {Domain::disc(o, z, 1.0f), "disc"},
      {Domain::box(o, Vec3(1.0f)), "box"},
      {Domain::sphere(o, 1.0f), "sphere"},
      {Domain::cylinder(o, z, 1.0f), "cylinder"},
      {Domain::cone(o, z, 1.0f), "cone"},
      {Domain::blob(o, 1.0f), "blob"}};
  for (const auto& [d, name] : all) {
    EXPECT_EQ(d.name(), name);
    const bool planar =
        name == "plane" || name == "rectangle" || name == "disc" || name == "triangle";
    EXPECT_EQ(d.isPlanar(), planar) << name;
  }
  EXPECT_STREQ(Domain().name(), "point");
}

// ---- validation ------------------------------------------------------------------------------

// Runs make(), expecting InvalidArgument naming `parameter`.
void expectInvalid(const std::function<void()>& make, const std::string& parameter) {
  try {
    make();
    ADD_FAILURE() << "no exception; expected one naming " << parameter;
  } catch (const flurry::InvalidArgument& e) {
    EXPECT_EQ(e.parameter(), parameter) << e.what();
  }
}

TEST(DomainValidation, DegenerateShapesThrowNamingTheParameter) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const Vec3 o(0.0f), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);

  expectInvalid([&] { Domain::sphere(o, 0.0f); }, "sphere.outerRadius");
  expectInvalid([&] { Domain::sphere(o, -1.0f); }, "sphere.outerRadius");
  expectInvalid([&] { Domain::sphere(o, inf); }, "sphere.outerRadius");
  expectInvalid([&] { Domain::sphere(o, 1.0f, 2.0f); }, "sphere.innerRadius");
  expectInvalid([&] { Domain::sphere(Vec3(0, nan, 0), 1.0f); }, "sphere.center");

  expectInvalid([&] { Domain::triangle(o, Vec3(1, 1, 1), Vec3(2, 2, 2)); }, "triangle");
  expectInvalid([&] { Domain::triangle(o, Vec3(1, 2, 3), Vec3(0.3f, 0.6f, 0.9f)); }, "triangle");
  expectInvalid([&] { Domain::triangle(o, o, x); }, "triangle");
  expectInvalid([&] { Domain::triangle(o, x, Vec3(nan)); }, "triangle.p2");

  expectInvalid([&] { Domain::plane(o, Vec3(0.0f)); }, "plane.normal");
  expectInvalid([&] { Domain::plane(o, Vec3(inf, 0, 0)); }, "plane.normal");
  expectInvalid([&] { Domain::plane(Vec3(nan, 0, 0), z); }, "plane.point");

  expectInvalid([&] { Domain::line(Vec3(nan, 0, 0), x); }, "line.p0");
  expectInvalid([&] { Domain::line(x, x); }, "line");
  expectInvalid([&] { Domain::point(Vec3(0, 0, nan)); }, "point.p");

  expectInvalid([&] { Domain::rectangle(o, x, Vec3(2, 0, 0)); }, "rectangle");
  expectInvalid([&] { Domain::rectangle(o, Vec3(0.0f), y); }, "rectangle");

  expectInvalid([&] { Domain::disc(o, z, 1.0f, 1.5f); }, "disc.innerRadius");
  expectInvalid([&] { Domain::disc(o, z, 1.0f, -0.5f); }, "disc.innerRadius");
  expectInvalid([&] { Domain::disc(o, z, 1.0f, nan); }, "disc.innerRadius");
  expectInvalid([&] { Domain::disc(o, Vec3(0.0f), 1.0f); }, "disc.normal");

  expectInvalid([&] { Domain::box(o, Vec3(1, 0, 1)); }, "box");
  expectInvalid([&] { Domain::box(o, Vec3(1, 1, nan)); }, "box.corner1");

  expectInvalid([&] { Domain::cylinder(x, x, 1.0f); }, "cylinder.axis");
  expectInvalid([&] { Domain::cylinder(o, z, 1.0f, 2.0f); }, "cylinder.innerRadius");
  expectInvalid([&] { Domain::cylinder(o, z, 0.0f); }, "cylinder.outerRadius");
  expectInvalid([&] { Domain::cone(z, z, 1.0f); }, "cone.axis");
  expectInvalid([&] { Domain::cone(o, z, 1.0f, -1.0f); }, "cone.innerRadius");

  expectInvalid([&] { Domain::blob(o, 0.0f); }, "blob.stddev");
  expectInvalid([&] { Domain::blob(o, nan); }, "blob.stddev");
}

TEST(DomainValidation, FactoriesNormaliseAndOrder) {
  const Domain plane = Domain::plane(Vec3(0.0f), Vec3(0, 3, 4));
  EXPECT_VEC_NEAR(std::get<flurry::PlaneDomain>(plane.shape()).normal, Vec3(0, 0.6f, 0.8f), 1e-6f);
  const Domain disc = Domain::disc(Vec3(0.0f), Vec3(0, 0, 1e-30f), 1.0f);  // tiny but valid
  EXPECT_VEC_NEAR(std::get<flurry::DiscDomain>(disc.shape()).normal, Vec3(0, 0, 1), 1e-6f);
  const Domain tri = Domain::triangle(Vec3(0.0f), Vec3(0, 1, 0), Vec3(1, 0, 0));
  EXPECT_VEC_NEAR(std::get<flurry::TriangleDomain>(tri.shape()).normal, Vec3(0, 0, -1), 1e-6f);
  const Domain rect = Domain::rectangle(Vec3(0.0f), Vec3(2, 0, 0), Vec3(0, 3, 0));
  EXPECT_VEC_NEAR(std::get<flurry::RectangleDomain>(rect.shape()).normal, Vec3(0, 0, 1), 1e-6f);
  const Domain boxDomain = Domain::box(Vec3(1, -1, 3), Vec3(-1, 1, 2));
  const flurry::BoxDomain& box = std::get<flurry::BoxDomain>(boxDomain.shape());
  EXPECT_EQ(box.min, Vec3(-1, -1, 2));
  EXPECT_EQ(box.max, Vec3(1, 1, 3));
}

}  // namespace

// The branch-free nearest point of a triangle (kernels/domain.h fl_closest_triangle_chosen, the
// vector loops' form) is the branching one's, bit for bit: points all around and in the plane
// (every Voronoi region), on edges and corners, and degenerate triangles.
TEST(Domain, BranchFreeNearestPointOfATriangleIsTheBranchingOnes) {
  namespace k = flurry::detail::kernel;
  Random rng(11, 0, 0, 0);
  auto same = [](Vec3 a, Vec3 b) {
    return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a.x) && std::isnan(b.x));
  };
  std::size_t checked = 0;
  for (int piece = 0; piece < 400; ++piece) {
    auto point = [&](float r) {
      return Vec3(rng.uniform(-r, r), rng.uniform(-r, r), rng.uniform(-r, r));
    };
    Vec3 a = point(2.0f), b = point(2.0f), c = point(2.0f);
    if (piece % 50 == 1) c = b;                   // a degenerate triangle: two corners one
    if (piece % 50 == 2) c = a + (b - a) * 0.5f;  // ... its corners on a line
    if (piece % 50 == 3) b = c = a;               // ... a point
    const Vec3 u = b - a, w = c - a;
    for (int q = 0; q < 60; ++q) {
      Vec3 p = point(4.0f);
      if (q % 6 == 1) p = a + (b - a) * rng.uniform();                // on an edge
      if (q % 6 == 2) p = (q % 12 == 2) ? b : c;                      // on a corner
      if (q % 6 == 3) p = a + u * rng.uniform() + w * rng.uniform();  // in the plane
      const Vec3 t0 = k::fl_closest_triangle(a, b, c, p);
      const Vec3 t1 = k::fl_closest_triangle_chosen(a, b, c, p);
      EXPECT_TRUE(same(t0, t1)) << "triangle " << piece << " point " << q;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 400u * 60u);
}

TEST(Domain, BranchFreeNearestPointOfARectangleIsTheBranchingOnes) {
  namespace k = flurry::detail::kernel;
  Random rng(12, 0, 0, 0);
  auto same = [](Vec3 a, Vec3 b) {
    return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a.x) && std::isnan(b.x));
  };
  const float inf = std::numeric_limits<float>::infinity();
  std::size_t checked = 0;
  for (int piece = 0; piece < 400; ++piece) {
    auto point = [&](float r) {
      return Vec3(rng.uniform(-r, r), rng.uniform(-r, r), rng.uniform(-r, r));
    };
    const Vec3 a = point(2.0f);
    Vec3 u = point(2.0f), w = point(2.0f);
    if (piece % 50 == 1) w = u * 0.5f;                  // degenerate: its edges on a line
    if (piece % 50 == 2) u = Vec3(0.0f);                // ... an edge of no length
    if (piece % 50 == 3) u = w = Vec3(0.0f);            // ... a point
    if (piece % 50 == 4) u = Vec3(1e-30f, 0.0f, 0.0f);  // ... an edge whose length² is 0
    if (piece % 50 == 5) w = Vec3(0.0f, -1e-30f, 0.0f);
    for (int q = 0; q < 60; ++q) {
      Vec3 p = point(4.0f);
      if (q % 6 == 1) p = a + u * rng.uniform();                      // on an edge
      if (q % 6 == 2) p = (q % 12 == 2) ? a + u : a + u + w;          // on a corner
      if (q % 6 == 3) p = a + u * rng.uniform() + w * rng.uniform();  // on it
      if (q == 5) p.y = inf;
      if (q == 11) p.x = -inf;
      if (q == 17) p.z = std::numeric_limits<float>::quiet_NaN();
      const Vec3 r0 = k::fl_closest_rectangle(a, u, w, p);
      const Vec3 r1 = k::fl_closest_rectangle_chosen(a, u, w, p);
      EXPECT_TRUE(same(r0, r1)) << "rectangle " << piece << " point " << q;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 400u * 60u);
}
