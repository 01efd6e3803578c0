// Collision events (Group::recordCollisions): a Bounce's deflections, found by comparing each
// particle's velocity before and after the action, and described from the state before it,
// on the path the bounce itself took (the parabola of kernels/deflect.h for a planar piece
// bounced with the acceleration, the straight line otherwise). Only while a group records:
// the pass otherwise never reaches this code.
#pragma once

#include <cmath>
#include <cstring>

#include "kernels.hpp"

namespace flurry::detail::cpu {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

/// A block's positions and velocities before a Bounce: six arrays of n in `keep`.
inline void keepState(const Lanes& L, std::size_t n, float* keep) {
  for (int c = 0; c < 3; ++c) {
    std::memcpy(keep + c * n, L.p[c], n * sizeof(float));
    std::memcpy(keep + (3 + c) * n, L.v[c], n * sizeof(float));
  }
}

/// flag[j] = 1 where particle j lives and its velocity (u) differs from what it was (v): a
/// loop over __restrict parameters, which GCC vectorises (over a lambda's captures it does
/// not).
inline void deflectedFlags(const float* __restrict ux, const float* __restrict uy,
                           const float* __restrict uz, const float* __restrict vx,
                           const float* __restrict vy, const float* __restrict vz,
                           const std::uint32_t* __restrict dead, std::size_t m,
                           std::uint8_t* __restrict flag) {
  for (std::size_t j = 0; j < m; ++j)
    flag[j] =
        std::uint8_t((dead[j] == 0) & ((ux[j] != vx[j]) | (uy[j] != vy[j]) | (uz[j] != vz[j])));
}

/// After Bounce `b` (action `action`) ran over the block's n particles whose state before is
/// in `keep` (keepState): an event for each live particle whose velocity it changed. `acc`:
/// the acceleration it bounced planar pieces with (three arrays), or null.
inline void logCollisions(const Bounce& b, std::uint32_t action, const Lanes& L, std::size_t n,
                          const BlockContext& c, const float* keep, const float* const* acc) {
  CollisionLog& log = *c.collisions;
  const float *px = keep, *py = keep + n, *pz = keep + 2 * n;
  const float *vx = keep + 3 * n, *vy = keep + 4 * n, *vz = keep + 5 * n;
  // Who was deflected, flags first (a loop that vectorises; most were not), then only those.
  // A particle killed earlier in the list is not deflected, whatever the bounce did to it.
  constexpr std::size_t kChunk = 256;
  alignas(32) std::uint8_t hit[kChunk];
  auto each = [&](auto&& event) {
    for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
      const std::size_t m = std::min(kChunk, n - c0);
      deflectedFlags(L.v[0] + c0, L.v[1] + c0, L.v[2] + c0, vx + c0, vy + c0, vz + c0, c.dead + c0,
                     m, hit);
      for (std::size_t j = 0; j < m; ++j)
        if (hit[j]) event(c0 + j);
    }
  };
  auto finish = [&](CollisionEvent& e, std::size_t i, float dt, float tau, Vec3 v, Vec3 a) {
    e.velocity = v + a * tau;
    e.id = L.id ? L.id[i] : 0u;
    e.action = action;
    // The particle's sub-step began at the block's time, or for a newborn of the batch
    // (its own step length) (substeps - sub) of its sub-step lengths before the end.
    const double start = c.ownDt && i >= c.newbornsFrom
                             ? log.t1 - double(dt) * double(log.substeps - log.sub)
                             : c.time;
    e.time = start + double(tau);
    // A particle left NaN or infinite by the list is killed by the step, not reported.
    const float sum = e.position.x + e.position.y + e.position.z + e.velocity.x + e.velocity.y +
                      e.velocity.z + float(e.time);
    if (!std::isfinite(sum)) return;
    const std::uint64_t key = (std::uint64_t(c.base + i) << 32) | (std::uint64_t(log.sub) << 16) |
                              std::uint64_t(action & 0xFFFFu);
    log.group->addCollision(log.block, key, e);
  };
  const bool planar = withPlanarPiece(b, [&](Vec3 P, Vec3 N, auto) {
    each([&](std::size_t i) {
      const float dt = c.dtAt(i);
      const Vec3 v(vx[i], vy[i], vz[i]);
      const Vec3 a = acc ? Vec3(acc[0][i], acc[1][i], acc[2][i]) : Vec3(0.0f);
      CollisionEvent e;
      float side, tau, hx, hy, hz;
      kernel::fl_planar_accel_hit(px[i], py[i], pz[i], v.x, v.y, v.z, a.x, a.y, a.z, dt, P.x, P.y,
                                  P.z, N.x, N.y, N.z, &side, &tau, &hx, &hy, &hz);
      e.position = Vec3(hx, hy, hz);
      e.normal = N * side;
      finish(e, i, dt, tau, v, a);
    });
  });
  if (planar) return;
  const auto& shape = b.surface.shape();
  each([&](std::size_t i) {
    const float dt = c.dtAt(i);
    const Vec3 p(px[i], py[i], pz[i]), v(vx[i], vy[i], vz[i]);
    Vec3 nrm(0.0f);
    float tau = 0.0f;
    // (kernels/deflect.h: the device's events take the same)
    if (const auto* s = std::get_if<SphereDomain>(&shape)) {
      tau =
          kernel::fl_sphere_hit(p.x, p.y, p.z, v.x, v.y, v.z, s->center.x, s->center.y, s->center.z,
                                s->outerRadius, b.inside, dt, &nrm.x, &nrm.y, &nrm.z);
    } else if (const auto* bx = std::get_if<BoxDomain>(&shape)) {
      const float pa[3] = {p.x, p.y, p.z}, va[3] = {v.x, v.y, v.z};
      const float lo[3] = {bx->min.x, bx->min.y, bx->min.z},
                  hi[3] = {bx->max.x, bx->max.y, bx->max.z};
      float na[3];
      tau = kernel::fl_box_hit(pa, va, lo, hi, b.inside, dt, na);
      nrm = Vec3(na[0], na[1], na[2]);
    }
    CollisionEvent e;
    e.position = p + v * tau;
    e.normal = b.inside ? -nrm : nrm;  // towards where the particle came from
    finish(e, i, dt, tau, v, Vec3(0.0f));
  });
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail::cpu
