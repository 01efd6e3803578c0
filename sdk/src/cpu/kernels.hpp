// The CPU backend's per-action loops. Each runs over one block of particles with its lanes
// passed as __restrict locals (GCC does not vectorise loops that reload array pointers from
// a struct), branch-free, so the compiler vectorises them. The fused pass runs every action
// of the list over a block while the block is in cache.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "../group_impl.hpp"
#include "../shape_math.hpp"
#include "flurry/actions.hpp"
#include "flurry/random.hpp"

namespace flurry::detail::cpu {

struct BlockContext {
  float dt;
  std::uint64_t seed;
  std::uint32_t step;
  std::uint32_t streamBase;  ///< keeps the random streams of different groups apart
  std::uint32_t action;      ///< index in the list: the random stream and the kill code
  std::uint32_t* dead;       ///< per particle of the block: 0 alive, else 1 + killing action
};

// The loops take their arrays as __restrict parameters: GCC 12 vectorises these, but not
// the same loops over __restrict locals loaded from a struct.

inline void addLoop(float* __restrict x, float* __restrict y, float* __restrict z, std::size_t n,
                    float ax, float ay, float az) {
  for (std::size_t i = 0; i < n; ++i) {
    x[i] += ax;
    y[i] += ay;
    z[i] += az;
  }
}

inline void scaleLoop(float* __restrict x, float* __restrict y, float* __restrict z,
                      std::size_t n, float fx, float fy, float fz) {
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

inline void moveLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                     const float* __restrict vx, const float* __restrict vy,
                     const float* __restrict vz, std::size_t n, float dt) {
  for (std::size_t i = 0; i < n; ++i) {
    px[i] += vx[i] * dt;
    py[i] += vy[i] * dt;
    pz[i] += vz[i] * dt;
  }
}

inline void ageLoop(float* __restrict age, std::size_t n, float dt) {
  for (std::size_t i = 0; i < n; ++i) age[i] += dt;
}

inline void killOldLoop(const float* __restrict age, const float* __restrict life,
                        std::uint32_t* __restrict dead, std::size_t n, std::uint32_t code) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t k = age[i] > life[i] ? code : 0u;
    dead[i] = dead[i] != 0u ? dead[i] : k;
  }
}

template <class Shape>
inline void sinkLoop(const Shape& shape, const float* __restrict px, const float* __restrict py,
                     const float* __restrict pz, std::uint32_t* __restrict dead, std::size_t n,
                     std::uint32_t code, bool killInside) {
  const std::uint32_t want = killInside ? 1u : 0u;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t in = detail::inside(shape, Vec3(px[i], py[i], pz[i])) ? 1u : 0u;
    const std::uint32_t k = in == want ? code : 0u;
    dead[i] = dead[i] != 0u ? dead[i] : k;
  }
}

inline void apply(const Gravity& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  addLoop(L.v[0], L.v[1], L.v[2], n, a.acceleration.x * c.dt, a.acceleration.y * c.dt,
          a.acceleration.z * c.dt);
}

inline void apply(const Damping& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  // The exact solution of dv/dt = -k v over the step: independent of the step size.
  scaleLoop(L.v[0], L.v[1], L.v[2], n, std::exp(-a.rate.x * c.dt), std::exp(-a.rate.y * c.dt),
            std::exp(-a.rate.z * c.dt));
}

inline void apply(const Move&, const Lanes& L, std::size_t n, const BlockContext& c) {
  if (L.prev[0]) copyLoop(L.prev[0], L.prev[1], L.prev[2], L.p[0], L.p[1], L.p[2], n);
  moveLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, c.dt);
  if (L.age) ageLoop(L.age, n, c.dt);
}

inline void apply(const KillOld&, const Lanes& L, std::size_t n, const BlockContext& c) {
  killOldLoop(L.age, L.lifetime, c.dead, n, c.action + 1);
}

inline void apply(const Sink& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const std::uint32_t code = c.action + 1;
  std::visit([&](const auto& shape) { sinkLoop(shape, L.p[0], L.p[1], L.p[2], c.dead, n, code, a.killInside); },
             a.region.shape());
  if (a.passThrough > 0.0f) {
    // Only the particles this sink just took draw a number: random numbers are compute-bound.
    for (std::size_t i = 0; i < n; ++i) {
      if (c.dead[i] != code) continue;
      Random rng(c.seed, L.id[i], c.step, c.streamBase + c.action);
      if (rng.uniform() < a.passThrough) c.dead[i] = 0u;
    }
  }
}

/// Reflects the velocity and places the particle so that the following Move ends it at the
/// reflected point; then makes sure that point is strictly on the side it came from.
struct Reflect {
  float restitution, keep, cutoff2;
  // In: position p, velocity v, hit point h, unit normal nrm, time of impact tau.
  // Out: the new position and velocity.
  inline void operator()(float& px, float& py, float& pz, float& vx, float& vy, float& vz,
                         float hx, float hy, float hz, float nx, float ny, float nz,
                         float tau) const {
    const float vn = vx * nx + vy * ny + vz * nz;
    const float vnx = vn * nx, vny = vn * ny, vnz = vn * nz;
    const float tx = vx - vnx, ty = vy - vny, tz = vz - vnz;
    const float t2 = tx * tx + ty * ty + tz * tz;
    const float f = t2 > cutoff2 ? keep : 1.0f;  // the one select: vectorises
    vx = tx * f - vnx * restitution;
    vy = ty * f - vny * restitution;
    vz = tz * f - vnz * restitution;
    px = hx - vx * tau;
    py = hy - vy * tau;
    pz = hz - vz * tau;
  }
};

/// A two-sided planar deflector (plane, rectangle, disc, triangle): `onPiece` says whether a
/// point of the plane belongs to the piece.
template <class OnPiece>
inline void bouncePlanarLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                             float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                             std::size_t n, float dt, Vec3 P, Vec3 N, OnPiece onPiece,
                             const Bounce& b) {
  const Reflect reflect{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  const float scaleP = std::abs(P.x) + std::abs(P.y) + std::abs(P.z);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = px[i], y = py[i], z = pz[i];
    const float vx = vxs[i], vy = vys[i], vz = vzs[i];
    const float d0 = (x - P.x) * N.x + (y - P.y) * N.y + (z - P.z) * N.z;
    const float vn = vx * N.x + vy * N.y + vz * N.z;
    const float d1 = d0 + vn * dt;
    const float side = d0 >= 0.0f ? 1.0f : -1.0f;
    // Computed for every particle and kept only on a hit (one if-block: GCC 12 vectorises
    // that, but not several selects on the same condition). Lanes that miss may hold inf.
    const float tau = d0 / (d0 - d1) * dt;
    const float hx = x + vx * tau, hy = y + vy * tau, hz = z + vz * tau;
    const bool hit = (side * d1 < 0.0f) & onPiece(hx, hy, hz);
    float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
    reflect(nx, ny, nz, nvx, nvy, nvz, hx, hy, hz, N.x, N.y, N.z, tau);
    // Where Move will put it; push it out if rounding left it on or behind the plane.
    const float qx = nx + nvx * dt, qy = ny + nvy * dt, qz = nz + nvz * dt;
    const float qd = side * ((qx - P.x) * N.x + (qy - P.y) * N.y + (qz - P.z) * N.z);
    const float margin = 4e-7f * (std::abs(qx) + std::abs(qy) + std::abs(qz) + scaleP) + 1e-30f;
    const float push = std::max(2.0f * margin - qd, 0.0f) * side;
    float ox = x, oy = y, oz = z, ovx = vx, ovy = vy, ovz = vz;
    if (hit) {
      ox = nx + push * N.x;
      oy = ny + push * N.y;
      oz = nz + push * N.z;
      ovx = nvx;
      ovy = nvy;
      ovz = nvz;
    }
    px[i] = ox;
    py[i] = oy;
    pz[i] = oz;
    vxs[i] = ovx;
    vys[i] = ovy;
    vzs[i] = ovz;
  }
}

/// A sphere deflecting from outside.
inline void bounceSphereLoop(float* __restrict px, float* __restrict py, float* __restrict pz,
                             float* __restrict vxs, float* __restrict vys, float* __restrict vzs,
                             std::size_t n, float dt, const SphereDomain& s, const Bounce& b) {
  const Reflect reflect{b.restitution, 1.0f - b.friction, b.cutoff * b.cutoff};
  const Vec3 C = s.center;
  const float R = s.outerRadius, R2 = R * R, invR = 1.0f / R;
  const float scaleC = std::abs(C.x) + std::abs(C.y) + std::abs(C.z) + R;
  for (std::size_t i = 0; i < n; ++i) {
    const float x = px[i], y = py[i], z = pz[i];
    const float vx = vxs[i], vy = vys[i], vz = vzs[i];
    const float rx = x - C.x, ry = y - C.y, rz = z - C.z;
    const float c2 = rx * rx + ry * ry + rz * rz - R2;
    const float bb = rx * vx + ry * vy + rz * vz;
    const float aa = vx * vx + vy * vy + vz * vz;
    const float disc = bb * bb - aa * c2;
    const float tHit = (-bb - std::sqrt(std::max(disc, 0.0f))) / aa;  // inf/NaN: a miss
    const bool hit = (c2 >= 0.0f) & (disc >= 0.0f) & (bb < 0.0f) & (tHit <= dt);
    const float tau = std::max(tHit, 0.0f);
    const float hx = x + vx * tau, hy = y + vy * tau, hz = z + vz * tau;
    const float nnx = (hx - C.x) * invR, nny = (hy - C.y) * invR, nnz = (hz - C.z) * invR;
    float nx = x, ny = y, nz = z, nvx = vx, nvy = vy, nvz = vz;
    reflect(nx, ny, nz, nvx, nvy, nvz, hx, hy, hz, nnx, nny, nnz, tau);
    const float qx = nx + nvx * dt - C.x, qy = ny + nvy * dt - C.y, qz = nz + nvz * dt - C.z;
    const float qd = std::sqrt(qx * qx + qy * qy + qz * qz) - R;
    const float margin = 4e-7f * (std::abs(qx) + std::abs(qy) + std::abs(qz) + scaleC) + 1e-30f;
    const float push = std::max(2.0f * margin - qd, 0.0f);
    float ox = x, oy = y, oz = z, ovx = vx, ovy = vy, ovz = vz;
    if (hit) {
      ox = nx + push * nnx;
      oy = ny + push * nny;
      oz = nz + push * nnz;
      ovx = nvx;
      ovy = nvy;
      ovz = nvz;
    }
    px[i] = ox;
    py[i] = oy;
    pz[i] = oz;
    vxs[i] = ovx;
    vys[i] = ovy;
    vzs[i] = ovz;
  }
}

template <class OnPiece>
inline void bouncePlanar(Vec3 P, Vec3 N, OnPiece onPiece, const Bounce& b, const Lanes& L,
                         std::size_t n, float dt) {
  bouncePlanarLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, dt, P, N, onPiece, b);
}

inline void apply(const Bounce& a, const Lanes& L, std::size_t n, const BlockContext& c) {
  const auto& shape = a.surface.shape();
  if (const auto* pl = std::get_if<PlaneDomain>(&shape)) {
    bouncePlanar(pl->point, pl->normal, [](float, float, float) { return true; }, a, L, n, c.dt);
  } else if (const auto* r = std::get_if<RectangleDomain>(&shape)) {
    // Dual vectors give the (s, t) coordinates of a point of the plane, also for a rhombus.
    const Vec3 cu = glm::cross(r->v, r->normal), cv = glm::cross(r->normal, r->u);
    const Vec3 du = cu / glm::dot(r->u, cu), dv = cv / glm::dot(r->v, cv);
    const Vec3 o = r->origin;
    bouncePlanar(
        o, r->normal,
        [=](float x, float y, float z) {
          const float wx = x - o.x, wy = y - o.y, wz = z - o.z;
          const float s = wx * du.x + wy * du.y + wz * du.z;
          const float t = wx * dv.x + wy * dv.y + wz * dv.z;
          return (s >= 0.0f) & (s <= 1.0f) & (t >= 0.0f) & (t <= 1.0f);
        },
        a, L, n, c.dt);
  } else if (const auto* t = std::get_if<TriangleDomain>(&shape)) {
    const Vec3 e1 = t->p1 - t->p0, e2 = t->p2 - t->p0;
    const Vec3 c1 = glm::cross(e2, t->normal), c2 = glm::cross(t->normal, e1);
    const Vec3 d1 = c1 / glm::dot(e1, c1), d2 = c2 / glm::dot(e2, c2);
    const Vec3 o = t->p0;
    bouncePlanar(
        o, t->normal,
        [=](float x, float y, float z) {
          const float wx = x - o.x, wy = y - o.y, wz = z - o.z;
          const float s = wx * d1.x + wy * d1.y + wz * d1.z;
          const float u = wx * d2.x + wy * d2.y + wz * d2.z;
          return (s >= 0.0f) & (u >= 0.0f) & (s + u <= 1.0f);
        },
        a, L, n, c.dt);
  } else if (const auto* d = std::get_if<DiscDomain>(&shape)) {
    const Vec3 o = d->center;
    const float ro2 = d->outerRadius * d->outerRadius, ri2 = d->innerRadius * d->innerRadius;
    bouncePlanar(
        o, d->normal,
        [=](float x, float y, float z) {
          const float wx = x - o.x, wy = y - o.y, wz = z - o.z;
          const float r2 = wx * wx + wy * wy + wz * wz;
          return (r2 <= ro2) & (r2 >= ri2);
        },
        a, L, n, c.dt);
  } else if (const auto* s = std::get_if<SphereDomain>(&shape)) {
    bounceSphereLoop(L.p[0], L.p[1], L.p[2], L.v[0], L.v[1], L.v[2], n, c.dt, *s, a);
  }
}

}  // namespace flurry::detail::cpu
