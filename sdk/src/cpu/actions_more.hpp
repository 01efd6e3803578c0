// The CPU kernels of the force fields, absorbers, blockers and the rest of the vocabulary.
// Those that are plain arithmetic keep the branch-free, __restrict style of kernels.hpp;
// most that sample domains, draw random numbers or call user code run per particle (RandomAccel
// draws and samples in batches).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../field_math.hpp"
#include "../isa_namespace.hpp"
#include "../sampling.hpp"
#include "kernels.hpp"

namespace flurry::detail::cpu {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

namespace {
inline Vec3 at(const float* const* a, std::size_t i) {
  return Vec3(a[0][i], a[1][i], a[2][i]);
}
inline void put(float* const* a, std::size_t i, Vec3 v) {
  a[0][i] = v.x;
  a[1][i] = v.y;
  a[2][i] = v.z;
}
// The per-particle math of the forces and absorbers is kernels/forces.h and absorb.h, shared
// with the device (forces_kernel.hpp and kernels.hpp include them in namespace kernel); each
// apply below reads its action's record (BlockContext::record(), made by actionParams as the
// device's is) and calls them.
// Gravitate's and Follow's pull towards a neighbour d away (kernels/forces.h fl_pull).
inline Vec3 softPull(Vec3 d, const cl::FlPullParams& q) {
  Vec3 o;
  kernel::fl_pull(q, d.x, d.y, d.z, &o.x, &o.y, &o.z);
  return o;
}
// Calls f(&x, &y, &z) on locals holding lane particle i's vector and stores them back: the
// shared kernels' pointers into the arrays would hide their __restrict from the vectoriser.
template <class F>
inline void onLocals(float* const* lane, std::size_t i, F f) {
  float x = lane[0][i], y = lane[1][i], z = lane[2][i];
  f(&x, &y, &z);
  lane[0][i] = x;
  lane[1][i] = y;
  lane[2][i] = z;
}
// The particles this absorber would kill survive if they pass it: decided once per particle
// and absorber (kernels/absorb.h), so a fraction passThrough of them passes in every mode.
inline void passThrough(const BlockContext& c, const Lanes& L, std::size_t n, float fraction) {
  if (fraction <= 0.0f) return;
  const std::uint32_t code = c.action + 1;
  // The group's part of the stream base, without the sub-step's (fused_pass.cpp: s << 8).
  const std::uint32_t key = (c.streamBase & 0xFFFF0000u) + c.action;
  const auto lo = std::uint32_t(c.seed), hi = std::uint32_t(c.seed >> 32);
  // Drawn for the particles taken only (a branch, not a vectorised draw for every particle).
  for (std::size_t i = 0; i < n; ++i)
    if (c.dead[i] == code) [[unlikely]]
      c.dead[i] = kernel::fl_dead_after_pass(code, code, L.id[i], key, lo, hi, fraction);
}
inline Random actionRandom(const BlockContext& c, const Lanes& L, std::size_t i) {
  return Random(c.seed, L.id[i], c.step, c.streamBase + c.action);
}

// Philox block `block` of every particle's action stream as uniforms: words 0-3 of the block
// are uniforms 4·block .. 4·block + 3 of actionRandom(c, L, i), as Random draws them
// (uniformBatchOfIds computes many blocks at once with vector instructions).
inline void actionUniforms(const BlockContext& c, const std::uint32_t* id, std::uint32_t block,
                           std::size_t n, float* u0, float* u1, float* u2, float* u3) {
  uniformBatchOfIds(c.seed, id, c.step, c.streamBase + c.action, block, n, u0, u1, u2, u3);
}

constexpr std::size_t kDrawBatch = 256;  // particles sampled at once (the rows live on the stack)

// Samples `d` for every particle of the block from its action stream, in batches: the same
// numbers as d.sample(actionRandom(c, L, i)) (Domain::sample is sampleBatch with a batch of
// one). use(first, m, x, y, z) receives each batch.
template <class Use>
inline void sampleFromActionStreams(const Domain& d, const Lanes& L, std::size_t n,
                                    const BlockContext& c, Use use) {
  const int draws = drawCount(d);
  alignas(64) float u[kMaxDomainDraws][kDrawBatch];
  alignas(64) float out[3][kDrawBatch];
  const float* rows[kMaxDomainDraws];
  for (int k = 0; k < kMaxDomainDraws; ++k) rows[k] = u[k];
  for (std::size_t first = 0; first < n; first += kDrawBatch) {
    const std::size_t m = std::min(kDrawBatch, n - first);
    for (int blk = 0; blk * 4 < draws; ++blk)
      actionUniforms(c, L.id + first, std::uint32_t(blk), m, u[4 * blk], u[4 * blk + 1],
                     u[4 * blk + 2], u[4 * blk + 3]);
    sampleBatch(d, rows, m, out[0], out[1], out[2]);
    use(first, m, out[0], out[1], out[2]);
  }
}

// v += a[i]·dt[i] over a batch.
template <class Dt>
inline void addVaryingLoop(float* __restrict vx, float* __restrict vy, float* __restrict vz,
                           const float* __restrict ax, const float* __restrict ay,
                           const float* __restrict az, std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) {
    vx[i] = vx[i] + ax[i] * dt[i];
    vy[i] = vy[i] + ay[i] * dt[i];
    vz[i] = vz[i] + az[i] * dt[i];
  }
}
}  // namespace

// ---- Absorbers, blockers -----------------------------------------------------------------

// Avoid's threat: outside the shape now, inside at the look-ahead point p + v·look.
template <class Shape>
inline void threatLoop(const Shape& shape, const float* __restrict px, const float* __restrict py,
                       const float* __restrict pz, const float* __restrict vx,
                       const float* __restrict vy, const float* __restrict vz,
                       std::uint8_t* __restrict threat, std::size_t n, float look) {
  for (std::size_t i = 0; i < n; ++i) {
    const int now = detail::inside(shape, Vec3(px[i], py[i], pz[i]));
    const int next = detail::inside(
        shape, Vec3(px[i] + vx[i] * look, py[i] + vy[i] * look, pz[i] + vz[i] * look));
    threat[i] = std::uint8_t((now == 0) & (next != 0));
  }
}

// Where each straight path p -> p + v·len crosses a planar piece's plane (fl_path_crosses
// from the piece's nearest point, as Domain gives it), *h, and how far that lies from the
// piece (Domain::distance), into gap; infinite where it does not cross. Sink's Hit and a
// planar obstacle's Avoid test a chunk of particles so, in vectors: the piece's nearest point
// is branch-free (a plane's and a disc's as they are, a triangle's and a rectangle's in their
// branch-free forms: closestChosen).
template <class Shape, class Len>
[[gnu::flatten]] inline void planarCrossingLoop(
    const Shape& s, const float* __restrict px, const float* __restrict py,
    const float* __restrict pz, const float* __restrict vx, const float* __restrict vy,
    const float* __restrict vz, Len len, std::size_t n, float* __restrict gap, float* __restrict hx,
    float* __restrict hy, float* __restrict hz) {
  // Two loops: the crossings, then their distances. In one, GCC 12 chose between the two
  // points' tests inside the piece (a choice of masks) and vectorised neither a triangle's nor
  // a rectangle's loop.
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p(px[i], py[i], pz[i]);
    const Vec3 q = p + Vec3(vx[i], vy[i], vz[i]) * len[i];
    Vec3 h = p;
    const int crosses = kernel::fl_path_crosses(p, q, detail::closestChosen(s, p), s.normal, &h);
    gap[i] = crosses ? 0.0f : kInfinity;
    hx[i] = h.x, hy[i] = h.y, hz[i] = h.z;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 h(hx[i], hy[i], hz[i]);
    const float d = glm::length(h - detail::closestChosen(s, h));
    gap[i] = gap[i] == 0.0f ? d : kInfinity;
  }
}

// planarCrossingLoop over chunks of the block: f(first, m, gap, h) for each.
constexpr std::size_t kCrossingChunk = 256;
using CrossingPoints = const float (*)[kCrossingChunk];
template <class Len, class F>
inline void planarCrossings(const Domain& piece, const Lanes& L, std::size_t n, Len len, F f) {
  constexpr std::size_t kChunk = kCrossingChunk;
  alignas(64) float gap[kChunk], h[3][kChunk];
  std::visit(
      [&]<class Shape>(const Shape& s) {
        if constexpr (kPlanarShape<Shape>) {
          for (std::size_t first = 0; first < n; first += kChunk) {
            const std::size_t m = std::min(kChunk, n - first);
            planarCrossingLoop(s, L.p[0] + first, L.p[1] + first, L.p[2] + first, L.v[0] + first,
                               L.v[1] + first, L.v[2] + first, OffsetDt<Len>{len, first}, m, gap,
                               h[0], h[1], h[2]);
            f(first, m, static_cast<const float*>(gap), CrossingPoints(h));
          }
        }
      },
      piece.shape());
}

template <class Shape, class Dt>
inline void sinkMotionLoop(const Shape& shape, const float* __restrict px,
                           const float* __restrict py, const float* __restrict pz,
                           const float* __restrict vx, const float* __restrict vy,
                           const float* __restrict vz, std::uint32_t* __restrict dead,
                           std::size_t n, Dt dt, std::uint32_t code, bool enter) {
  for (std::size_t i = 0; i < n; ++i) {
    const int now = detail::inside(shape, Vec3(px[i], py[i], pz[i]));
    const int next = detail::inside(
        shape, Vec3(px[i] + vx[i] * dt[i], py[i] + vy[i] * dt[i], pz[i] + vz[i] * dt[i]));
    dead[i] = kernel::fl_dead_sink_motion(now, next, enter, code, dead[i]);
  }
}

inline void apply(const Sink& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const std::uint32_t code = c.action + 1;
  using M = Sink::Mode;
  if (a.mode == M::Inside || a.mode == M::Outside) {
    std::visit(
        [&](const auto& shape) {
          sinkLoop(shape, L.p[0], L.p[1], L.p[2], c.dead, n, code, a.mode == M::Inside);
        },
        a.region.shape());
  } else if (a.mode == M::Enter || a.mode == M::Leave) {
    withDt(c, [&](auto dt) {
      std::visit(
          [&](const auto& shape) {
            sinkMotionLoop(shape, L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], c.dead, n, dt,
                           code, a.mode == M::Enter);
          },
          a.region.shape());
    });
  } else {  // Hit: the coming Move crosses the plane piece (an infinite gap: it does not)
    withDt(c, [&](auto dt) {
      planarCrossings(a.region, L, n, dt,
                      [&](std::size_t first, std::size_t m, const float* gap, CrossingPoints h) {
                        std::uint32_t* __restrict dead = c.dead + first;
                        for (std::size_t k = 0; k < m; ++k)
                          dead[k] = kernel::fl_dead_sink_hit(
                              gap[k], Vec3(h[0][k], h[1][k], h[2][k]), code, dead[k]);
                      });
    });
  }
  passThrough(c, L, n, c.record().own.sink.passThrough);
}

inline void apply(const SinkVelocity& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  std::visit(
      [&](const auto& shape) {
        sinkLoop(shape, L.v[0], L.v[1], L.v[2], c.dead, n, c.action + 1, a.killInside);
      },
      a.velocity.shape());
}

inline void apply(const Block& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  // The list's first blocker starts from "visible"; the others can only hide more.
  std::uint32_t* __restrict vis = L.visible;
  if (c.action == c.firstBlocker) std::fill_n(vis, n, 1u);
  std::visit(
      [&](const auto& shape) {
        const float* __restrict px = L.p[0];
        const float* __restrict py = L.p[1];
        const float* __restrict pz = L.p[2];
        for (std::size_t i = 0; i < n; ++i)
          vis[i] = kernel::fl_visible_after_block(detail::inside(shape, Vec3(px[i], py[i], pz[i])),
                                                  vis[i]);
      },
      a.region.shape());
}

// ---- Forces ------------------------------------------------------------------------------

inline void apply(const RotDamping&, const Lanes& L, std::size_t n, const BlockContext& c) {
  dampLanes(c.record().own.damping, L.rot, n, c);
}

inline void apply(const OrbitPoint&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlOrbitPointParams o = c.record().own.orbitPoint;
  velocityLoop(L, n, c, [o](float px, float py, float pz, float dt, float* x, float* y, float* z) {
    kernel::fl_orbit_point(o, dt, px, py, pz, x, y, z);
  });
}

inline void apply(const OrbitLine&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlOrbitLineParams o = c.record().own.orbitLine;
  velocityLoop(L, n, c, [o](float px, float py, float pz, float dt, float* x, float* y, float* z) {
    kernel::fl_orbit_line(o, dt, px, py, pz, x, y, z);
  });
}

// kMatchLanes particles at a time scan the others in lockstep, each summing in its own
// order (fl_match_mean's: the others by index, a neighbour's value added, anyone else's -0,
// which leaves every sum as it was), so that the scan runs in vectors with the same sums.
// GCC's vector types of this build's width, two side by side, not its vectoriser: that one
// turned "add -0 or u" back into a conditional add, and branched on whether any lane had a
// neighbour.
constexpr std::size_t kMatchWidth = FLURRY_ISA_FLOATS, kMatchLanes = 2 * kMatchWidth;
using MatchFloats = float __attribute__((vector_size(4 * kMatchWidth)));
using MatchInts = std::int32_t __attribute__((vector_size(4 * kMatchWidth)));
// The positions and indices of the block's particles i0.. (up to kMatchLanes) a scan takes;
// lanes past the block at the origin, with no index to skip.
struct ScanLanes {
  alignas(64) float p[3][kMatchLanes] = {};
  alignas(64) std::int32_t own[kMatchLanes];
  std::size_t lanes;
  ScanLanes(const float* const* pos, std::size_t base, std::size_t i0, std::size_t n)
      : lanes(std::min(kMatchLanes, n - i0)) {
    for (std::size_t l = 0; l < kMatchLanes; ++l) own[l] = std::int32_t(base + i0 + l);
    for (int d = 0; d < 3; ++d)
      for (std::size_t l = 0; l < lanes; ++l) p[d][l] = pos[d][i0 + l];
  }
};

inline void matchScan(const float* __restrict sx, const float* __restrict sy,
                      const float* __restrict sz, const float* __restrict fx,
                      const float* __restrict fy, const float* __restrict fz, std::size_t others,
                      const float* px0, const float* py0, const float* pz0,
                      const std::int32_t* own0, float r2max, float* sumx, float* sumy, float* sumz,
                      std::int32_t* count) {
  MatchFloats px[2], py[2], pz[2], ax[2], ay[2], az[2];
  MatchInts own[2], cn[2];
  std::memcpy(px, px0, sizeof px);
  std::memcpy(py, py0, sizeof py);
  std::memcpy(pz, pz0, sizeof pz);
  std::memcpy(own, own0, sizeof own);
  const MatchFloats zero = {}, minusZero = -zero;
  for (int h = 0; h < 2; ++h) ax[h] = ay[h] = az[h] = zero, cn[h] = MatchInts{};
  for (std::size_t j = 0; j < others; ++j) {
    // (x - +0 broadcasts x exactly, -0 included: + would turn a -0 into +0)
    const MatchFloats qx = sx[j] - zero, qy = sy[j] - zero, qz = sz[j] - zero;
    const MatchFloats ux = fx[j] - zero, uy = fy[j] - zero, uz = fz[j] - zero;
    for (int h = 0; h < 2; ++h) {
      const MatchFloats dx = qx - px[h], dy = qy - py[h], dz = qz - pz[h];
      const MatchInts out = (dx * dx + dy * dy + dz * dz > r2max) | (own[h] == std::int32_t(j));
      ax[h] += out ? minusZero : ux;
      ay[h] += out ? minusZero : uy;
      az[h] += out ? minusZero : uz;
      cn[h] += out + 1;  // (out is -1 or 0)
    }
  }
  std::memcpy(sumx, ax, sizeof ax);
  std::memcpy(sumy, ay, sizeof ay);
  std::memcpy(sumz, az, sizeof az);
  std::memcpy(count, cn, sizeof cn);
}

// Gravitate: as matchScan, kMatchLanes particles pulled in lockstep, each summing its pulls
// in the scalar order (itself adding -0). The pulls of a step's lanes go through an array, so
// that GCC vectorises them (sqrt) and does not fold the sums into conditional adds.
inline void gravitateScan(const float* __restrict sx, const float* __restrict sy,
                          const float* __restrict sz, std::size_t others, const float* px,
                          const float* py, const float* pz, const std::int32_t* own,
                          const cl::FlPullParams& q, float* sumx, float* sumy, float* sumz) {
  MatchFloats ax[2] = {}, ay[2] = {}, az[2] = {};
  alignas(64) float tx[kMatchLanes], ty[kMatchLanes], tz[kMatchLanes];
  for (std::size_t j = 0; j < others; ++j) {
    const float qx = sx[j], qy = sy[j], qz = sz[j];
    for (std::size_t l = 0; l < kMatchLanes; ++l) {
      float ox, oy, oz;
      kernel::fl_pull(q, qx - px[l], qy - py[l], qz - pz[l], &ox, &oy, &oz);
      const bool me = own[l] == std::int32_t(j);
      tx[l] = me ? -0.0f : ox;
      ty[l] = me ? -0.0f : oy;
      tz[l] = me ? -0.0f : oz;
    }
    for (int h = 0; h < 2; ++h) {
      MatchFloats x, y, z;
      std::memcpy(&x, tx + h * kMatchWidth, sizeof x);
      std::memcpy(&y, ty + h * kMatchWidth, sizeof y);
      std::memcpy(&z, tz + h * kMatchWidth, sizeof z);
      ax[h] += x, ay[h] += y, az[h] += z;
    }
  }
  std::memcpy(sumx, ax, sizeof ax);
  std::memcpy(sumy, ay, sizeof ay);
  std::memcpy(sumz, az, sizeof az);
}

// f(i, pull) for particles [0, n) of a block at `base`, at positions `pos`: each one's pulls
// towards the snapshot's others, summed by gravitateScan (its own loop's and, at each stage,
// an integrator's).
template <class F>
inline void forEachGravitatePull(const Snapshot& s, const float* const* pos, std::size_t base,
                                 std::size_t n, const cl::FlPullParams& q, F f) {
  for (std::size_t i0 = 0; i0 < n; i0 += kMatchLanes) {
    const ScanLanes at0(pos, base, i0, n);
    alignas(64) float ax[kMatchLanes], ay[kMatchLanes], az[kMatchLanes];
    gravitateScan(s.p[0], s.p[1], s.p[2], s.size, at0.p[0], at0.p[1], at0.p[2], at0.own, q, ax, ay,
                  az);
    for (std::size_t l = 0; l < at0.lanes; ++l) f(i0 + l, Vec3(ax[l], ay[l], az[l]));
  }
}

inline void apply(const Gravitate&, const Lanes& L, std::size_t n, const BlockContext& c) {
  forEachGravitatePull(
      *c.snapshot, L.p, c.base, n, c.record().own.pull,
      [&](std::size_t i, Vec3 pull) { put(L.v, i, at(L.v, i) + pull * c.dtAt(i)); });
}

// fl_vortex, bit for bit, with its approach factor apart from the field: once for a block's
// step, each newborn's in a loop of its own. (Taken inside the loop over the field, the
// factor's exp, even of the same step for all, kept that loop scalar.)
inline void apply(const Vortex&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlVortexParams v = c.record().own.vortex;
  const kernel::FlVortex field = kernel::fl_vortex_of(v);
  auto run = [&](std::size_t first, std::size_t m, auto factor) {
    velocityLoop(L.p[0] + first, L.p[1] + first, L.p[2] + first, L.v[0] + first, L.v[1] + first,
                 L.v[2] + first, m, UniformDt{0.0f},
                 [field, factor](std::size_t i, float px, float py, float pz, float, float* x,
                                 float* y, float* z) {
                   kernel::fl_vortex_step(field, factor[i], px, py, pz, x, y, z);
                 });
  };
  if (!c.ownDt) {
    run(0, n, UniformDt{kernel::fl_force_approach(v.responsiveness, c.dt, v.dt, v.decay)});
    return;
  }
  constexpr std::size_t kChunk = 256;
  alignas(64) float factor[kChunk];
  const float rate = v.responsiveness, madeDt = v.dt, made = v.decay;
  for (std::size_t first = 0; first < n; first += kChunk) {
    const std::size_t m = std::min(kChunk, n - first);
    const float* __restrict own = c.ownDt + first;
    for (std::size_t i = 0; i < m; ++i)
      factor[i] = kernel::fl_force_approach(rate, own[i], madeDt, made);
    run(first, m, OwnDt{factor});
  }
}

inline void apply(const Jet& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlJetParams jet = c.record().own.jet;
  const bool constant = std::holds_alternative<PointDomain>(a.acceleration.shape());
  const Vec3 fixed = constant ? std::get<PointDomain>(a.acceleration.shape()).p : Vec3(0.0f);
  if (constant) {  // the same sums, kept by a choice: a vector loop
    velocityLoop(
        L, n, c,
        [jet, fixed](float px, float py, float pz, float dt, float* x, float* y, float* z) {
          const int in = kernel::fl_jet_reaches(jet, px, py, pz);
          const float nx = *x + fixed.x * dt, ny = *y + fixed.y * dt, nz = *z + fixed.z * dt;
          *x = in ? nx : *x;
          *y = in ? ny : *y;
          *z = in ? nz : *z;
        });
    return;
  }
  // A drawn acceleration: where a quarter of the block's particles or more are in reach, every
  // particle's is drawn in batches (the same numbers as one Random each) and kept by a choice;
  // where fewer are, theirs are drawn one by one. (Measured on the AVX2 build: a batch costs
  // about what one by one costs with a fifth in reach.)
  std::size_t reached = 0;
  {
    const float* __restrict px = L.p[0];
    const float* __restrict py = L.p[1];
    const float* __restrict pz = L.p[2];
    for (std::size_t i = 0; i < n; ++i)
      reached += std::size_t(kernel::fl_jet_reaches(jet, px[i], py[i], pz[i]));
  }
  if (reached == 0) return;
  if (reached * 4 >= n) {
    sampleFromActionStreams(
        a.acceleration, L, n, c,
        [&](std::size_t first, std::size_t m, float* ax, float* ay, float* az) {
          withDt(c, [&](auto dt) {
            velocityLoop(L.p[0] + first, L.p[1] + first, L.p[2] + first, L.v[0] + first,
                         L.v[1] + first, L.v[2] + first, m, OffsetDt<decltype(dt)>{dt, first},
                         [jet, ax, ay, az](std::size_t k, float px, float py, float pz, float h,
                                           float* x, float* y, float* z) {
                           const int in = kernel::fl_jet_reaches(jet, px, py, pz);
                           const float nx = *x + ax[k] * h, ny = *y + ay[k] * h,
                                       nz = *z + az[k] * h;
                           *x = in ? nx : *x;
                           *y = in ? ny : *y;
                           *z = in ? nz : *z;
                         });
          });
        });
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!kernel::fl_jet_reaches(jet, L.p[0][i], L.p[1][i], L.p[2][i])) continue;
    Vec3 acc = fixed;
    if (!constant) {
      Random rng = actionRandom(c, L, i);
      acc = a.acceleration.sample(rng);
    }
    put(L.v, i, at(L.v, i) + acc * c.dtAt(i));
  }
}

inline void apply(const Explosion&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlExplosionParams e = c.record().own.explosion;
  if (c.time + 0.5 * c.dt < e.time) return;  // (fl_explosion's test, once for the block)
  // The blast over the whole (sub-)step for every particle, a newborn too: its front is at
  // mid-step (as the device's).
  const float dt = c.dt;
  const double time = c.time;
  velocityLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, UniformDt{dt},
               [e, dt, time](float px, float py, float pz, float, float* x, float* y, float* z) {
                 kernel::fl_explosion(e, dt, time, px, py, pz, x, y, z);
               });
}

// The accelerations are drawn for a batch of particles at once (Philox vectorised, the
// domain sampled by sampleBatch), the same numbers as one Random per particle.
inline void apply(const RandomAccel& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlFalloffParams falloff = c.record().falloff;
  const bool weighted = falloff.radius < kInfinity;
  sampleFromActionStreams(a.acceleration, L, n, c,
                          [&](std::size_t first, std::size_t m, float* ax, float* ay, float* az) {
                            if (weighted) {  // v + a·(dt·w), as without a falloff (w = 1)
                              withFalloff<true>(falloff, [&](auto fall) {
                                for (std::size_t k = 0; k < m; ++k) {
                                  const std::size_t i = first + k;
                                  const float s =
                                      c.dtAt(i) * kernel::fl_falloff_weight(fall(), L.p[0][i],
                                                                            L.p[1][i], L.p[2][i]);
                                  ax[k] *= s;
                                  ay[k] *= s;
                                  az[k] *= s;
                                }
                              });
                              addVaryingLoop(L.v[0] + first, L.v[1] + first, L.v[2] + first, ax, ay,
                                             az, m, UniformDt{1.0f});
                              return;
                            }
                            withDt(c, [&](auto dt) {
                              addVaryingLoop(L.v[0] + first, L.v[1] + first, L.v[2] + first, ax, ay,
                                             az, m, OffsetDt<decltype(dt)>{dt, first});
                            });
                          });
}
inline void apply(const RandomDisplace& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  sampleFromActionStreams(a.displacement, L, n, c,
                          [&](std::size_t first, std::size_t m, float* x, float* y, float* z) {
                            withDt(c, [&](auto dt) {
                              addVaryingLoop(L.p[0] + first, L.p[1] + first, L.p[2] + first, x, y,
                                             z, m, OffsetDt<decltype(dt)>{dt, first});
                            });
                          });
}
// A batch of samples stored into a vector attribute.
inline void storeSamples(const Domain& d, float* const* lane, const Lanes& L, std::size_t n,
                         const BlockContext& c) {
  sampleFromActionStreams(d, L, n, c,
                          [&](std::size_t first, std::size_t m, float* x, float* y, float* z) {
                            copyLoop(lane[0] + first, lane[1] + first, lane[2] + first, x, y, z, m);
                          });
}
inline void apply(const RandomVelocity& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  storeSamples(a.velocity, L.v, L, n, c);
}
inline void apply(const RandomRotVelocity& a, const Lanes& L, std::size_t n,
                  const BlockContext& c) {
  storeSamples(a.rotVelocity, L.rot, L, n, c);
}

// fl_turbulence's arithmetic per particle, bit for bit, with its loop over octaves outside the
// loops over a chunk of particles: each octave's noise (eight corners unrolled, no branch) then
// runs in vectors, which a loop of a runtime count inside the particle loop prevented.
inline void apply(const Turbulence&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlActionParams& r = c.record();
  const kernel::FlTurbulence t = kernel::fl_turbulence_of(r.own.turbulence);
  const cl::FlFalloffParams f = r.falloff;
  // fl_turbulence_field's drift at the time, and its point's scaling.
  const float time = float(c.time);
  const float sx = t.driftX * time, sy = t.driftY * time, sz = t.driftZ * time;
  constexpr std::size_t kChunk = 128;
  alignas(64) float q[3][kChunk], curl[3][kChunk];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    const float* __restrict px = L.p[0] + c0;
    const float* __restrict py = L.p[1] + c0;
    const float* __restrict pz = L.p[2] + c0;
    for (std::size_t i = 0; i < m; ++i) {
      q[0][i] = (px[i] - sx) * t.frequency;
      q[1][i] = (py[i] - sy) * t.frequency;
      q[2][i] = (pz[i] - sz) * t.frequency;
      curl[0][i] = curl[1][i] = curl[2][i] = 0.0f;
    }
    float scale = 1.0f, freq = 1.0f;  // (fl_curl_noise's)
    for (kernel::uint o = 0; o < t.octaves; ++o) {
      const float k = scale * freq;
      for (std::size_t i = 0; i < m; ++i)
        kernel::fl_curl_octave(q[0][i] * freq, q[1][i] * freq, q[2][i] * freq, o, k, &curl[0][i],
                               &curl[1][i], &curl[2][i]);
      scale *= 0.5f;
      freq *= 2.0f;
    }
    withFalloff(f, [&](auto fall) {
      withDt(c, [&](auto dt) {
        velocityLoop(px, py, pz, L.v[0] + c0, L.v[1] + c0, L.v[2] + c0, m,
                     OffsetDt<decltype(dt)>{dt, c0},
                     [&](std::size_t i, float x0, float y0, float z0, float dti, float* x, float* y,
                         float* z) {
                       const float w = kernel::fl_falloff_weight(fall(), x0, y0, z0);
                       kernel::fl_add_scaled(curl[0][i] * t.amplitude, curl[1][i] * t.amplitude,
                                             curl[2][i] * t.amplitude, dti * w, x, y, z);
                     });
      });
    });
  }
}

// A field acting on charge over mass: f(falloff, dt, px, py, pz, x, y, z, charge, mass) on
// each particle's velocity, in a vector loop (velocityLoop, withFalloff).
template <class F>
inline void chargedLoop(const Lanes& L, std::size_t n, const BlockContext& c, F f) {
  const float* __restrict charge = L.charge;
  const float* __restrict mass = L.mass;
  withFalloff(c.record().falloff, [&](auto fall) {
    velocityLoop(L, n, c,
                 [f, fall, charge, mass](std::size_t i, float px, float py, float pz, float dt,
                                         float* x, float* y, float* z) {
                   f(fall(), dt, px, py, pz, x, y, z, charge[i], mass[i]);
                 });
  });
}

inline void apply(const ElectricField&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlElectricParams e = c.record().own.electric;
  chargedLoop(L, n, c, [e](const cl::FlFalloffParams& f, auto... args) {
    kernel::fl_electric(e, f, args...);
  });
}

inline void apply(const MagneticField&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlMagneticParams m = c.record().own.magnetic;
  if (!(m.strength > 0.0f)) return;
  chargedLoop(L, n, c, [m](const cl::FlFalloffParams& f, auto... args) {
    kernel::fl_magnetic_field_on(m, f, args...);
  });
}

// SampledField over a grid of fewer than 2^31 floats (its lookups gathered with 32-bit
// offsets), in mode kCarry; `fall` the falloff as withFalloff gives it.
template <int kCarry, class Dt>
[[gnu::flatten]] inline void sampledFieldLoop(
    const float* __restrict px, const float* __restrict py, const float* __restrict pz,
    float* __restrict vx, float* __restrict vy, float* __restrict vz, std::size_t n, Dt dt,
    const float* __restrict grid, int nx, int ny, int nz, Vec3 o, float voxel,
    cl::FlSampledFieldParams s, cl::FlFalloffParams fall) {
  s.carry = kCarry;
  const float ox = o.x, oy = o.y, oz = o.z;
  // The carry's approach (an exp) once for a step length all share.
  constexpr bool kUniform = std::is_same_v<Dt, UniformDt>;
  float approach = 0.0f;
  if constexpr (kCarry && kUniform)
    approach = kernel::fl_force_approach(s.responsiveness, dt[0], s.dt, s.decay);
  for (std::size_t i = 0; i < n; ++i) {
    const float x0 = px[i], y0 = py[i], z0 = pz[i];
    const Vec3 u = kernel::fl_grid_sample_int(grid, nx, ny, nz, ox, oy, oz, voxel, x0, y0, z0);
    float x = vx[i], y = vy[i], z = vz[i];
    const float w = kernel::fl_falloff_weight(fall, x0, y0, z0);
    if constexpr (kCarry && !kUniform)
      kernel::fl_sampled_field(s, dt[i], w, u.x, u.y, u.z, &x, &y, &z);
    else
      kernel::fl_sampled_field_approach(s, approach, dt[i], w, u.x, u.y, u.z, &x, &y, &z);
    vx[i] = x, vy[i] = y, vz[i] = z;
  }
}

// The grid is the CPU's own copy (VectorField), sampled as the device samples its buffer.
inline void apply(const SampledField& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlActionParams& r = c.record();
  const cl::FlSampledFieldParams s = r.own.sampledField;
  const cl::FlFalloffParams f = r.falloff;
  const VectorField& field = *a.field;
  if (field.data.size() * 3 < (std::size_t(1) << 31)) {  // offsets in int: gathered in vectors
    const float* grid = reinterpret_cast<const float*>(field.data.data());
    const int nx = field.dims.x, ny = field.dims.y, nz = field.dims.z;
    const Vec3 o = field.origin;
    const float vs = field.voxelSize;
    // The mode too as a constant of the loop (as withFalloff the falloff's), and the grid's
    // lookups in a loop of its own over restricted arrays: GCC left the loop scalar with the
    // mode's branch inside it, and with the grid reached through the lambda's captures.
    withFalloff(f, [&](auto fall) {
      withDt(c, [&](auto dt) {
        if (s.carry)
          sampledFieldLoop<1>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, grid, nx, ny,
                              nz, o, vs, s, fall());
        else
          sampledFieldLoop<0>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, grid, nx, ny,
                              nz, o, vs, s, fall());
      });
    });
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p = at(L.p, i);
    const Vec3 u = sampleTrilinear(field, p);
    onLocals(L.v, i, [&](float* x, float* y, float* z) {
      kernel::fl_sampled_field(s, c.dtAt(i), kernel::fl_falloff_weight(f, p.x, p.y, p.z), u.x, u.y,
                               u.z, x, y, z);
    });
  }
}

// A closed obstacle threatens a particle outside it whose look-ahead point lies inside: that
// test (the same containment as Domain::contains) runs over a chunk of particles in vectors,
// and only the few it finds take the push, one by one. A planar obstacle tests each particle's
// crossing one by one.
inline void apply(const Avoid& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlAvoidParams avoid = c.record().own.avoid;
  const bool planar = a.obstacle.isPlanar();
  auto push = [&](std::size_t i) {
    const Vec3 p = at(L.p, i);
    const float dist = a.obstacle.distance(p);
    Vec3 away = a.obstacle.normal(p);
    if (planar && glm::dot(p - a.obstacle.closestPoint(p), away) < 0.0f) away = -away;
    onLocals(L.v, i, [&](float* x, float* y, float* z) {
      kernel::fl_add_scaled(away.x, away.y, away.z, kernel::fl_avoid_step(avoid, dist, c.dtAt(i)),
                            x, y, z);
    });
  };
  if (planar) {  // the look-ahead path crosses the piece
    planarCrossings(a.obstacle, L, n, UniformDt{avoid.lookAhead},
                    [&](std::size_t first, std::size_t m, const float* gap, CrossingPoints) {
                      for (std::size_t k = 0; k < m; ++k)
                        if (gap[k] < kInfinity &&  // (most do not cross: no length taken)
                            gap[k] < 1e-4f * (1.0f + glm::length(at(L.p, first + k)))) [[unlikely]]
                          push(first + k);
                    });
    return;
  }
  std::visit(
      [&](const auto& shape) {
        constexpr std::size_t kChunk = 256;
        alignas(64) std::uint8_t threat[kChunk];
        const float look = avoid.lookAhead;
        for (std::size_t first = 0; first < n; first += kChunk) {
          const std::size_t m = std::min(kChunk, n - first);
          threatLoop(shape, L.p[0] + first, L.p[1] + first, L.p[2] + first, L.v[0] + first,
                     L.v[1] + first, L.v[2] + first, threat, m, look);
          for (std::size_t i = 0; i < m; ++i)
            if (threat[i]) [[unlikely]]
              push(first + i);
        }
      },
      a.obstacle.shape());
}

// Follow's pull: out[i] += pull towards its leader (the next particle) at (lx, ly, lz)[i],
// times dt[i] (its own loop: out is the velocity; an integrator's stage: the acceleration's
// sums, with dt 1, whose product is the pull itself).
template <class Dt>
inline void followLoop(const float* __restrict lx, const float* __restrict ly,
                       const float* __restrict lz, const float* __restrict px,
                       const float* __restrict py, const float* __restrict pz, float* __restrict ox,
                       float* __restrict oy, float* __restrict oz, std::size_t n, Dt dt,
                       const cl::FlPullParams q) {
  for (std::size_t i = 0; i < n; ++i) {
    float x, y, z;
    kernel::fl_pull(q, lx[i] - px[i], ly[i] - py[i], lz[i] - pz[i], &x, &y, &z);
    ox[i] = ox[i] + x * dt[i];
    oy[i] = oy[i] + y * dt[i];
    oz[i] = oz[i] + z * dt[i];
  }
}
// followLoop for the particles of a block at `base` that have a leader as the step began (the
// last of the group leads); returns their count.
template <class Dt>
inline std::size_t followPulls(const Snapshot& s, std::size_t base, const float* const* pos,
                               float* const* out, std::size_t n, Dt dt, const cl::FlPullParams& q) {
  const std::size_t led = s.size > base + 1 ? std::min(n, s.size - base - 1) : 0;
  followLoop(s.p[0] + base + 1, s.p[1] + base + 1, s.p[2] + base + 1, pos[0], pos[1], pos[2],
             out[0], out[1], out[2], led, dt, q);
  return led;
}

inline void apply(const Follow&, const Lanes& L, std::size_t n, const BlockContext& c) {
  withDt(c,
         [&](auto dt) { followPulls(*c.snapshot, c.base, L.p, L.v, n, dt, c.record().own.pull); });
}

// Towards the mean of the neighbours' values within maxRadius, at `magnitude` per second
// (kernels/forces.h, shared with the device).
inline void matchMean(const Snapshot& s, const float* const* self, const float* const* field,
                      float* const* out, std::size_t n, const BlockContext& c) {
  const cl::FlMatchParams m = c.record().own.match;
  const float kStep = kernel::fl_match_k(m, c.dt);
  for (std::size_t i0 = 0; i0 < n; i0 += kMatchLanes) {
    const ScanLanes at0(self, c.base, i0, n);
    const std::size_t lanes = at0.lanes;
    alignas(64) float sumx[kMatchLanes], sumy[kMatchLanes], sumz[kMatchLanes];
    alignas(64) std::int32_t count[kMatchLanes];
    matchScan(s.p[0], s.p[1], s.p[2], field[0], field[1], field[2], s.size, at0.p[0], at0.p[1],
              at0.p[2], at0.own, m.maxRadius2, sumx, sumy, sumz, count);
    for (std::size_t l = 0; l < lanes; ++l) {
      const std::size_t i = i0 + l;
      const float k = c.ownDt ? kernel::fl_match_k(m, c.ownDt[i]) : kStep;
      kernel::fl_match_finish(sumx[l], sumy[l], sumz[l], count[l], k, &out[0][i], &out[1][i],
                              &out[2][i]);
    }
  }
}
inline void apply(const MatchVelocity&, const Lanes& L, std::size_t n, const BlockContext& c) {
  matchMean(*c.snapshot, L.p, c.snapshot->v, L.v, n, c);
}
inline void apply(const MatchRotVelocity&, const Lanes& L, std::size_t n, const BlockContext& c) {
  matchMean(*c.snapshot, L.p, c.snapshot->rot, L.rot, n, c);
}

// ---- Targets, clamps, curves -------------------------------------------------------------

inline void approachLoop(float* __restrict x, std::size_t n, float target, float k) {
  for (std::size_t i = 0; i < n; ++i) x[i] = kernel::fl_toward(x[i], target, k);
}
// Each lane towards the record's target: one factor for the block's step (fl_target_k), or
// one per newborn for its own, taken once for all its lanes (an exp each: a colour's four
// lanes took four).
inline void approachLanes(float* const* lane, int count, std::size_t n, const BlockContext& c) {
  const cl::FlTargetParams t = c.record().own.target;
  if (c.ownDt) {
    for (std::size_t i = 0; i < n; ++i) {
      const float k = kernel::fl_target_k(t, c.ownDt[i]);
      for (int d = 0; d < count; ++d) lane[d][i] = kernel::fl_toward(lane[d][i], t.target[d], k);
    }
    return;
  }
  const float k = kernel::fl_target_k(t, c.dt);
  for (int d = 0; d < count; ++d) approachLoop(lane[d], n, t.target[d], k);
}
inline void apply(const TargetVelocity&, const Lanes& L, std::size_t n, const BlockContext& c) {
  approachLanes(L.v, 3, n, c);
}
inline void apply(const TargetRotVelocity&, const Lanes& L, std::size_t n, const BlockContext& c) {
  approachLanes(L.rot, 3, n, c);
}
inline void apply(const TargetColor&, const Lanes& L, std::size_t n, const BlockContext& c) {
  approachLanes(L.color, 4, n, c);
}
inline void apply(const TargetSize&, const Lanes& L, std::size_t n, const BlockContext& c) {
  approachLanes(&L.size, 1, n, c);
}

inline void apply(const SpeedClamp&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlSpeedClampParams clamp = c.record().own.speedClamp;
  float* __restrict vx = L.v[0];
  float* __restrict vy = L.v[1];
  float* __restrict vz = L.v[2];
  for (std::size_t i = 0; i < n; ++i) {
    float x = vx[i], y = vy[i], z = vz[i];
    kernel::fl_speed_clamp(clamp, &x, &y, &z);
    vx[i] = x, vy[i] = y, vz[i] = z;
  }
}

// The keys as the shared lookup reads them: t, then the values, packed.
static_assert(sizeof(ColorOverLife::Key) == 5 * sizeof(float) &&
              offsetof(ColorOverLife::Key, color) == sizeof(float));
static_assert(sizeof(SizeOverLife::Key) == 2 * sizeof(float) &&
              offsetof(SizeOverLife::Key, size) == sizeof(float));
template <class Key>
inline const float* keyFloats(const std::vector<Key>& keys) {
  return reinterpret_cast<const float*>(keys.data());
}

// Curves of up to this many keys are evaluated a segment at a time over a chunk of particles
// (curveLanes); longer ones search their keys per particle (curveSearched). At 16 keys the
// segments were 1.5x faster on AVX-512 and as fast on AVX2 (bench_fountain
// OverLifeCurves/keys:16, this constant at 16 against a build of it at 8).
constexpr std::uint32_t kMostSegmentedKeys = 16;

// A curve of `count` keys (its t, then C values) at each of n particles' life fractions,
// into out[0..C): fl_curve_lookup's values bit for bit, in loops the vectoriser takes. Its walk
// over the keys per particle is a branch per key; here each particle's segment is found by one
// compare per key, and each segment's values are then taken for all and kept where they
// belong (a select). Curves have a few keys: that is a few passes over a chunk in cache.
template <int C>
inline void curveLanes(const float* keys, std::uint32_t count, const float* __restrict age,
                       const float* __restrict life, std::size_t n, float* const* out) {
  constexpr std::uint32_t stride = C + 1;
  constexpr std::size_t kChunk = 256;
  alignas(64) float t[kChunk];
  alignas(64) std::uint32_t seg[kChunk];  // fl_curve_lookup's hi: 0 before, count past the last
  const float first = keys[0];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    for (std::size_t i = 0; i < m; ++i) t[i] = kernel::fl_life_fraction(age[c0 + i], life[c0 + i]);
    for (std::size_t i = 0; i < m; ++i) seg[i] = t[i] <= first ? 0u : count;
    for (std::uint32_t k = count - 1; k >= 1; --k) {  // downwards: the first key at or past t
      const float tk = keys[k * stride];
      for (std::size_t i = 0; i < m; ++i) seg[i] = seg[i] != 0u && t[i] <= tk ? k : seg[i];
    }
    for (int c = 0; c < C; ++c) {
      float* __restrict o = out[c] + c0;
      const float before = keys[1 + c], after = keys[(count - 1) * stride + 1 + c];
      for (std::size_t i = 0; i < m; ++i) o[i] = seg[i] == 0u ? before : after;
    }
    for (std::uint32_t k = 1; k < count; ++k) {
      const float* k0 = keys + (k - 1) * stride;
      const float* k1 = keys + k * stride;
      float v0[C], d[C];
      for (int c = 0; c < C; ++c) v0[c] = k0[1 + c], d[c] = k1[1 + c] - k0[1 + c];
      const float t0 = k0[0], t1 = k1[0];
      for (int c = 0; c < C; ++c) {
        float* __restrict o = out[c] + c0;
        for (std::size_t i = 0; i < m; ++i) {
          const float v = v0[c] + d[c] * kernel::fl_key_weight(t0, t1, t[i]);
          o[i] = seg[i] == k ? v : o[i];
        }
      }
    }
  }
}

// The same for a curve of more keys (count >= 2): each particle's segment found by a search
// of fixed steps (log2 of the keys, the same for every particle: a vector loop, its keys
// gathered), for fl_curve_lookup's walk's segment: the first key at or past t (where no key
// is, t NaN among them, past the last).
template <int C>
inline void curveSearched(const float* __restrict keys, std::uint32_t count,
                          const float* __restrict age, const float* __restrict life, std::size_t n,
                          float* const* out) {
  constexpr std::uint32_t stride = C + 1;
  constexpr std::size_t kChunk = 256;
  alignas(64) float t[kChunk];
  alignas(64) std::uint32_t seg[kChunk];
  const float first = keys[0];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    for (std::size_t i = 0; i < m; ++i) t[i] = kernel::fl_life_fraction(age[c0 + i], life[c0 + i]);
    // Keys [1, count): the window [seg, seg + w] holds the first k with t <= keys[k] (count
    // where none is), halved each step (as std::partition_point, by a select).
    for (std::size_t i = 0; i < m; ++i) seg[i] = 1u;
    std::uint32_t w = count - 1;
    for (; w > 1; w -= w / 2) {
      const std::uint32_t half = w / 2;
      for (std::size_t i = 0; i < m; ++i)
        seg[i] = !(t[i] <= keys[(seg[i] + half) * stride]) ? seg[i] + half : seg[i];
    }
    for (std::size_t i = 0; i < m; ++i)
      seg[i] = t[i] <= first ? 0u : seg[i] + std::uint32_t(!(t[i] <= keys[seg[i] * stride]));
    for (int c = 0; c < C; ++c) {
      float* __restrict o = out[c] + c0;
      const float before = keys[1 + c], after = keys[(count - 1) * stride + 1 + c];
      for (std::size_t i = 0; i < m; ++i) {
        // Between keys hi - 1 and hi (clamped for those before or past, then not kept).
        const std::uint32_t hi = std::min(std::max(seg[i], 1u), count - 1);
        const float* k0 = keys + (hi - 1) * stride;
        const float* k1 = keys + hi * stride;
        const float wt = kernel::fl_key_weight(k0[0], k1[0], t[i]);
        const float v = k0[1 + c] + (k1[1 + c] - k0[1 + c]) * wt;
        o[i] = seg[i] == 0u ? before : seg[i] == count ? after : v;
      }
    }
  }
}

// Multiply scales the birth value (stored by emission), Replace sets the curve's value.
inline void apply(const ColorOverLife& a, const Lanes& L, std::size_t n, const BlockContext&) {
  const auto count = kernel::uint(a.keys.size());
  if (count <= kMostSegmentedKeys)
    curveLanes<4>(keyFloats(a.keys), count, L.age, L.lifetime, n, L.color);
  else
    curveSearched<4>(keyFloats(a.keys), count, L.age, L.lifetime, n, L.color);
  if (a.mode == OverLifeMode::Multiply)
    for (int d = 0; d < 4; ++d) {
      float* __restrict col = L.color[d];
      const float* __restrict birth = L.birthColor[d];
      for (std::size_t i = 0; i < n; ++i) col[i] = birth[i] * col[i];
    }
}
inline void apply(const SizeOverLife& a, const Lanes& L, std::size_t n, const BlockContext&) {
  const auto count = kernel::uint(a.keys.size());
  float* const out[1] = {L.size};
  if (count <= kMostSegmentedKeys)
    curveLanes<1>(keyFloats(a.keys), count, L.age, L.lifetime, n, out);
  else
    curveSearched<1>(keyFloats(a.keys), count, L.age, L.lifetime, n, out);
  if (a.mode == OverLifeMode::Multiply) {
    float* __restrict size = L.size;
    const float* __restrict birth = L.birthSize;
    for (std::size_t i = 0; i < n; ++i) size[i] = birth[i] * size[i];
  }
}

// ---- Bookkeeping -------------------------------------------------------------------------

// f(&x, &y, &z, &u, &v, &w, i) on locals holding particle i's position and velocity, stored
// back: a loop over restricted arguments, which GCC 12 vectorises (over restricted locals
// loaded from a struct it did not).
template <class F>
[[gnu::flatten]] inline void positionVelocityLoop(float* __restrict px, float* __restrict py,
                                                  float* __restrict pz, float* __restrict vx,
                                                  float* __restrict vy, float* __restrict vz,
                                                  std::size_t n, F f) {
  for (std::size_t i = 0; i < n; ++i) {
    float x = px[i], y = py[i], z = pz[i], u = vx[i], v = vy[i], w = vz[i];
    f(&x, &y, &z, &u, &v, &w, i);
    px[i] = x, py[i] = y, pz[i] = z, vx[i] = u, vy[i] = v, vz[i] = w;
  }
}

inline void apply(const Constrain2D&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlConstrain2DParams plane = c.record().own.constrain2d;
  positionVelocityLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n,
                       [plane](float* x, float* y, float* z, float* u, float* v, float* w,
                               std::size_t) { kernel::fl_constrain2d(plane, x, y, z, u, v, w); });
}

inline void apply(const CopyVertexB& a, const Lanes& L, std::size_t n, const BlockContext&) {
  if (a.copyPosition) copyLoop(L.posB[0], L.posB[1], L.posB[2], L.p[0], L.p[1], L.p[2], n);
  if (a.copyVelocity) copyLoop(L.velB[0], L.velB[1], L.velB[2], L.v[0], L.v[1], L.v[2], n);
}

inline void apply(const Restore&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlRestoreParams r = c.record().own.restore;
  if (!kernel::fl_restore_started(kernel::fl_real_from_bits(r.start), c.time)) return;
  // fl_restore's step, its time left and the step's length the same for the block.
  const float left = kernel::fl_restore_left(kernel::fl_real_from_bits(r.end), c.time);
  const float dt = c.dt;
  const float* __restrict hx = L.posB[0];
  const float* __restrict hy = L.posB[1];
  const float* __restrict hz = L.posB[2];
  positionVelocityLoop(
      L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n,
      [=](float* x, float* y, float* z, float* u, float* v, float* w, std::size_t i) {
        kernel::fl_restore_step(left, dt, hx[i], hy[i], hz[i], x, y, z, u, v, w);
      });
}

inline void apply(const Callback& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const CallbackContext ctx{c.dt, c.time, c.step};
  for (std::size_t i = 0; i < n; ++i) {
    Particle q = readParticle(L, i);
    a.function(q, ctx);
    writeParticle(L, i, q);
  }
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail::cpu
