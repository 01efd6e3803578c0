#include "sampling.hpp"

#include "shape_math.hpp"

#include <algorithm>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#define FLURRY_PHILOX_LANES
#endif

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

// Box-Muller in float arithmetic alone (kernels/math.h): no libm call, so this vectorises.
FL_LOOP void blob(C u0, C u1, C u2, C u3, F x, F y, F z, std::size_t n, Vec3 c, float sd) {
  for (std::size_t i = 0; i < n; ++i)
    store(x, y, z, i, k::fl_blob_at(c, sd, u0[i], u1[i], u2[i], u3[i]));
}

FL_LOOP void gaussian(C u0, C u1, F out, std::size_t n, float center, float spread) {
  for (std::size_t i = 0; i < n; ++i) out[i] = k::fl_fuzzy_normal(center, spread, u0[i], u1[i]);
}

// The normal at each point (the shape's own, as Domain::normal), for every shape but a mesh
// and a union.
template <class Shape>
FL_LOOP void normals(const Shape& s, C x, C y, C z, F nx, F ny, F nz, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    store(nx, ny, nz, i, detail::normal(s, Vec3(x[i], y[i], z[i])));
}

#undef FL_LOOP

// The entries of running sums[0, count) that n <= kChunk draws u0 pick in proportion to their
// steps, into k: std::upper_bound's index, clamped below `entries` (kernels/domain.cl fl_pick:
// the same search and clamp). The searches' halving steps (as many for each) run in lockstep,
// a vector loop a step with the sums gathered, and halve by a select rather than a branch
// (mispredicted half the time, ~5 ns a level: a mesh of 2,000 triangles takes 11).
constexpr std::size_t kChunk = 256;
void pickAll(const std::vector<double>& running, std::size_t entries, C u0, std::size_t n,
             std::uint32_t* __restrict k) {
  const double* __restrict sums = running.data();
  const std::size_t count = running.size();
  const double total = sums[count - 1];
  for (std::size_t i = 0; i < n; ++i) k[i] = 0;
  for (std::size_t w = count; w > 1; w -= w / 2) {
    const auto half = std::uint32_t(w / 2);
    for (std::size_t i = 0; i < n; ++i)
      k[i] = sums[k[i] + half] <= double(u0[i]) * total ? k[i] + half : k[i];
  }
  const auto last = std::uint32_t(entries - 1);
  for (std::size_t i = 0; i < n; ++i)
    k[i] = std::min(k[i] + std::uint32_t(sums[k[i]] <= double(u0[i]) * total), last);
}
void meshTriangles(const MeshData& m, C u0, std::size_t n, std::uint32_t* __restrict k) {
  pickAll(m.cumulativeArea, m.triangles.size(), u0, n, k);
}

// Points on the triangles k[0, n) of a mesh from u1, u2.
void onTriangles(const MeshData& m, const std::uint32_t* __restrict k, C u1, C u2, F x, F y, F z,
                 std::size_t n) {
  const glm::uvec3* __restrict tri = m.triangles.data();
  const Vec3* __restrict vert = m.vertices.data();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::uvec3 t = tri[k[i]];
    const Vec3 a = vert[t.x];
    store(x, y, z, i, k::fl_triangle_at(a, vert[t.y] - a, vert[t.z] - a, u1[i], u2[i]));
  }
}

// Calls f(part, rows, count, of, c0) for each part of a union that samples [0, n) picked with
// their first draws u[0]: the samples c0 + of[0 .. count) (ascending), `rows` their draws for
// the part (u[1 ..], gathered). A chunk at a time: the picks in lockstep, then the samples
// grouped by part, so that each part samples its share as one batch: sorted by the part's
// index a byte at a time (a stable radix sort; one pass up to 256 parts, a counting sort), the
// parts in ascending order.
template <class F>
void forEachPart(const UnionData& un, const float* const* u, std::size_t n, F f) {
  const std::size_t parts = un.parts.size();
  std::uint32_t picked[kChunk];
  std::uint16_t order[2][kChunk], count[257];
  float gathered[kMaxDomainDraws][kChunk];
  const float* rows[kMaxDomainDraws];
  for (int j = 0; j < kMaxDomainDraws; ++j) rows[j] = gathered[j];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t c = std::min(kChunk, n - c0);
    pickAll(un.cumulativeMeasure, parts, u[0] + c0, c, picked);
    std::uint16_t* of = order[0];
    std::uint16_t* sorted = order[1];
    for (std::size_t i = 0; i < c; ++i) of[i] = std::uint16_t(i);
    for (unsigned shift = 0; shift == 0 || ((parts - 1) >> shift) != 0; shift += 8) {
      for (unsigned d = 0; d <= 256; ++d) count[d] = 0;
      for (std::size_t i = 0; i < c; ++i) ++count[(picked[of[i]] >> shift & 255u) + 1];
      for (unsigned d = 0; d < 256; ++d) count[d + 1] = std::uint16_t(count[d + 1] + count[d]);
      for (std::size_t i = 0; i < c; ++i) sorted[count[picked[of[i]] >> shift & 255u]++] = of[i];
      std::swap(of, sorted);
    }
    // Each part's run of samples.
    for (std::size_t first = 0; first < c;) {
      const std::uint32_t p = picked[of[first]];
      std::size_t last = first + 1;
      while (last < c && picked[of[last]] == p) ++last;
      const std::size_t share = last - first;
      const int draws = drawCount(un.parts[p]);
      for (int j = 0; j < draws; ++j)
        for (std::size_t q = 0; q < share; ++q) gathered[j][q] = u[1 + j][c0 + of[first + q]];
      f(un.parts[p], rows, share, of + first, c0);
      first = last;
    }
  }
}

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
          std::uint32_t tri[kChunk];
          for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
            const std::size_t c = std::min(kChunk, n - c0);
            meshTriangles(m, u[0] + c0, c, tri);
            onTriangles(m, tri, u[1] + c0, u[2] + c0, x + c0, y + c0, z + c0, c);
          }
        } else if constexpr (std::is_same_v<S, UnionDomain>) {
          // A part in proportion to its measure; the part's draws follow (a fixed count per
          // sample: 1 + the most any part needs).
          forEachPart(*s.parts, u, n,
                      [&](const Domain& part, const float* const* rows, std::size_t count,
                          const std::uint16_t* of, std::size_t c0) {
                        float px[kChunk], py[kChunk], pz[kChunk];
                        sampleBatch(part, rows, count, px, py, pz);
                        for (std::size_t q = 0; q < count; ++q)
                          store(x + c0, y + c0, z + c0, of[q], Vec3(px[q], py[q], pz[q]));
                      });
        } else if constexpr (std::is_same_v<S, BlobDomain>) {
          blob(u[0], u[1], u[2], u[3], x, y, z, n, s.center, s.stddev);
        }
      },
      d.shape());
}

void sampledNormals(const Domain& d, const float* const* u, std::size_t n, const float* x,
                    const float* y, const float* z, float* nx, float* ny, float* nz) {
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, MeshDomain>) {
          const MeshData& m = *s.mesh;
          std::uint32_t tri[kChunk];
          for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
            const std::size_t c = std::min(kChunk, n - c0);
            meshTriangles(m, u[0] + c0, c, tri);
            for (std::size_t i = 0; i < c; ++i)
              store(nx + c0, ny + c0, nz + c0, i, m.normals[tri[i]]);
          }
        } else if constexpr (std::is_same_v<S, UnionDomain>) {
          // The part sampleBatch picked, with the draws it gave the part.
          forEachPart(*s.parts, u, n,
                      [&](const Domain& part, const float* const* rows, std::size_t count,
                          const std::uint16_t* of, std::size_t c0) {
                        float px[kChunk], py[kChunk], pz[kChunk], qx[kChunk], qy[kChunk],
                            qz[kChunk];
                        for (std::size_t q = 0; q < count; ++q)
                          px[q] = x[c0 + of[q]], py[q] = y[c0 + of[q]], pz[q] = z[c0 + of[q]];
                        sampledNormals(part, rows, count, px, py, pz, qx, qy, qz);
                        for (std::size_t q = 0; q < count; ++q)
                          store(nx + c0, ny + c0, nz + c0, of[q], Vec3(qx[q], qy[q], qz[q]));
                      });
        } else {
          normals(s, x, y, z, nx, ny, nz, n);
        }
      },
      d.shape());
}

void sampleBatch(const Fuzzy& f, const float* const* u, std::size_t n, float* out) {
  if (f.spread == 0.0f) {
    std::fill_n(out, n, f.center);
  } else if (f.distribution == Fuzzy::Distribution::Normal) {
    gaussian(u[0], u[1], out, n, f.center, f.spread);
  } else {
    const float* __restrict a = u[0];
    for (std::size_t i = 0; i < n; ++i) out[i] = kernel::fl_fuzzy_uniform(f.center, f.spread, a[i]);
  }
}

namespace {

// Philox4x32-10 on W counters at once, for this translation unit's instruction set (it is
// compiled once per set, sdk/CMakeLists.txt): the same function as kernels/philox.h, bit
// for bit. GCC vectorises the scalar loop but packs the 32x32->64-bit products with
// cross-lane shuffles. Here the even and the odd lanes of a vector run apart, each word in the
// low half of a 64-bit slot: an unsigned 32-bit multiply (which reads only the low halves)
// then gives the full product, its low half is the next round's word as it stands and its
// high half one shift away; the halves are blended back into 32-bit lanes once, at the end.
// Only the first counter word varies across lanes (the particle id).
#if defined(__AVX512F__)
// GCC 12 takes the undefined pass-through operand of its AVX-512 intrinsics for an
// uninitialised read (GCC bug 105593).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
struct Lanes {
  using V = __m512i;
  static constexpr std::size_t kWidth = 16;
  static V set1(std::uint32_t x) { return _mm512_set1_epi32(int(x)); }
  static V iota(std::uint32_t first) {
    return _mm512_add_epi32(
        set1(first), _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
  }
  static V load(const std::uint32_t* p) { return _mm512_loadu_si512(p); }
  static V xor2(V a, V b) { return _mm512_xor_si512(a, b); }
  static V xor3(V a, V b, V c) { return _mm512_ternarylogic_epi32(a, b, c, 0x96); }
  static constexpr int kInFlight = 2;  // 32 registers
  static V mul(V a, V b) { return _mm512_mul_epu32(a, b); }
  static V high(V a) { return _mm512_srli_epi64(a, 32); }
  static V pack(V even, V odd) {
    return _mm512_mask_blend_epi32(0xAAAA, even, _mm512_slli_epi64(odd, 32));
  }
  // uniformFloat: w >> 8 < 2^24 converts exactly as a signed int.
  static void storeUniform(float* p, V w) {
    _mm512_storeu_ps(p, _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_srli_epi32(w, 8)),
                                      _mm512_set1_ps(1.0f / 16777216.0f)));
  }
};
#elif defined(__AVX2__)
struct Lanes {
  using V = __m256i;
  static constexpr std::size_t kWidth = 8;
  static V set1(std::uint32_t x) { return _mm256_set1_epi32(int(x)); }
  static V iota(std::uint32_t first) {
    return _mm256_add_epi32(set1(first), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  }
  static V load(const std::uint32_t* p) {
    return _mm256_loadu_si256(reinterpret_cast<const V*>(p));
  }
  static V xor2(V a, V b) { return _mm256_xor_si256(a, b); }
  static V xor3(V a, V b, V c) { return xor2(xor2(a, b), c); }
  static constexpr int kInFlight = 1;  // 16 registers
  static V mul(V a, V b) { return _mm256_mul_epu32(a, b); }
  static V high(V a) { return _mm256_srli_epi64(a, 32); }
  static V pack(V even, V odd) {
    return _mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA);
  }
  static void storeUniform(float* p, V w) {
    _mm256_storeu_ps(p, _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(w, 8)),
                                      _mm256_set1_ps(1.0f / 16777216.0f)));
  }
};
#elif defined(__SSE2__)
struct Lanes {
  using V = __m128i;
  static constexpr std::size_t kWidth = 4;
  static V set1(std::uint32_t x) { return _mm_set1_epi32(int(x)); }
  static V iota(std::uint32_t first) {
    return _mm_add_epi32(set1(first), _mm_setr_epi32(0, 1, 2, 3));
  }
  static V load(const std::uint32_t* p) { return _mm_loadu_si128(reinterpret_cast<const V*>(p)); }
  static V xor2(V a, V b) { return _mm_xor_si128(a, b); }
  static V xor3(V a, V b, V c) { return xor2(xor2(a, b), c); }
  static constexpr int kInFlight = 1;
  static V mul(V a, V b) { return _mm_mul_epu32(a, b); }
  static V high(V a) { return _mm_srli_epi64(a, 32); }
  static V pack(V even, V odd) {  // no blend before SSE4.1
    return _mm_or_si128(_mm_and_si128(even, _mm_set1_epi64x(0xFFFFFFFF)), _mm_slli_epi64(odd, 32));
  }
  static void storeUniform(float* p, V w) {
    _mm_storeu_ps(
        p, _mm_mul_ps(_mm_cvtepi32_ps(_mm_srli_epi32(w, 8)), _mm_set1_ps(1.0f / 16777216.0f)));
  }
};
#endif

constexpr std::uint32_t kM0 = FL_PHILOX_M0, kM1 = FL_PHILOX_M1;  // kernels/philox.h
constexpr std::uint32_t kW0 = FL_PHILOX_W0, kW1 = FL_PHILOX_W1;

// Counter word 0 of particle i: firstId + i, or id[i].
struct Consecutive {
  std::uint32_t first;
  std::uint32_t operator[](std::size_t i) const { return first + std::uint32_t(i); }
#ifdef FLURRY_PHILOX_LANES
  Lanes::V lanes(std::size_t i) const {
    return Lanes::iota(first + std::uint32_t(i));
  }
#endif
};
struct Listed {
  const std::uint32_t* __restrict id;
  std::uint32_t operator[](std::size_t i) const { return id[i]; }
#ifdef FLURRY_PHILOX_LANES
  Lanes::V lanes(std::size_t i) const {
    return Lanes::load(id + i);
  }
#endif
};

#ifdef FLURRY_PHILOX_LANES
// Blocks (ids[i], c1, c2, c3) for i < n as uniforms. A round is a dependent chain (multiply,
// shift, xor): the even and odd halves of kInFlight vectors run side by side to hide it.
template <class Ids>
void philoxUniforms(Ids ids, std::uint32_t c1, std::uint32_t c2, std::uint32_t c3, std::uint32_t k0,
                    std::uint32_t k1, std::size_t n, float* __restrict u0, float* __restrict u1,
                    float* __restrict u2, float* __restrict u3) {
  using L = Lanes;
  using V = L::V;
  constexpr std::size_t W = L::kWidth;
  constexpr int U = L::kInFlight;
  // Round 1's product of c2 is the same for every lane: its results are broadcast.
  const std::uint64_t p1 = std::uint64_t(kM1) * c2;
  const V r1c0 = L::set1(std::uint32_t(p1 >> 32) ^ c1 ^ k0), r1c1 = L::set1(std::uint32_t(p1));
  const V c3k1 = L::set1(c3 ^ k1);
  const V m0 = L::set1(kM0), m1 = L::set1(kM1);
  V key0[10], key1[10];
  for (int r = 0; r < 10; ++r) {
    key0[r] = L::set1(k0 + std::uint32_t(r) * kW0);
    key1[r] = L::set1(k1 + std::uint32_t(r) * kW1);
  }
  auto blocks = [&](auto lanesOf, float* o0, float* o1, float* o2, float* o3, auto count) {
    constexpr int N = 2 * decltype(count)::value;  // halves: 2v even lanes, 2v + 1 odd lanes
    V x0[N], x1[N], x2[N], x3[N];
    for (int h = 0; h < N; ++h) {
      const V c0 = h % 2 ? L::high(lanesOf(h / 2)) : lanesOf(h / 2);
      const V p0 = L::mul(c0, m0);
      x0[h] = r1c0;
      x1[h] = r1c1;
      x2[h] = L::xor2(L::high(p0), c3k1);
      x3[h] = p0;
    }
    for (int r = 1; r < 10; ++r)
      for (int h = 0; h < N; ++h) {
        const V p0 = L::mul(x0[h], m0), p1 = L::mul(x2[h], m1);
        x0[h] = L::xor3(L::high(p1), x1[h], key0[r]);
        x1[h] = p1;
        x2[h] = L::xor3(L::high(p0), x3[h], key1[r]);
        x3[h] = p0;
      }
    for (int v = 0; v < N / 2; ++v) {
      L::storeUniform(o0 + v * W, L::pack(x0[2 * v], x0[2 * v + 1]));
      L::storeUniform(o1 + v * W, L::pack(x1[2 * v], x1[2 * v + 1]));
      L::storeUniform(o2 + v * W, L::pack(x2[2 * v], x2[2 * v + 1]));
      L::storeUniform(o3 + v * W, L::pack(x3[2 * v], x3[2 * v + 1]));
    }
  };
  std::size_t i = 0;
  for (; i + U * W <= n; i += U * W)
    blocks([&](int v) { return ids.lanes(i + v * W); }, u0 + i, u1 + i, u2 + i, u3 + i,
           std::integral_constant<int, U>{});
  // The rest, fewer than U * W, a vector at a time; the last partial one through a buffer.
  for (; i < n; i += W) {
    const std::size_t m = std::min(W, n - i);
    if (m == W) {
      blocks([&](int) { return ids.lanes(i); }, u0 + i, u1 + i, u2 + i, u3 + i,
             std::integral_constant<int, 1>{});
    } else {
      alignas(64) std::uint32_t id[W] = {};
      alignas(64) float o[4][W];
      for (std::size_t j = 0; j < m; ++j) id[j] = ids[i + j];
      blocks([&](int) { return L::load(id); }, o[0], o[1], o[2], o[3],
             std::integral_constant<int, 1>{});
      for (std::size_t j = 0; j < m; ++j) {
        u0[i + j] = o[0][j];
        u1[i + j] = o[1][j];
        u2[i + j] = o[2][j];
        u3[i + j] = o[3][j];
      }
    }
  }
}
#else
template <class Ids>
void philoxUniforms(Ids ids, std::uint32_t c1, std::uint32_t c2, std::uint32_t c3, std::uint32_t k0,
                    std::uint32_t k1, std::size_t n, float* __restrict u0, float* __restrict u1,
                    float* __restrict u2, float* __restrict u3) {
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t w0 = ids[i], w1 = c1, w2 = c2, w3 = c3;
    kernel::fl_philox_rounds(&w0, &w1, &w2, &w3, k0, k1);
    u0[i] = kernel::fl_uniform_bits(w0);
    u1[i] = kernel::fl_uniform_bits(w1);
    u2[i] = kernel::fl_uniform_bits(w2);
    u3[i] = kernel::fl_uniform_bits(w3);
  }
}
#endif

}  // namespace

void uniformBatch(std::uint64_t seed, std::uint32_t firstId, std::uint32_t c1, std::uint32_t c2,
                  std::uint32_t block, std::size_t n, float* u0, float* u1, float* u2, float* u3) {
  philoxUniforms(Consecutive{firstId}, c1, c2, block, std::uint32_t(seed),
                 std::uint32_t(seed >> 32), n, u0, u1, u2, u3);
}

void uniformBatchOfIds(std::uint64_t seed, const std::uint32_t* id, std::uint32_t c1,
                       std::uint32_t c2, std::uint32_t block, std::size_t n, float* u0, float* u1,
                       float* u2, float* u3) {
  philoxUniforms(Listed{id}, c1, c2, block, std::uint32_t(seed), std::uint32_t(seed >> 32), n, u0,
                 u1, u2, u3);
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
