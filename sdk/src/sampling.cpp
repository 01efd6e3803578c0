#include "sampling.hpp"

#include <algorithm>
#include <type_traits>

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {

namespace {

using F = float* __restrict;
using C = const float* __restrict;

void fill(F x, F y, F z, std::size_t n, Vec3 p) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = p.x;
    y[i] = p.y;
    z[i] = p.z;
  }
}

void line(C u0, F x, F y, F z, std::size_t n, Vec3 a, Vec3 d) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = a.x + d.x * u0[i];
    y[i] = a.y + d.y * u0[i];
    z[i] = a.z + d.z * u0[i];
  }
}

// Triangle: su is how far the point lies from p0 towards the opposite edge; the cross-section
// there is su long, so su's density grows linearly: su = sqrt(uniform).
void triangle(C u0, C u1, F x, F y, F z, std::size_t n, Vec3 a, Vec3 e1, Vec3 e2) {
  for (std::size_t i = 0; i < n; ++i) {
    const float su = std::sqrt(u0[i]);
    const float s = su * (1.0f - u1[i]), t = su * u1[i];
    x[i] = a.x + e1.x * s + e2.x * t;
    y[i] = a.y + e1.y * s + e2.y * t;
    z[i] = a.z + e1.z * s + e2.z * t;
  }
}

void parallelogram(C u0, C u1, F x, F y, F z, std::size_t n, Vec3 a, Vec3 e1, Vec3 e2) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = a.x + e1.x * u0[i] + e2.x * u1[i];
    y[i] = a.y + e1.y * u0[i] + e2.y * u1[i];
    z[i] = a.z + e1.z * u0[i] + e2.z * u1[i];
  }
}

void box(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 lo, Vec3 hi) {
  const Vec3 d = hi - lo;
  for (std::size_t i = 0; i < n; ++i) {
    // The min undoes a rounding step past max, so samples always pass contains().
    x[i] = std::min(lo.x + d.x * u0[i], hi.x);
    y[i] = std::min(lo.y + d.y * u1[i], hi.y);
    z[i] = std::min(lo.z + d.z * u2[i], hi.z);
  }
}

// Disc (t = 0) and cylinder: an annulus of radii ri..ro (area grows with r²) around an axis.
// (HasAxis and Surface below are template parameters so that the loops carry no branch.)
template <bool HasAxis>
void annulus(C ut, C ur, C uphi, F x, F y, F z, std::size_t n, Vec3 a, Vec3 axis, Vec3 e1,
             Vec3 e2, float ri, float ro) {
  const float ri2 = ri * ri, span = ro * ro - ri2;
  for (std::size_t i = 0; i < n; ++i) {
    const float r = std::sqrt(ur[i] * span + ri2);
    float t = 0.0f;
    if constexpr (HasAxis) t = ut[i];
    float s, c;
    sinCos2Pi(uphi[i], s, c);
    x[i] = a.x + axis.x * t + (e1.x * c + e2.x * s) * r;
    y[i] = a.y + axis.y * t + (e1.y * c + e2.y * s) * r;
    z[i] = a.z + axis.z * t + (e1.z * c + e2.z * s) * r;
  }
}

// Sphere: the volume inside radius r grows with r³ (inner == outer: the surface); uniform
// cos(theta) and phi give a uniform direction.
void sphere(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 c0, float ri, float ro) {
  const float ri3 = ri * ri * ri, span = ro * ro * ro - ri3;
  for (std::size_t i = 0; i < n; ++i) {
    const float r = cbrtNonNegative(u0[i] * span + ri3);
    const float cz = 1.0f - 2.0f * u1[i];
    const float sz = std::sqrt(std::max(0.0f, 1.0f - cz * cz));
    float s, c;
    sinCos2Pi(u2[i], s, c);
    x[i] = c0.x + sz * c * r;
    y[i] = c0.y + sz * s * r;
    z[i] = c0.z + cz * r;
  }
}

// Cone: the cross-section's area grows with t², so the volume up to t with t³; the lateral
// surface alone (inner == outer) grows with t, its area with t².
template <bool Surface>
void cone(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 apex, Vec3 axis, Vec3 e1, Vec3 e2,
          float ri, float ro) {
  const float ri2 = ri * ri, span = ro * ro - ri2;
  for (std::size_t i = 0; i < n; ++i) {
    float t, r;
    if constexpr (Surface) {
      t = std::sqrt(u0[i]);
      r = t * ro;
    } else {
      t = cbrtNonNegative(u0[i]);
      r = t * std::sqrt(u1[i] * span + ri2);
    }
    float s, c;
    sinCos2Pi(u2[i], s, c);
    x[i] = apex.x + axis.x * t + (e1.x * c + e2.x * s) * r;
    y[i] = apex.y + axis.y * t + (e1.y * c + e2.y * s) * r;
    z[i] = apex.z + axis.z * t + (e1.z * c + e2.z * s) * r;
  }
}

// The same Box-Muller transform as Random::normal().
inline float normalFrom(float ua, float ub) {
  return std::sqrt(-2.0f * std::log(1.0f - ua)) * std::cos(6.28318530718f * ub);
}

}  // namespace

int drawCount(const Domain& d) {
  return std::visit(
      [](const auto& s) -> int {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PointDomain> || std::is_same_v<S, PlaneDomain>) return 0;
        if constexpr (std::is_same_v<S, LineDomain>) return 1;
        if constexpr (std::is_same_v<S, TriangleDomain> || std::is_same_v<S, RectangleDomain> ||
                      std::is_same_v<S, DiscDomain>)
          return 2;
        if constexpr (std::is_same_v<S, BoxDomain> || std::is_same_v<S, SphereDomain> ||
                      std::is_same_v<S, CylinderDomain> || std::is_same_v<S, ConeDomain>)
          return 3;
        if constexpr (std::is_same_v<S, BlobDomain>) return 6;
        if constexpr (std::is_same_v<S, MeshDomain>) return 3;
        if constexpr (std::is_same_v<S, UnionDomain>) {
          int most = 0;
          for (const Domain& part : s.parts->parts) most = std::max(most, drawCount(part));
          return 1 + most;
        }
      },
      d.shape());
}

void sampleBatch(const Domain& d, const float* const* u, std::size_t n, float* x, float* y,
                 float* z) {
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PointDomain>) {
          fill(x, y, z, n, s.p);
        } else if constexpr (std::is_same_v<S, PlaneDomain>) {
          fill(x, y, z, n, s.point);
        } else if constexpr (std::is_same_v<S, LineDomain>) {
          line(u[0], x, y, z, n, s.p0, s.p1 - s.p0);
        } else if constexpr (std::is_same_v<S, TriangleDomain>) {
          triangle(u[0], u[1], x, y, z, n, s.p0, s.p1 - s.p0, s.p2 - s.p0);
        } else if constexpr (std::is_same_v<S, RectangleDomain>) {
          parallelogram(u[0], u[1], x, y, z, n, s.origin, s.u, s.v);
        } else if constexpr (std::is_same_v<S, DiscDomain>) {
          Vec3 e1, e2;
          orthonormalBasis(s.normal, e1, e2);
          annulus<false>(nullptr, u[0], u[1], x, y, z, n, s.center, Vec3(0.0f), e1, e2,
                         s.innerRadius, s.outerRadius);
        } else if constexpr (std::is_same_v<S, BoxDomain>) {
          box(u[0], u[1], u[2], x, y, z, n, s.min, s.max);
        } else if constexpr (std::is_same_v<S, SphereDomain>) {
          sphere(u[0], u[1], u[2], x, y, z, n, s.center, s.innerRadius, s.outerRadius);
        } else if constexpr (std::is_same_v<S, CylinderDomain>) {
          const Vec3 axis = s.p1 - s.p0;
          Vec3 e1, e2;
          orthonormalBasis(glm::normalize(axis), e1, e2);
          annulus<true>(u[0], u[1], u[2], x, y, z, n, s.p0, axis, e1, e2, s.innerRadius,
                        s.outerRadius);
        } else if constexpr (std::is_same_v<S, ConeDomain>) {
          const Vec3 axis = s.base - s.apex;
          Vec3 e1, e2;
          orthonormalBasis(glm::normalize(axis), e1, e2);
          if (s.innerRadius < s.outerRadius)
            cone<false>(u[0], u[1], u[2], x, y, z, n, s.apex, axis, e1, e2, s.innerRadius,
                        s.outerRadius);
          else
            cone<true>(u[0], u[1], u[2], x, y, z, n, s.apex, axis, e1, e2, s.innerRadius,
                       s.outerRadius);
        } else if constexpr (std::is_same_v<S, MeshDomain>) {
          // A triangle in proportion to its area, then a point uniform on it.
          const MeshData& m = *s.mesh;
          const double total = m.cumulativeArea.back();
          for (std::size_t i = 0; i < n; ++i) {
            const double target = double(u[0][i]) * total;
            std::size_t k = std::size_t(std::upper_bound(m.cumulativeArea.begin(),
                                                         m.cumulativeArea.end(), target) -
                                        m.cumulativeArea.begin());
            k = std::min(k, m.triangles.size() - 1);
            const glm::uvec3 t = m.triangles[k];
            const Vec3 a = m.vertices[t.x];
            triangle(u[1] + i, u[2] + i, x + i, y + i, z + i, 1, a, m.vertices[t.y] - a,
                     m.vertices[t.z] - a);
          }
        } else if constexpr (std::is_same_v<S, UnionDomain>) {
          // A part in proportion to its measure; the part's draws follow (a fixed count per
          // sample: 1 + the most any part needs).
          const UnionData& un = *s.parts;
          const double total = un.cumulativeMeasure.back();
          const float* rest[kMaxDomainDraws];
          for (std::size_t i = 0; i < n; ++i) {
            const double target = double(u[0][i]) * total;
            std::size_t k = std::size_t(std::upper_bound(un.cumulativeMeasure.begin(),
                                                         un.cumulativeMeasure.end(), target) -
                                        un.cumulativeMeasure.begin());
            k = std::min(k, un.parts.size() - 1);
            const int draws = drawCount(un.parts[k]);
            for (int j = 0; j < draws; ++j) rest[j] = u[1 + j] + i;
            sampleBatch(un.parts[k], rest, 1, x + i, y + i, z + i);
          }
        } else if constexpr (std::is_same_v<S, BlobDomain>) {
          for (std::size_t i = 0; i < n; ++i) {
            x[i] = s.center.x + s.stddev * normalFrom(u[0][i], u[1][i]);
            y[i] = s.center.y + s.stddev * normalFrom(u[2][i], u[3][i]);
            z[i] = s.center.z + s.stddev * normalFrom(u[4][i], u[5][i]);
          }
        }
      },
      d.shape());
}

void sampleBatch(const Fuzzy& f, const float* const* u, std::size_t n, float* out) {
  if (f.spread == 0.0f) {
    std::fill_n(out, n, f.center);
  } else if (f.distribution == Fuzzy::Distribution::Normal) {
    for (std::size_t i = 0; i < n; ++i) out[i] = f.center + f.spread * normalFrom(u[0][i], u[1][i]);
  } else {
    const float* __restrict a = u[0];
    for (std::size_t i = 0; i < n; ++i) out[i] = f.center + f.spread * (2.0f * a[i] - 1.0f);
  }
}

// Philox dominates emission; wider vectors multiply more 32-bit lanes at once, so the loop
// is built for AVX-512, AVX2 and the baseline and picked at load time.
__attribute__((target_clones("avx512f", "avx2", "default"))) void uniformBatch(
    std::uint64_t seed, std::uint32_t firstId, std::uint32_t c1, std::uint32_t c2,
    std::uint32_t block, std::size_t n, float* __restrict u0, float* __restrict u1,
    float* __restrict u2, float* __restrict u3) {
  const std::uint32_t k0 = std::uint32_t(seed), k1 = std::uint32_t(seed >> 32);
  for (std::size_t i = 0; i < n; ++i) {
    const Philox4x32::Block b = Philox4x32::generate(firstId + std::uint32_t(i), c1, c2, block, k0, k1);
    u0[i] = uniformFloat(b.v[0]);
    u1[i] = uniformFloat(b.v[1]);
    u2[i] = uniformFloat(b.v[2]);
    u3[i] = uniformFloat(b.v[3]);
  }
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
