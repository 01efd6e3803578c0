#include "sampling.hpp"

#include "shape_math.hpp"

#include <algorithm>
#include <type_traits>

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {

namespace {

using F = float* __restrict;
using C = const float* __restrict;

namespace k = kernel;

void fill(F x, F y, F z, std::size_t n, Vec3 p) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = p.x;
    y[i] = p.y;
    z[i] = p.z;
  }
}

void store(F x, F y, F z, std::size_t i, Vec3 p) {
  x[i] = p.x;
  y[i] = p.y;
  z[i] = p.z;
}

// Each shape's loop calls its sampler in kernels/domain.h per point; the samplers are
// branch-free (HasAxis and Surface are template parameters so that the loops carry no branch)
// and the loops vectorise. They stay out of line: inlined into sampleBatch's visitor, GCC 12
// no longer saw the box's and the sphere's loads as consecutive and left them scalar.
#define FL_LOOP __attribute__((noinline))
FL_LOOP void line(C u0, F x, F y, F z, std::size_t n, Vec3 a, Vec3 d) {
  for (std::size_t i = 0; i < n; ++i) store(x, y, z, i, k::fl_line_at(a, d, u0[i]));
}

FL_LOOP void triangle(C u0, C u1, F x, F y, F z, std::size_t n, Vec3 a, Vec3 e1, Vec3 e2) {
  for (std::size_t i = 0; i < n; ++i) store(x, y, z, i, k::fl_triangle_at(a, e1, e2, u0[i], u1[i]));
}

FL_LOOP void parallelogram(C u0, C u1, F x, F y, F z, std::size_t n, Vec3 a, Vec3 e1, Vec3 e2) {
  for (std::size_t i = 0; i < n; ++i)
    store(x, y, z, i, k::fl_parallelogram_at(a, e1, e2, u0[i], u1[i]));
}

FL_LOOP void box(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 lo, Vec3 hi) {
  for (std::size_t i = 0; i < n; ++i) store(x, y, z, i, k::fl_box_at(lo, hi, u0[i], u1[i], u2[i]));
}

template <bool HasAxis>
FL_LOOP void annulus(C ut, C ur, C uphi, F x, F y, F z, std::size_t n, Vec3 a, Vec3 axis, Vec3 e1,
                     Vec3 e2, float ri, float ro) {
  for (std::size_t i = 0; i < n; ++i) {
    float t = 0.0f;
    if constexpr (HasAxis) t = ut[i];
    store(x, y, z, i, k::fl_annulus_at(a, axis, e1, e2, ri, ro, t, ur[i], uphi[i]));
  }
}

FL_LOOP void sphere(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 c0, float ri, float ro) {
  for (std::size_t i = 0; i < n; ++i)
    store(x, y, z, i, k::fl_sphere_at(c0, ri, ro, u0[i], u1[i], u2[i]));
}

template <bool Surface>
FL_LOOP void cone(C u0, C u1, C u2, F x, F y, F z, std::size_t n, Vec3 apex, Vec3 axis, Vec3 e1,
                  Vec3 e2, float ri, float ro) {
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (Surface)
      store(x, y, z, i, k::fl_cone_surface_at(apex, axis, e1, e2, ro, u0[i], u2[i]));
    else
      store(x, y, z, i, k::fl_cone_solid_at(apex, axis, e1, e2, ri, ro, u0[i], u1[i], u2[i]));
  }
}

#undef FL_LOOP

}  // namespace

// The kinds' numbers are Domain::Shape's alternatives' indices.
static_assert(
    std::is_same_v<std::variant_alternative_t<FL_DOMAIN_BLOB, Domain::Shape>, BlobDomain>);
static_assert(
    std::is_same_v<std::variant_alternative_t<FL_DOMAIN_UNION, Domain::Shape>, UnionDomain>);

int drawCount(const Domain& d) {
  if (const auto* u = std::get_if<UnionDomain>(&d.shape())) {
    int most = 0;
    for (const Domain& part : u->parts->parts) most = std::max(most, drawCount(part));
    return 1 + most;
  }
  return int(kernel::fl_draw_count(kernel::uint(d.shape().index())));
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
          k::fl_basis(s.normal, &e1, &e2);
          annulus<false>(nullptr, u[0], u[1], x, y, z, n, s.center, Vec3(0.0f), e1, e2,
                         s.innerRadius, s.outerRadius);
        } else if constexpr (std::is_same_v<S, BoxDomain>) {
          box(u[0], u[1], u[2], x, y, z, n, s.min, s.max);
        } else if constexpr (std::is_same_v<S, SphereDomain>) {
          sphere(u[0], u[1], u[2], x, y, z, n, s.center, s.innerRadius, s.outerRadius);
        } else if constexpr (std::is_same_v<S, CylinderDomain>) {
          const Vec3 axis = s.p1 - s.p0;
          Vec3 e1, e2;
          k::fl_basis(k::fl_normalize(axis), &e1, &e2);
          annulus<true>(u[0], u[1], u[2], x, y, z, n, s.p0, axis, e1, e2, s.innerRadius,
                        s.outerRadius);
        } else if constexpr (std::is_same_v<S, ConeDomain>) {
          const Vec3 axis = s.base - s.apex;
          Vec3 e1, e2;
          k::fl_basis(k::fl_normalize(axis), &e1, &e2);
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
            std::size_t k = std::size_t(
                std::upper_bound(m.cumulativeArea.begin(), m.cumulativeArea.end(), target) -
                m.cumulativeArea.begin());
            k = std::min(k, m.triangles.size() - 1);
            const glm::uvec3 t = m.triangles[k];
            const Vec3 a = m.vertices[t.x];
            store(x, y, z, i,
                  k::fl_triangle_at(a, m.vertices[t.y] - a, m.vertices[t.z] - a, u[1][i], u[2][i]));
          }
        } else if constexpr (std::is_same_v<S, UnionDomain>) {
          // A part in proportion to its measure; the part's draws follow (a fixed count per
          // sample: 1 + the most any part needs).
          const UnionData& un = *s.parts;
          const double total = un.cumulativeMeasure.back();
          const float* rest[kMaxDomainDraws];
          for (std::size_t i = 0; i < n; ++i) {
            const double target = double(u[0][i]) * total;
            std::size_t k = std::size_t(
                std::upper_bound(un.cumulativeMeasure.begin(), un.cumulativeMeasure.end(), target) -
                un.cumulativeMeasure.begin());
            k = std::min(k, un.parts.size() - 1);
            const int draws = drawCount(un.parts[k]);
            for (int j = 0; j < draws; ++j) rest[j] = u[1 + j] + i;
            sampleBatch(un.parts[k], rest, 1, x + i, y + i, z + i);
          }
        } else if constexpr (std::is_same_v<S, BlobDomain>) {
          for (std::size_t i = 0; i < n; ++i)
            store(x, y, z, i,
                  k::fl_blob_at(s.center, s.stddev, u[0][i], u[1][i], u[2][i], u[3][i], u[4][i],
                                u[5][i]));
        }
      },
      d.shape());
}

void sampleBatch(const Fuzzy& f, const float* const* u, std::size_t n, float* out) {
  if (f.spread == 0.0f) {
    std::fill_n(out, n, f.center);
  } else if (f.distribution == Fuzzy::Distribution::Normal) {
    for (std::size_t i = 0; i < n; ++i)
      out[i] = f.center + f.spread * kernel::fl_normal_from(u[0][i], u[1][i]);
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
    const Philox4x32::Block b =
        Philox4x32::generate(firstId + std::uint32_t(i), c1, c2, block, k0, k1);
    u0[i] = uniformFloat(b.v[0]);
    u1[i] = uniformFloat(b.v[1]);
    u2[i] = uniformFloat(b.v[2]);
    u3[i] = uniformFloat(b.v[3]);
  }
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
