// Integrators for Move: the forces before a Move, evaluated together as an acceleration
// a(p, v, t), integrated by explicit Euler, velocity Verlet, RK4, or in closed form.
#pragma once

#include <cmath>
#include <vector>

#include "../isa_namespace.hpp"
#include "actions_more.hpp"

namespace flurry::detail::cpu {
inline namespace FLURRY_ISA_NAMESPACE {  // see isa_namespace.hpp

/// Arrays an acceleration is evaluated on: positions and velocities of a block (or of an
/// integrator's intermediate stage), and where it accumulates.
struct Stage {
  const float* p[3];
  const float* v[3];
  float* a[3];
};

namespace {
inline Vec3 get(const float* const* a, std::size_t i) {
  return Vec3(a[0][i], a[1][i], a[2][i]);
}
inline void add(float* const* a, std::size_t i, Vec3 d) {
  a[0][i] += d.x;
  a[1][i] += d.y;
  a[2][i] += d.z;
}
}  // namespace

// f(i, p, v, ax, ay, az) for each particle of a stage, its acceleration's sums in locals.
template <class F>
[[gnu::flatten]] inline void stageLoop(const float* __restrict px, const float* __restrict py,
                                       const float* __restrict pz, const float* __restrict vx,
                                       const float* __restrict vy, const float* __restrict vz,
                                       float* __restrict ax, float* __restrict ay,
                                       float* __restrict az, std::size_t n, F f) {
  for (std::size_t i = 0; i < n; ++i) {
    float x = ax[i], y = ay[i], z = az[i];
    f(i, Vec3(px[i], py[i], pz[i]), Vec3(vx[i], vy[i], vz[i]), x, y, z);
    ax[i] = x, ay[i] = y, az[i] = z;
  }
}
template <class F>
inline void stageLoop(const Stage& s, std::size_t n, F f) {
  stageLoop(s.p[0], s.p[1], s.p[2], s.v[0], s.v[1], s.v[2], s.a[0], s.a[1], s.a[2], n, f);
}

// Adds one force's acceleration at (p, v, t), from its record (c.record()) by the shared
// kernel functions (kernels/forces.h), which add to the stage's sums as the device's do. `L`
// gives the per-particle constants (charge, mass, id); `c` the step (its random numbers are the
// same in every stage of a step).
inline void accumulate(const Action& action, const Stage& s, const Lanes& L, std::size_t n,
                       const BlockContext& c, double t) {
  const cl::FlActionParams& record = c.record();
  const cl::FlFalloffParams& f = record.falloff;
  // Gravity without a falloff weighs 1 everywhere (fl_falloff_weight): its constant added as a
  // vector loop gives the same sums as the general loop below.
  if (std::holds_alternative<Gravity>(action) && !(f.radius < kInfinity)) {
    const cl::FlXyz g = record.own.gravity.acceleration;
    const float k[3] = {g.x, g.y, g.z};
    for (int d = 0; d < 3; ++d) {
      float* __restrict a = s.a[d];
      const float x = k[d];
      for (std::size_t i = 0; i < n; ++i) a[i] += x;
    }
    return;
  }
  // Drawn accelerations (Jet, RandomAccel): every particle's drawn in batches, the same
  // numbers as one Random each (sampleFromActionStreams), then weighed at the stage's place.
  const Domain* drawn = nullptr;
  if (const auto* jet = std::get_if<Jet>(&action)) drawn = &jet->acceleration;
  if (const auto* ra = std::get_if<RandomAccel>(&action)) drawn = &ra->acceleration;
  if (drawn) {
    const bool isJet = std::holds_alternative<Jet>(action);
    const cl::FlJetParams jet = record.own.jet;
    withFalloff(f, [&](auto fall) {
      sampleFromActionStreams(
          *drawn, L, n, c, [&](std::size_t first, std::size_t m, float* dx, float* dy, float* dz) {
            const float* const p[3] = {s.p[0] + first, s.p[1] + first, s.p[2] + first};
            float* const a[3] = {s.a[0] + first, s.a[1] + first, s.a[2] + first};
            // (stageLoop's velocities are the draws here: a loop over restricted arguments,
            // which GCC 12 vectorised where the same loop over restricted locals was scalar)
            if (isJet) {  // d in reach, + 0 out of it, as the sum was (not d·0: -0 for d < 0)
              stageLoop(p[0], p[1], p[2], dx, dy, dz, a[0], a[1], a[2], m,
                        [jet](std::size_t, Vec3 q, Vec3 d, float& ax, float& ay, float& az) {
                          const int in = kernel::fl_jet_reaches(jet, q.x, q.y, q.z);
                          ax += in ? d.x : 0.0f;
                          ay += in ? d.y : 0.0f;
                          az += in ? d.z : 0.0f;
                        });
            } else {
              const cl::FlFalloffParams ff = fall();
              stageLoop(p[0], p[1], p[2], dx, dy, dz, a[0], a[1], a[2], m,
                        [ff](std::size_t, Vec3 q, Vec3 d, float& ax, float& ay, float& az) {
                          const float w = kernel::fl_falloff_weight(ff, q.x, q.y, q.z);
                          ax += d.x * w;
                          ay += d.y * w;
                          az += d.z * w;
                        });
            }
          });
    });
    return;
  }
  // Gravitate: each stage's pulls summed as in its own loop (gravitateScan: two vectors'
  // worth of particles against the step's snapshot, each in the scalar order, itself adding
  // -0), from the stage's positions; then added to the stage's sums.
  if (std::holds_alternative<Gravitate>(action)) {
    forEachGravitatePull(*c.snapshot, s.p, c.base, n, record.own.pull,
                         [&](std::size_t i, Vec3 pull) { add(s.a, i, pull); });
    return;
  }
  // Follow: the pull towards the next particle as it was at the step's start, for those that
  // have one; the last of the group leads (it adds +0, as the sum of none).
  if (std::holds_alternative<Follow>(action)) {
    const std::size_t led =
        followPulls(*c.snapshot, c.base, s.p, s.a, n, UniformDt{1.0f}, record.own.pull);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = led; i < n; ++i) s.a[d][i] += 0.0f;
    return;
  }
  // A SampledField on a grid of fewer than 2^31 floats: its lookups in 32-bit offsets,
  // gathered in vectors, and its mode a constant of the loop (as in its own loop).
  if (const auto* sf = std::get_if<SampledField>(&action);
      sf && sf->field->data.size() * 3 < (std::size_t(1) << 31)) {
    const VectorField& field = *sf->field;
    const float* grid = reinterpret_cast<const float*>(field.data.data());
    const int nx = field.dims.x, ny = field.dims.y, nz = field.dims.z;
    const float ox = field.origin.x, oy = field.origin.y, oz = field.origin.z;
    const float voxel = field.voxelSize;
    const cl::FlSampledFieldParams params = record.own.sampledField;
    auto mode = [&](auto carry) {
      cl::FlSampledFieldParams sp = params;
      sp.carry = decltype(carry)::value;
      withFalloff(f, [&](auto fall) {
        stageLoop(s, n, [=](std::size_t, Vec3 p, Vec3 v, float& ax, float& ay, float& az) {
          const Vec3 u =
              kernel::fl_grid_sample_int(grid, nx, ny, nz, ox, oy, oz, voxel, p.x, p.y, p.z);
          kernel::fl_sampled_field_acc(sp, kernel::fl_falloff_weight(fall(), p.x, p.y, p.z), u.x,
                                       u.y, u.z, v.x, v.y, v.z, &ax, &ay, &az);
        });
      });
    };
    if (params.carry)
      mode(std::integral_constant<int, 1>{});
    else
      mode(std::integral_constant<int, 0>{});
    return;
  }
  std::visit(
      [&](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        // The record by value and the stage's arrays as a function's restricted arguments
        // (stageLoop): GCC read them again for each particle (the stage's stores might have
        // changed them), and kept the loop scalar.
        const cl::FlActionParams r = record;
        const float* __restrict charge = L.charge;
        const float* __restrict mass = L.mass;
        // The falloff as withFalloff gives it (kernels.hpp): an infinite radius or a power of 1
        // folded into the loop, as in the forces' own loops, and no fl_powf in each stage.
        auto run = [&](auto fall) {
          stageLoop(
              s, n,
              [r, fall, t, charge, mass, &a](std::size_t i, Vec3 p, Vec3 v, float& ax, float& ay,
                                             float& az) {
                const cl::FlFalloffParams f = fall();
                if constexpr (std::is_same_v<A, Gravity>) {
                  kernel::fl_gravity_acc(r.own.gravity, f, p.x, p.y, p.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, Damping>) {
                  kernel::fl_damping_acc(r.own.damping, f, p.x, p.y, p.z, v.x, v.y, v.z, &ax, &ay,
                                         &az);
                } else if constexpr (std::is_same_v<A, OrbitPoint>) {
                  kernel::fl_orbit_point_acc(r.own.orbitPoint, p.x, p.y, p.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, OrbitLine>) {
                  kernel::fl_orbit_line_acc(r.own.orbitLine, p.x, p.y, p.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, Vortex>) {
                  kernel::fl_vortex_acc(r.own.vortex, p.x, p.y, p.z, v.x, v.y, v.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, Explosion>) {
                  kernel::fl_explosion_acc(r.own.explosion, t, p.x, p.y, p.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, Turbulence>) {
                  kernel::fl_turbulence_acc(r.own.turbulence, f, t, p.x, p.y, p.z, &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, ElectricField>) {
                  kernel::fl_electric_acc(r.own.electric, f, p.x, p.y, p.z, charge[i], mass[i], &ax,
                                          &ay, &az);
                } else if constexpr (std::is_same_v<A, MagneticField>) {
                  kernel::fl_magnetic_acc(r.own.magnetic, f, p.x, p.y, p.z, v.x, v.y, v.z,
                                          charge[i], mass[i], &ax, &ay, &az);
                } else if constexpr (std::is_same_v<A, SampledField>) {
                  const Vec3 u = sampleTrilinear(*a.field, p);  // (a larger grid)
                  kernel::fl_sampled_field_acc(r.own.sampledField,
                                               kernel::fl_falloff_weight(f, p.x, p.y, p.z), u.x,
                                               u.y, u.z, v.x, v.y, v.z, &ax, &ay, &az);
                }
              });
        };
        constexpr bool weighs = std::is_same_v<A, Gravity> || std::is_same_v<A, Damping> ||
                                std::is_same_v<A, Turbulence> || std::is_same_v<A, ElectricField> ||
                                std::is_same_v<A, MagneticField> || std::is_same_v<A, SampledField>;
        if constexpr (weighs)
          withFalloff(r.falloff, run);
        else
          run([f = r.falloff] { return f; });
      },
      action);
}

// The integrators' per-particle steps (kernels/integrate.h) as loops over restricted arrays:
// written over the lanes and the scratch's arrays in place, GCC could not tell them apart and
// kept every one scalar.
template <class Dt>
void eulerLoop(const float* __restrict a, float* __restrict p, float* __restrict v, std::size_t n,
               Dt dt) {
  for (std::size_t i = 0; i < n; ++i) kernel::fl_euler_explicit(a[i], dt[i], &p[i], &v[i]);
}
// f(x[i], y[i], z[i], dt[i], &out0[i], &out1[i]): Verlet's halves.
template <class Dt, class F>
[[gnu::flatten]] void threeToTwoLoop(const float* __restrict x, const float* __restrict y,
                                     const float* __restrict z, float* __restrict out0,
                                     float* __restrict out1, std::size_t n, Dt dt, F f) {
  for (std::size_t i = 0; i < n; ++i) f(x[i], y[i], z[i], dt[i], &out0[i], &out1[i]);
}
// RK4's stages (kernels/integrate.h): each weighs its slopes (vs, a) into the sums and makes
// the next stage's state, `next` of the step on. The first takes its slopes from the lanes and
// starts the sums from 0; a middle one reads vs, then writes it; the last one ends the step.
template <class Dt>
void rk4FirstLoop(const float* __restrict p, const float* __restrict v, const float* __restrict a,
                  float next, float* __restrict sp, float* __restrict sv, float* __restrict ps,
                  float* __restrict vs, std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) {
    float s0 = 0.0f, s1 = 0.0f;
    kernel::fl_rk4_stage(p[i], v[i], v[i], a[i], 1.0f, next * dt[i], &s0, &s1, &ps[i], &vs[i]);
    sp[i] = s0, sv[i] = s1;
  }
}
template <class Dt>
void rk4StageLoop(const float* __restrict p, const float* __restrict v, float* __restrict vs,
                  const float* __restrict a, float next, float* __restrict sp, float* __restrict sv,
                  float* __restrict ps, std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i)
    kernel::fl_rk4_stage(p[i], v[i], vs[i], a[i], 2.0f, next * dt[i], &sp[i], &sv[i], &ps[i],
                         &vs[i]);
}
template <class Dt>
void rk4LastLoop(const float* __restrict vs, const float* __restrict a, const float* __restrict sp,
                 const float* __restrict sv, float* __restrict p, float* __restrict v,
                 std::size_t n, Dt dt) {
  for (std::size_t i = 0; i < n; ++i) {
    float s0 = sp[i], s1 = sv[i], unused0, unused1;  // (the next state: there is none)
    kernel::fl_rk4_stage(p[i], v[i], vs[i], a[i], 1.0f, 0.0f, &s0, &s1, &unused0, &unused1);
    kernel::fl_rk4_finish(s0, s1, dt[i], &p[i], &v[i]);
  }
}

/// Scratch for one block's integration (per thread).
struct IntegratorScratch {
  std::vector<float> data;
  float* take(std::size_t n) {  // call reset() first
    float* p = data.data() + used;
    used += n;
    return p;
  }
  void reset(std::size_t n, std::size_t arrays) {
    if (data.size() < n * arrays) data.resize(n * arrays);
    used = 0;
  }
  std::size_t used = 0;
};

/// The acceleration a Bounce takes as constant over the step before a Move that integrates
/// `forces` (fused_pass.cpp): the forces evaluated at the block's state at the step's start,
/// as the integrators' first stage evaluates them, into `a` (three arrays of n).
inline void startAcceleration(const std::vector<Action>& acts,
                              const std::vector<std::uint32_t>& forces, const Lanes& L,
                              std::size_t n, const BlockContext& c, float* const* a) {
  for (int d = 0; d < 3; ++d) std::fill_n(a[d], n, 0.0f);
  const Stage s{{L.p[0], L.p[1], L.p[2]}, {L.v[0], L.v[1], L.v[2]}, {a[0], a[1], a[2]}};
  for (std::uint32_t k : forces) {
    BlockContext ck = c;
    ck.action = k;
    accumulate(acts[k], s, L, n, ck, c.time);
  }
}

/// Move with an integrator other than semi-implicit Euler: `forces` are the indices of the
/// force actions gathered for this Move. `dt` is the block's sub-step (UniformDt) or each
/// newborn's own (OwnDt); with OwnDt the forces must not depend on the time (the stages are
/// evaluated at c.time), which the fused pass checks (fused_pass.cpp runNewborns).
template <class Dt>
inline void integrate(Integrator integrator, const std::vector<Action>& acts,
                      const std::vector<std::uint32_t>& forces, const Lanes& L, std::size_t n,
                      const BlockContext& c, IntegratorScratch& scratch, Dt dt) {
  // A stage's time, for the forces that read it: with OwnDt none does.
  const float h0 = dt[0];
  const double t = c.time;
  scratch.reset(n, 24);
  auto arrays3 = [&](float** out) {
    for (int d = 0; d < 3; ++d) out[d] = scratch.take(n);
  };
  auto evaluate = [&](const float* const* p, const float* const* v, float* const* a, double at) {
    for (int d = 0; d < 3; ++d) std::fill_n(a[d], n, 0.0f);
    const Stage s{{p[0], p[1], p[2]}, {v[0], v[1], v[2]}, {a[0], a[1], a[2]}};
    for (std::uint32_t k : forces) {
      BlockContext ck = c;
      ck.action = k;
      accumulate(acts[k], s, L, n, ck, at);
    }
  };
  if (L.prev[0]) copyLoop(L.prev[0], L.prev[1], L.prev[2], L.p[0], L.p[1], L.p[2], n);

  float *a0[3], *a1[3];
  arrays3(a0);
  switch (integrator) {
    case Integrator::ExplicitEuler: {
      evaluate(L.p, L.v, a0, t);
      for (int d = 0; d < 3; ++d) eulerLoop(a0[d], L.p[d], L.v[d], n, dt);
      break;
    }
    case Integrator::VelocityVerlet: {
      arrays3(a1);
      float *p1[3], *v1[3];
      arrays3(p1);
      arrays3(v1);
      evaluate(L.p, L.v, a0, t);
      for (int d = 0; d < 3; ++d)
        threeToTwoLoop(L.p[d], L.v[d], a0[d], p1[d], v1[d], n, dt,
                       [](auto... x) { kernel::fl_verlet_predict(x...); });
      evaluate(p1, v1, a1, t + h0);
      for (int d = 0; d < 3; ++d)
        threeToTwoLoop(p1[d], a0[d], a1[d], L.p[d], L.v[d], n, dt,
                       [](auto... x) { kernel::fl_verlet_finish(x...); });
      break;
    }
    case Integrator::RK4: {
      // Classic RK4 on (p, v): k_p = v, k_v = a(p, v, t); stages at 0, h/2, h/2 and h, their
      // slopes weighed 1, 2, 2, 1.
      float *ps[3], *vs[3], *sp[3], *sv[3];
      arrays3(a1);  // stage acceleration
      arrays3(ps);
      arrays3(vs);
      arrays3(sp);  // weighted sums
      arrays3(sv);
      evaluate(L.p, L.v, a1, t);
      for (int d = 0; d < 3; ++d)
        rk4FirstLoop(L.p[d], L.v[d], a1[d], 0.5f, sp[d], sv[d], ps[d], vs[d], n, dt);
      for (int k = 1; k < 3; ++k) {
        evaluate(ps, vs, a1, t + 0.5f * h0);
        const float next = k == 1 ? 0.5f : 1.0f;
        for (int d = 0; d < 3; ++d)
          rk4StageLoop(L.p[d], L.v[d], vs[d], a1[d], next, sp[d], sv[d], ps[d], n, dt);
      }
      evaluate(ps, vs, a1, t + 1.0f * h0);
      for (int d = 0; d < 3; ++d) rk4LastLoop(vs[d], a1[d], sp[d], sv[d], L.p[d], L.v[d], n, dt);
      break;
    }
    case Integrator::Exact: {
      // Constant acceleration g (Gravity + (q/m)E) with per-axis linear drag k: exact.
      arrays3(a1);  // drag rates
      const Stage none{{L.p[0], L.p[1], L.p[2]}, {L.v[0], L.v[1], L.v[2]}, {a0[0], a0[1], a0[2]}};
      for (int d = 0; d < 3; ++d) {
        std::fill_n(a0[d], n, 0.0f);
        std::fill_n(a1[d], n, 0.0f);
      }
      bool drag = false;
      for (std::uint32_t k : forces) {
        if (std::holds_alternative<Damping>(acts[k])) {
          drag = true;
          const cl::FlXyz r = c.records[k].own.damping.rate;
          const float rate[3] = {r.x, r.y, r.z};
          for (int d = 0; d < 3; ++d)
            for (std::size_t i = 0; i < n; ++i) a1[d][i] += rate[d];
        } else {
          BlockContext ck = c;
          ck.action = k;
          accumulate(acts[k], none, L, n, ck, t);
        }
      }
      for (int d = 0; d < 3; ++d) {
        float* __restrict p = L.p[d];
        float* __restrict v = L.v[d];
        const float* __restrict g = a0[d];
        const float* __restrict k = a1[d];
        if (drag) {
          for (std::size_t i = 0; i < n; ++i)
            kernel::fl_exact_step(g[i], k[i], dt[i], &p[i], &v[i]);
        } else {
          // No drag: every rate is 0, and the form without exp() vectorises (the same bits).
          for (std::size_t i = 0; i < n; ++i)
            kernel::fl_exact_step(g[i], 0.0f, dt[i], &p[i], &v[i]);
        }
      }
      break;
    }
    case Integrator::SemiImplicitEuler:
      break;  // not used: the forces ran as their own updates
  }
  if (L.age) ageLoop(L.age, n, dt);
}

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail::cpu
