// The CPU backend's per-action loops. Each runs over one block of particles with its lanes
// passed as __restrict locals (GCC does not vectorise loops that reload array pointers from
// a struct), branch-free, so the compiler vectorises them. The fused pass runs every action
// of the list over a block while the block is in cache.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "../action_params.hpp"
#include "../forces_kernel.hpp"
#include "../group_impl.hpp"
#include "../isa_namespace.hpp"
#include "../kernel_compat.hpp"
#include "../noise.hpp"
#include "../shape_math.hpp"
#include "flurry/actions.hpp"
#include "flurry/random.hpp"

namespace flurry::detail {
inline namespace FLURRY_ISA_NAMESPACE {
namespace kernel {
#include "../../kernels/absorb.h"
#include "../../kernels/deflect.h"
#include "../../kernels/integrate.h"
}  // namespace kernel
}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail

namespace flurry::detail::cpu {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

/// Positions and velocities at the start of the step, for actions that read other particles.
struct Snapshot {
  const float* p[3] = {};
  const float* v[3] = {};
  const float* rot[3] = {};
  std::size_t size = 0;
};

/// Where a block's collisions go while the group records them (Group::recordCollisions):
/// the group, the block, the end of the step and the sub-step (an event's time is found
/// from them and the particle's own step length).
struct CollisionLog {
  GroupImpl* group = nullptr;
  std::size_t block = 0;
  double t1 = 0.0;
  std::uint32_t substeps = 1, sub = 0;
};

struct BlockContext {
  float dt;
  std::uint64_t seed;
  std::uint32_t step;
  std::uint32_t streamBase;  ///< keeps the random streams of different groups apart
  std::uint32_t action;      ///< index in the list: the random stream and the kill code
  std::uint32_t* dead;       ///< per particle of the block: 0 alive, else 1 + killing action
  double time = 0.0;         ///< at the start of the step
  std::size_t base = 0;      ///< index of the block's first particle in the group
  const Snapshot* snapshot = nullptr;
  std::uint32_t firstBlocker = ~0u;  ///< index of the list's first Block action
  /// Newborns: each particle's own step length (what is left of its birth step), indexed as
  /// `dead`; null when every particle of the block steps `dt`.
  const float* ownDt = nullptr;
  /// With ownDt: the newborns are the particles from this index on (those before it began
  /// the step and step the whole sub-step: a block run with its newborns in one pass).
  std::size_t newbornsFrom = 0;
  CollisionLog* collisions = nullptr;  ///< non-null while the group records collisions
  /// The list's records (actionRecords), made for the sub-step's length.
  const cl::FlActionParams* records = nullptr;
  /// Positions when the step began, indexed as `dead` (set where the list guards a curved
  /// step: the guard compares with them).
  const float* stepStart[3] = {};
  /// Particle i's step length.
  float dtAt(std::size_t i) const { return ownDt ? ownDt[i] : dt; }
  /// The running action's record.
  const cl::FlActionParams& record() const { return records[action]; }
};

// The loops take their arrays as __restrict parameters: GCC 12 vectorises these, but not
// the same loops over __restrict locals loaded from a struct.

/// The step length of a loop: the same for every particle (a block's sub-step), or each
/// particle's own (newborns, which live only what is left of their birth step).
struct UniformDt {
  float h;
  float operator[](std::size_t) const { return h; }
};
struct OwnDt {
  const float* h;
  float operator[](std::size_t i) const { return h[i]; }
};
/// A Dt seen from particle `first` on.
template <class Dt>
struct OffsetDt {
  Dt dt;
  std::size_t first;
  float operator[](std::size_t i) const { return dt[first + i]; }
};

/// Calls f with the block's step lengths: the sub-step for all, or each newborn's own. Loops
/// written over a Dt serve both, the newborns in one batch like everyone else.
template <class F>
inline void withDt(const BlockContext& c, F&& f) {
  if (c.ownDt)
    f(OwnDt{c.ownDt});
  else
    f(UniformDt{c.dt});
}

inline void addLoop(float* __restrict x, float* __restrict y, float* __restrict z, std::size_t n,
                    float ax, float ay, float az) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] += ax;
    y[i] += ay;
    z[i] += az;
  }
}

inline void scaleLoop(float* __restrict x, float* __restrict y, float* __restrict z, std::size_t n,
                      float fx, float fy, float fz) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] *= fx;
    y[i] *= fy;
    z[i] *= fz;
  }
}

inline void copyLoop(float* __restrict qx, float* __restrict qy, float* __restrict qz,
                     const float* __restrict px, const float* __restrict py,
                     const float* __restrict pz, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    qx[i] = px[i];
    qy[i] = py[i];
    qz[i] = pz[i];
  }
}

template <class Dt>
inline void moveLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                     const float* __restrict vx, const float* __restrict vy,
                     const float* __restrict vz, std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) {
    px[i] += vx[i] * dt[i];
    py[i] += vy[i] * dt[i];
    pz[i] += vz[i] * dt[i];
  }
}

template <class Dt>
inline void ageLoop(float* __restrict age, std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) age[i] += dt[i];
}

inline void killOldLoop(const float* __restrict age, const float* __restrict life,
                        std::uint32_t* __restrict dead, std::size_t n, std::uint32_t code) {
  for (std::size_t i = 0; i < n; ++i) dead[i] = kernel::fl_dead_old(age[i], life[i], code, dead[i]);
}

template <class Shape>
inline void sinkLoop(const Shape& shape, const float* __restrict px, const float* __restrict py,
                     const float* __restrict pz, std::uint32_t* __restrict dead, std::size_t n,
                     std::uint32_t code, bool killInside) {
  for (std::size_t i = 0; i < n; ++i) {
    const int in = detail::inside(shape, Vec3(px[i], py[i], pz[i]));
    dead[i] = kernel::fl_dead_sink(in, killInside, code, dead[i]);
  }
}

// A force's update of each particle's velocity from its position, f(px, py, pz, dt, &vx, &vy,
// &vz) (a shared kernel function with the force's record bound): through locals and
// __restrict parameters, so that a branch-free f vectorises; flattened, so that GCC's
// inlining budget, spent on the pass around it, leaves no kernel function a call in the loop.
template <class Dt, class F>
[[gnu::flatten]] inline void velocityLoop(const float* __restrict px, const float* __restrict py,
                                          const float* __restrict pz, float* __restrict vx,
                                          float* __restrict vy, float* __restrict vz, std::size_t n,
                                          Dt dt, F f) {
  for (std::size_t i = 0; i < n; ++i) {
    float x = vx[i], y = vy[i], z = vz[i];
    if constexpr (std::is_invocable_v<F, std::size_t, float, float, float, float, float*, float*,
                                      float*>)
      f(i, px[i], py[i], pz[i], dt[i], &x, &y, &z);  // (one that reads other lanes at i)
    else
      f(px[i], py[i], pz[i], dt[i], &x, &y, &z);
    vx[i] = x, vy[i] = y, vz[i] = z;
  }
}
template <class F>
inline void velocityLoop(const Lanes& L, std::size_t n, const BlockContext& c, F f) {
  withDt(c,
         [&](auto dt) { velocityLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, f); });
}

// Calls body(fall), fall() giving the falloff record f as a loop over particles reads it. Where
// its radius is infinite or its power 1 (the usual cases), those fields are constants there,
// so that fl_falloff_weight's choices fold and the loop takes no fl_powf (for an infinite
// radius, no distance) only to throw it away: the same weights. kFinite: the caller took an
// infinite radius apart (no loop made for it).
template <bool kFinite = false, class Body>
inline void withFalloff(const cl::FlFalloffParams& f, Body body) {
  if (!kFinite && !(f.radius < kInfinity)) {
    body([f] {
      cl::FlFalloffParams u = f;
      u.radius = kInfinity;
      return u;
    });
  } else if (f.power == 1.0f) {
    body([f] {
      cl::FlFalloffParams u = f;
      u.power = 1.0f;
      return u;
    });
  } else {
    body([f] { return f; });
  }
}

inline void apply(const Gravity&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlActionParams& r = c.record();
  const cl::FlGravityParams g = r.own.gravity;
  if (r.falloff.radius < kInfinity) {
    withFalloff<true>(r.falloff, [&](auto fall) {
      velocityLoop(L, n, c,
                   [g, fall](float px, float py, float pz, float dt, float* x, float* y, float* z) {
                     kernel::fl_gravity_falloff(g, fall(), dt, px, py, pz, x, y, z);
                   });
    });
    return;
  }
  if (!c.ownDt) {  // fl_gravity with a·dt made once for the block
    const cl::FlXyz a = g.acceleration;
    addLoop(L.v[0], L.v[1], L.v[2], n, a.x * c.dt, a.y * c.dt, a.z * c.dt);
    return;
  }
  velocityLoop(L, n, c, [g](float, float, float, float dt, float* x, float* y, float* z) {
    kernel::fl_gravity(g, dt, x, y, z);
  });
}

// Damping and RotDamping without a falloff: the record's factors for a block's step (one
// fl_damping_factors a block), each newborn's own for its rest of the step.
inline void dampLanes(const cl::FlDampingParams& d, float* const* lane, std::size_t n,
                      const BlockContext& c) {
  if (c.ownDt) {
    // fl_damping per newborn, in loops the vectoriser takes (its exp is float arithmetic;
    // the record's fields are read before the loops, which would otherwise keep a branch).
    const float* __restrict own = c.ownDt;
    if (d.rate.y == d.rate.x && d.rate.z == d.rate.x) {  // (fl_damping_factors' one exp)
      float* __restrict x = lane[0];
      float* __restrict y = lane[1];
      float* __restrict z = lane[2];
      const float rate = d.rate.x, madeDt = d.dt, made = d.decay.x;
      for (std::size_t i = 0; i < n; ++i) {
        const float f = kernel::fl_force_decay(rate, own[i], madeDt, made);
        x[i] *= f;
        y[i] *= f;
        z[i] *= f;
      }
      return;
    }
    const float rate[3] = {d.rate.x, d.rate.y, d.rate.z};
    const float made[3] = {d.decay.x, d.decay.y, d.decay.z};
    const float madeDt = d.dt;
    for (int k = 0; k < 3; ++k) {
      float* __restrict v = lane[k];
      const float r = rate[k], m = made[k];
      for (std::size_t i = 0; i < n; ++i) v[i] *= kernel::fl_force_decay(r, own[i], madeDt, m);
    }
    return;
  }
  float fx, fy, fz;
  kernel::fl_damping_factors(d, c.dt, &fx, &fy, &fz);
  scaleLoop(lane[0], lane[1], lane[2], n, fx, fy, fz);
}

inline void apply(const Damping&, const Lanes& L, std::size_t n, const BlockContext& c) {
  const cl::FlActionParams& r = c.record();
  const cl::FlDampingParams d = r.own.damping;
  if (r.falloff.radius < kInfinity) {
    withFalloff<true>(r.falloff, [&](auto fall) {
      velocityLoop(L, n, c,
                   [d, fall](float px, float py, float pz, float dt, float* x, float* y, float* z) {
                     kernel::fl_damping_falloff(d, fall(), dt, px, py, pz, x, y, z);
                   });
    });
    return;
  }
  dampLanes(d, L.v, n, c);
}

template <class Dt>
[[gnu::flatten]] inline void turnUpLoop(float* __restrict ux, float* __restrict uy,
                                        float* __restrict uz, const float* __restrict wx,
                                        const float* __restrict wy, const float* __restrict wz,
                                        std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) {
    float x = ux[i], y = uy[i], z = uz[i];
    kernel::fl_turn_up(dt[i], &x, &y, &z, wx[i], wy[i], wz[i]);
    ux[i] = x, uy[i] = y, uz[i] = z;
  }
}

inline void apply(const Move&, const Lanes& L, std::size_t n, const BlockContext& c) {
  if (L.prev[0]) copyLoop(L.prev[0], L.prev[1], L.prev[2], L.p[0], L.p[1], L.p[2], n);
  withDt(c, [&](auto dt) {
    moveLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt);
    if (L.age) ageLoop(L.age, n, dt);
  });
  if (L.up[0] && L.rot[0])  // the up vector turns with the angular velocity (fl_turn_up)
    withDt(c, [&](auto dt) {
      turnUpLoop(L.up[0], L.up[1], L.up[2], L.rot[0], L.rot[1], L.rot[2], n, dt);
    });
}

inline void apply(const KillOld&, const Lanes& L, std::size_t n, const BlockContext& c) {
  killOldLoop(L.age, L.lifetime, c.dead, n, c.action + 1);
}

/// Reflects the velocity and places the particle so that the following Move ends it at the
/// reflected point (kernels/deflect.h fl_reflect, shared with the device).
struct Reflect {
  float restitution, keep, cutoff2;
  // In: position p, velocity v, hit point h, unit normal nrm, time of impact tau.
  // Out: the new position and velocity.
  inline void operator()(float& px, float& py, float& pz, float& vx, float& vy, float& vz, float hx,
                         float hy, float hz, float nx, float ny, float nz, float tau) const {
    kernel::fl_reflect(kernel::FlReflect{restitution, keep, cutoff2}, &px, &py, &pz, &vx, &vy, &vz,
                       hx, hy, hz, nx, ny, nz, tau);
  }
};

/// The hit and the reflection of a two-sided planar deflector, over particles [0, n) all of
/// which may reach the plane: computed for every one and kept only on a hit (kernels/deflect.h,
/// shared with the device; through locals, which keep the arrays' __restrict visible).
template <class Dt, class OnPiece>
inline void bouncePlanarAll(float* __restrict px, float* __restrict py, float* __restrict pz,
                            float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                            std::size_t n, Dt dts, Vec3 P, Vec3 N, OnPiece onPiece,
                            const Reflect& reflect) {
  const kernel::FlReflect rf{reflect.restitution, reflect.keep, reflect.cutoff2};
  for (std::size_t i = 0; i < n; ++i) {
    const float dt = dts[i];
    float x = px[i], y = py[i], z = pz[i], vx = vxs[i], vy = vys[i], vz = vzs[i];
    float side, tau, hx, hy, hz;
    const int reaches = kernel::fl_planar_hit(x, y, z, vx, vy, vz, dt, P.x, P.y, P.z, N.x, N.y, N.z,
                                              &side, &tau, &hx, &hy, &hz);
    const int hit = reaches & int(onPiece(hx, hy, hz));
    kernel::fl_planar_bounce(rf, hit, side, tau, hx, hy, hz, dt, P.x, P.y, P.z, N.x, N.y, N.z, &x,
                             &y, &z, &vx, &vy, &vz);
    px[i] = x, py[i] = y, pz[i] = z, vxs[i] = vx, vys[i] = vy, vzs[i] = vz;
  }
}

/// kernel::fl_planar_reaches for a normal along one axis (the other two components zero), from
/// that axis' position q and velocity w. Without FMA contraction the zero terms add exactly
/// nothing, so for finite particles the answer is the general test's bit for bit; where a
/// coordinate is not finite it may say yes where the general says no, which only adds a
/// candidate: the hit itself is decided by the general fl_planar_hit.
inline int planarReachesAlong(float q, float w, float dt, float Pk, float Nk) {
  const float d0 = (q - Pk) * Nk;
  const float vn = w * Nk;
  const float d1 = d0 + vn * dt;
  const float side = d0 >= 0.0f ? 1.0f : -1.0f;
  const float reach =
      1.2e-7f * (std::abs(Nk) * (std::abs(q) + std::abs(Pk) + 2.0f * std::abs(w * dt))) + 1e-30f;
  return (side * d1 <= reach) & (side * vn < 0.0f);
}

/// For each byte b, the positions j of its set bits in ascending order, packed one per byte
/// of a little-endian word (bit j stands for flag j, as bouncePlanarLoop builds it).
struct SetBitPositions {
  std::uint64_t at[256];
  constexpr SetBitPositions() : at{} {
    for (unsigned b = 0; b < 256; ++b) {
      unsigned k = 0;
      for (unsigned j = 0; j < 8; ++j)
        if (b & (1u << j)) at[b] |= std::uint64_t(j) << (8 * k++);
    }
  }
};
inline constexpr SetBitPositions kSetBitPositions{};

/// A two-sided planar deflector (plane, rectangle, disc, triangle): `onPiece` says whether a
/// point of the plane belongs to the piece. Most particles do not reach the plane in a step,
/// and where some do (particles resting on a floor are spread through the group) they are
/// few among many: a vectorised test marks who may reach it, those are packed into a small
/// contiguous batch, the hit is computed over the batch (vectorised) and written back. Each
/// particle's arithmetic is the same wherever it runs, so the result does not depend on how
/// many were packed.
template <class Dt, class OnPiece>
inline void bouncePlanarLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                             float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                             std::size_t n, Dt dts, Vec3 P, Vec3 N, OnPiece onPiece,
                             const Bounce& b) {
  constexpr std::size_t kChunk = 256;
  constexpr std::size_t kPad = FLURRY_ISA_FLOATS;  // this build's widest vector
  const Reflect reflect{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  alignas(32) std::uint8_t reaches[kChunk];
  // A floor, a wall: a normal along an axis makes the test read two lanes, not six.
  const int axis = N.y == 0.0f && N.z == 0.0f   ? 0
                   : N.x == 0.0f && N.z == 0.0f ? 1
                   : N.x == 0.0f && N.y == 0.0f ? 2
                                                : -1;
  const float Pk = axis == 0 ? P.x : axis == 1 ? P.y : P.z;
  const float Nk = axis == 0 ? N.x : axis == 1 ? N.y : N.z;
  alignas(64) float g[7][kChunk];  // the packed candidates: x, y, z, vx, vy, vz, dt
  std::uint8_t idx[kChunk + 8];    // (eight are stored at once; padding stays below m/4 + 16)
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    float *x = px + c0, *y = py + c0, *z = pz + c0, *vx = vxs + c0, *vy = vys + c0, *vz = vzs + c0;
    if (axis < 0) {
      for (std::size_t i = 0; i < m; ++i)
        reaches[i] = std::uint8_t(kernel::fl_planar_reaches(
            x[i], y[i], z[i], vx[i], vy[i], vz[i], dts[c0 + i], P.x, P.y, P.z, N.x, N.y, N.z));
    } else {
      const float* __restrict q = (axis == 0 ? px : axis == 1 ? py : pz) + c0;
      const float* __restrict w = (axis == 0 ? vxs : axis == 1 ? vys : vzs) + c0;
      for (std::size_t i = 0; i < m; ++i)
        reaches[i] = std::uint8_t(planarReachesAlong(q[i], w[i], dts[c0 + i], Pk, Nk));
    }
    // The candidates' indices, eight flags at a time and without branches: the eight flags
    // make a byte, whose set bits' positions come from a table, stored eight at once (a
    // branch per candidate mispredicted about once a word where a floor holds many).
    std::size_t k = 0, i = 0;
    for (; i + 8 <= m; i += 8) {
      std::uint64_t w;
      std::memcpy(&w, reaches + i, 8);
      const unsigned bits = unsigned((w * 0x0102040810204080ull) >> 56);  // flag j -> bit j
      const std::uint64_t at = kSetBitPositions.at[bits] + i * 0x0101010101010101ull;
      std::memcpy(idx + k, &at, 8);
      k += std::size_t(std::popcount(bits));
    }
    for (; i < m; ++i) {
      idx[k] = std::uint8_t(i);
      k += reaches[i];
    }
    if (k == 0) continue;
    if (4 * k >= m) {  // many: packing would cost more than computing all of them
      bouncePlanarAll(x, y, z, vx, vy, vz, m, OffsetDt<Dt>{dts, c0}, P, N, onPiece, reflect);
      continue;
    }
    // Padded with copies of the first candidate to whole vectors: the batch runs in the
    // vector loop alone, with no scalar remainder (the copies are computed, never stored).
    const std::size_t padded = (k + kPad - 1) / kPad * kPad;
    for (std::size_t j = k; j < padded; ++j) idx[j] = idx[0];
    for (std::size_t j = 0; j < padded; ++j) {
      const std::size_t s = idx[j];
      g[0][j] = x[s], g[1][j] = y[s], g[2][j] = z[s];
      g[3][j] = vx[s], g[4][j] = vy[s], g[5][j] = vz[s];
      g[6][j] = dts[c0 + s];
    }
    bouncePlanarAll(g[0], g[1], g[2], g[3], g[4], g[5], padded, OwnDt{g[6]}, P, N, onPiece,
                    reflect);
    for (std::size_t j = 0; j < k; ++j) {
      const std::size_t s = idx[j];
      x[s] = g[0][j], y[s] = g[1][j], z[s] = g[2][j];
      vx[s] = g[3][j], vy[s] = g[4][j], vz[s] = g[5][j];
    }
  }
}

/// The same deflector when the following Move integrates each particle with an acceleration
/// a (per particle: ax, ay, az) taken as constant over the step: the impact found on the
/// parabola and the velocity there reflected (kernels/deflect.h, shared with the device).
template <class OnPiece, class Dt>
inline void bouncePlanarAccelLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                                  float* __restrict vxs, float* __restrict vys,
                                  float* __restrict vzs, const float* __restrict axs,
                                  const float* __restrict ays, const float* __restrict azs,
                                  std::size_t n, Dt dts, Vec3 P, Vec3 N, OnPiece onPiece,
                                  const Bounce& b) {
  const kernel::FlReflect rf{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  // The test, branch-free, as a vectorised loop over a chunk; then the bounce of the hits only
  // (the test again for each, for its impact: the same function, the same values).
  constexpr std::size_t kChunk = 256;
  std::uint8_t hits[kChunk];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    float *x = px + c0, *y = py + c0, *z = pz + c0, *vx = vxs + c0, *vy = vys + c0, *vz = vzs + c0;
    const float *ax = axs + c0, *ay = ays + c0, *az = azs + c0;
    std::size_t any = 0;
    for (std::size_t i = 0; i < m; ++i) {
      float side, tau, hx, hy, hz;
      const int hit = kernel::fl_planar_accel_hit(x[i], y[i], z[i], vx[i], vy[i], vz[i], ax[i],
                                                  ay[i], az[i], dts[c0 + i], P.x, P.y, P.z, N.x,
                                                  N.y, N.z, &side, &tau, &hx, &hy, &hz) &
                      int(onPiece(hx, hy, hz));
      hits[i] = std::uint8_t(hit);
      any += std::size_t(hit);
    }
    if (any == 0) continue;
    for (std::size_t i = 0; i < m; ++i) {
      if (!hits[i]) continue;
      const float dt = dts[c0 + i];
      float side, tau, hx, hy, hz;
      kernel::fl_planar_accel_hit(x[i], y[i], z[i], vx[i], vy[i], vz[i], ax[i], ay[i], az[i], dt,
                                  P.x, P.y, P.z, N.x, N.y, N.z, &side, &tau, &hx, &hy, &hz);
      kernel::fl_planar_accel_bounce(rf, side, tau, hx, hy, hz, dt, ax[i], ay[i], az[i], P.x, P.y,
                                     P.z, N.x, N.y, N.z, &x[i], &y[i], &z[i], &vx[i], &vy[i],
                                     &vz[i]);
    }
  }
}

/// acts(x, y, z, vx, vy, vz, dt) for particles [0, n) in vectors, a chunk at a time, then
/// f(i) for each it holds for, in order: a deflector that acts on few of them in a step.
template <class Dt, class Acts>
[[gnu::flatten]] inline void actingLoop(const float* __restrict px, const float* __restrict py,
                                        const float* __restrict pz, const float* __restrict vx,
                                        const float* __restrict vy, const float* __restrict vz,
                                        std::size_t n, Dt dt, Acts acts,
                                        std::uint8_t* __restrict out) {
  for (std::size_t i = 0; i < n; ++i)
    out[i] = std::uint8_t(acts(px[i], py[i], pz[i], vx[i], vy[i], vz[i], dt[i]) != 0);
}
template <class Dt, class Acts, class F>
inline void withActing(const float* px, const float* py, const float* pz, const float* vx,
                       const float* vy, const float* vz, std::size_t n, Dt dt, Acts acts, F f) {
  constexpr std::size_t kChunk = 256;
  alignas(64) std::uint8_t out[kChunk];
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    actingLoop(px + c0, py + c0, pz + c0, vx + c0, vy + c0, vz + c0, m, OffsetDt<Dt>{dt, c0}, acts,
               out);
    for (std::size_t i = 0; i < m; ++i)
      if (out[i]) [[unlikely]]
        f(c0 + i);
  }
}

/// A sphere deflecting from outside (Inside = false) or keeping particles in (Inside = true):
/// kernels/deflect.h, shared with the device.
template <bool Inside, class Dt>
inline void bounceSphereLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                             float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                             std::size_t n, Dt dts, const Bounce& b) {
  const kernel::FlReflect rf{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  const cl::FlBounceParams bp = bounceParams(b);
  const Vec3 C(bp.point.x, bp.point.y, bp.point.z);
  const float R = bp.piece.sphere.radius, R2 = bp.piece.sphere.radius2;
  const float invR = bp.piece.sphere.invRadius, scaleC = bp.piece.sphere.reach;
  // Through locals: the kernel's pointers would hide the arrays' __restrict from the
  // vectoriser.
  for (std::size_t i = 0; i < n; ++i) {
    float x = px[i], y = py[i], z = pz[i], vx = vxs[i], vy = vys[i], vz = vzs[i];
    kernel::fl_bounce_sphere_once(rf, C.x, C.y, C.z, R, R2, invR, scaleC, Inside, dts[i], &x, &y,
                                  &z, &vx, &vy, &vz);
    px[i] = x, py[i] = y, pz[i] = z, vxs[i] = vx, vys[i] = vy, vzs[i] = vz;
  }
  if constexpr (Inside) {
    // The bounces after the first: the few it acts on (fl_bounce_sphere_again_acts), marked in
    // vectors a chunk at a time.
    withActing(
        px, py, pz, vxs, vys, vzs, n, dts,
        [=](float x, float y, float z, float vx, float vy, float vz, float dt) {
          return kernel::fl_bounce_sphere_again_acts(C.x, C.y, C.z, R, dt, x, y, z, vx, vy, vz);
        },
        [&](std::size_t i) {
          float x = px[i], y = py[i], z = pz[i], vx = vxs[i], vy = vys[i], vz = vzs[i];
          kernel::fl_bounce_sphere_again(rf, C.x, C.y, C.z, R, R2, dts[i], &x, &y, &z, &vx, &vy,
                                         &vz);
          px[i] = x, py[i] = y, pz[i] = z, vxs[i] = vx, vys[i] = vy, vzs[i] = vz;
        });
  }
}

/// A box keeping particles in, or deflecting them from outside: kernels/deflect.h.
template <bool Inside, class Dt>
inline void bounceBoxLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                          float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                          std::size_t n, Dt dts, const BoxDomain& box, const Bounce& b) {
  const kernel::FlReflect rf{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  const float lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
  auto bounce = [&](std::size_t i) {
    float x = px[i], y = py[i], z = pz[i], vx = vxs[i], vy = vys[i], vz = vzs[i];
    if constexpr (Inside)
      kernel::fl_bounce_box_inside(rf, lo, hi, dts[i], &x, &y, &z, &vx, &vy, &vz);
    else
      kernel::fl_bounce_box_outside(rf, lo, hi, dts[i], &x, &y, &z, &vx, &vy, &vz);
    px[i] = x, py[i] = y, pz[i] = z, vxs[i] = vx, vys[i] = vy, vzs[i] = vz;
  };
  if constexpr (Inside) {
    // Most stay in for the step: those whose end leaves the box (fl_bounce_box_inside_acts),
    // marked in vectors a chunk at a time, take the kernel.
    const float l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
    withActing(
        px, py, pz, vxs, vys, vzs, n, dts,
        [=](float x, float y, float z, float vx, float vy, float vz, float dt) {
          const float l[3] = {l0, l1, l2}, h[3] = {h0, h1, h2};
          return kernel::fl_bounce_box_inside_acts(l, h, dt, x, y, z, vx, vy, vz);
        },
        bounce);
  } else {
    // Outside: fl_bounce_box_outside leaves a particle already in (its own first test) and one
    // whose step's segment misses the box; a segment whose two ends lie past one face, by far
    // more than the rounding of the kernel's slab test (1e-4 of the magnitudes; its entry
    // time is then past the step), misses it. The rest are marked in vectors and take it
    // (NaN, infinities: marked).
    const float l0 = lo[0], l1 = lo[1], l2 = lo[2], h0 = hi[0], h1 = hi[1], h2 = hi[2];
    withActing(
        px, py, pz, vxs, vys, vzs, n, dts,
        [=](float x, float y, float z, float vx, float vy, float vz, float dt) {
          const int in = (x >= l0) & (x <= h0) & (y >= l1) & (y <= h1) & (z >= l2) & (z <= h2);
          auto apart = [](float a, float q, float l, float h) {
            const float m =
                1e-4f * (std::abs(l) + std::abs(h) + std::abs(a) + std::abs(q)) + 1e-30f;
            return ((a > h + m) & (q > h + m)) | ((a < l - m) & (q < l - m));
          };
          const int misses = apart(x, x + vx * dt, l0, h0) | apart(y, y + vy * dt, l1, h1) |
                             apart(z, z + vz * dt, l2, h2);
          return !in & !misses;
        },
        bounce);
  }
}

// Calls f(P, N, onPiece) for a planar Bounce surface (plane, rectangle, triangle, disc, and
// the 2-D segment, a wall standing on the group's plane); false for the others. The plane and
// the piece are the record the device reads too (bounceParams).
template <class F>
inline bool withPlanarPiece(const Bounce& a, F&& f) {
  const int piece = planarPiece(a);
  if (piece < 0) return false;
  const cl::FlBounceParams b = bounceParams(a);
  const Vec3 P(b.point.x, b.point.y, b.point.z), N(b.normal.x, b.normal.y, b.normal.z);
  auto on = [&]<int Piece>() {
    f(P, N, [b](float x, float y, float z) { return kernel::fl_on_piece(&b, Piece, x, y, z); });
  };
  switch (piece) {
    case FL_PIECE_PLANE:
      on.template operator()<FL_PIECE_PLANE>();
      break;
    case FL_PIECE_RECTANGLE:
      on.template operator()<FL_PIECE_RECTANGLE>();
      break;
    case FL_PIECE_TRIANGLE:
      on.template operator()<FL_PIECE_TRIANGLE>();
      break;
    case FL_PIECE_DISC:
      on.template operator()<FL_PIECE_DISC>();
      break;
    default:
      on.template operator()<FL_PIECE_SEGMENT>();
      break;
  }
  return true;
}

inline void apply(const Bounce& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  withDt(c, [&](auto dt) {
    const bool planar = withPlanarPiece(a, [&](Vec3 P, Vec3 N, auto onPiece) {
      bouncePlanarLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, P, N, onPiece, a);
    });
    if (planar) return;
    const auto& shape = a.surface.shape();
    if (std::holds_alternative<SphereDomain>(shape)) {
      if (a.inside)
        bounceSphereLoop<true>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, a);
      else
        bounceSphereLoop<false>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, a);
    } else if (const auto* bx = std::get_if<BoxDomain>(&shape)) {
      if (a.inside)
        bounceBoxLoop<true>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, *bx, a);
      else
        bounceBoxLoop<false>(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, *bx, a);
    }
  });
}

/// A Bounce before a Move whose integrator moves each particle with the acceleration `acc`
/// (three arrays, per particle) over the step: planar pieces bounce on that parabola.
/// Spheres and boxes still bounce on the straight path (first order at the impact), and the
/// guard after the Move keeps them on their side.
inline void applyAccelerated(const Bounce& a, const Lanes& L, std::size_t n, const BlockContext& c,
                             const float* const* acc) {
  const bool planar = withPlanarPiece(a, [&](Vec3 P, Vec3 N, auto onPiece) {
    withDt(c, [&](auto dt) {
      bouncePlanarAccelLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], acc[0], acc[1], acc[2],
                            n, dt, P, N, onPiece, a);
    });
  });
  if (!planar) apply(a, L, n, c);
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail::cpu
