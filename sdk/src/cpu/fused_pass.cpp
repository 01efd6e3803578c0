// The CPU backend's act phase: the whole action list as one fused pass over the group.
//
// Actions are built at run time (effect files), so the pass cannot be one compiled loop per
// list. Instead it is blocked: every action runs over a block of particles small enough to
// stay in cache, so each particle is read from and written to memory once per step however
// many actions there are, and each action's loop is vectorised on its own. Sub-steps, the
// integrator's stages and the NaN guard all happen while the block is in cache.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "../action_traits.hpp"
#include "../backend.hpp"
#include "actions_more.hpp"
#include "collisions.hpp"
#include "integrate.hpp"
#include "kernels.hpp"

#ifndef FLURRY_ISA
#define FLURRY_ISA baseline
#endif

namespace flurry::detail::FLURRY_ISA {

namespace {

constexpr std::size_t kDefaultBlock = 1024;
constexpr std::size_t kParticlesPerTask = 32768;  // below this a group is stepped inline

// How each action of the list runs this step: what follows from the list (cached in the
// group), and what follows from this step's velocities and dt.
struct Plan {
  const ActionPlan& list;
  std::uint32_t substeps = 1;
};

std::uint32_t substepCount(GroupImpl& g, const StepParams& sp, ThreadPool& pool) {
  const Substeps& sub = g.actions.substeps();
  double n = 1;
  if (sub.maxStep > 0) n = std::max(n, std::ceil(sp.dt / sub.maxStep));
  if (sub.maxDistance > 0 && g.stored.has(Attribute::Velocity)) {
    // The fastest particle decides, for the whole group, so that the result does not depend
    // on how the group is cut into blocks.
    const Lanes L = g.lanePointers();
    const std::size_t chunks = (g.size + 65535) / 65536;
    std::vector<float>& fastest = g.plan.fastest;  // grows, never shrinks
    assignFill(fastest, chunks, 0.0f);
    pool.parallelFor(chunks, [&](std::size_t c) {
      float m = 0.0f;
      for (std::size_t i = c * 65536; i < std::min(g.size, (c + 1) * 65536); ++i)
        m = std::max(m, L.v[0][i] * L.v[0][i] + L.v[1][i] * L.v[1][i] + L.v[2][i] * L.v[2][i]);
      fastest[c] = m;
    });
    const float vmax = std::sqrt(*std::max_element(fastest.begin(), fastest.end()));
    if (std::isfinite(vmax)) n = std::max(n, std::ceil(vmax * sp.dt / sub.maxDistance));
  }
  return std::uint32_t(std::min<double>(n, sub.maxSubsteps));
}

// After an integrating Move, a particle that its curved step (or its bounce) left on the
// wrong side of a deflector, compared with where it was when the step began, is put back on
// its side and reflected: no particle ends behind a deflector.
//
// A planar piece is one plane: a vectorised test first drops the particles that are clearly
// on their starting side at both ends of the step, by far more than the rounding of the exact
// test below (which gives the same answer for them); the few left (near the plane, or across
// it) take the exact test, so the result is bitwise what testing everyone would give.
void guard(const Bounce& b, const Lanes& L, const float* const* start, std::size_t n) {
  const Domain& d = b.surface;
  const auto* seg = std::get_if<LineDomain>(&d.shape());
  const bool planar = d.isPlanar() || seg;
  // A segment is a wall standing on the group's plane (bounceParams).
  const cl::FlXyz wall = seg ? bounceParams(b).normal : cl::FlXyz{};
  const Vec3 wallNormal(wall.x, wall.y, wall.z);
  thread_local std::vector<std::uint32_t> nearStore, flagStore;
  std::vector<std::uint32_t>& near = nearStore;
  std::size_t count = n;
  if (planar && n > 0) {
    const Vec3 p00(start[0][0], start[1][0], start[2][0]);
    const Vec3 N = seg ? wallNormal : d.normal(p00);
    const Vec3 P = seg ? seg->p0 : d.closestPoint(p00);
    // How far the exact test's own point on the piece (its closest point) may lie from P.
    float extent = 0.0f;
    if (const auto* x = std::get_if<DiscDomain>(&d.shape())) extent = x->outerRadius;
    if (const auto* x = std::get_if<RectangleDomain>(&d.shape()))
      extent = glm::length(x->u) + glm::length(x->v);
    if (const auto* x = std::get_if<TriangleDomain>(&d.shape()))
      extent = glm::length(x->p1 - x->p0) + glm::length(x->p2 - x->p0);
    if (seg) extent = glm::length(seg->p1 - seg->p0);
    const float reach = std::abs(P.x) + std::abs(P.y) + std::abs(P.z) + extent + 1.0f;
    std::vector<std::uint32_t>& flags = flagStore;
    if (near.size() < n) near.resize(std::max<std::size_t>(n, 1024));
    if (flags.size() < n) flags.resize(near.size());
    std::uint32_t* __restrict flag = flags.data();
    const float *x0 = start[0], *y0 = start[1], *z0 = start[2];
    const float *x1 = L.p[0], *y1 = L.p[1], *z1 = L.p[2];
    for (std::size_t i = 0; i < n; ++i) {
      const float s0 = (x0[i] - P.x) * N.x + (y0[i] - P.y) * N.y + (z0[i] - P.z) * N.z;
      const float s1 = (x1[i] - P.x) * N.x + (y1[i] - P.y) * N.y + (z1[i] - P.z) * N.z;
      const float size = reach + std::abs(x0[i]) + std::abs(y0[i]) + std::abs(z0[i]) +
                         std::abs(x1[i]) + std::abs(y1[i]) + std::abs(z1[i]);
      const float slack = 1e-3f * size;
      // Clearly off the plane at the start, and still on that side by as much at the end
      // (NaN: a candidate).
      const bool clear = std::abs(s0) > slack && (s0 > 0.0f ? s1 : -s1) > slack;
      flag[i] = clear ? 0u : 1u;
    }
    count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      near[count] = std::uint32_t(i);
      count += flag[i];
    }
  }
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = planar ? near[k] : k;
    const Vec3 p0(start[0][i], start[1][i], start[2][i]);
    Vec3 p1(L.p[0][i], L.p[1][i], L.p[2][i]);
    Vec3 nrm, back;
    if (planar) {
      nrm = seg ? wallNormal : d.normal(p0);
      const Vec3 o = seg ? seg->p0 : d.closestPoint(p0);
      Vec3 hit;
      if (!kernel::fl_guard_planar(p0, p1, o, &nrm, &hit, &back)) continue;
      if (!seg && !kernel::fl_guard_on_piece(d.distance(hit), hit)) continue;
    } else {
      if (!kernel::fl_guard_crossed(d.contains(p0), d.contains(p1), b.inside)) continue;
      const Vec3 c = d.closestPoint(p1);
      nrm = d.normal(c);
      back = kernel::fl_guard_solid_back(c, b.inside, &nrm);
    }
    const Vec3 v =
        kernel::fl_guard_reflect(Vec3(L.v[0][i], L.v[1][i], L.v[2][i]), nrm, b.restitution);
    for (int c = 0; c < 3; ++c) {
      L.p[c][i] = back[c];
      L.v[c][i] = v[c];
    }
  }
}

// The reductions over a block (its swept bounds, its live bounds) keep 16 independent lanes
// in values of GCC's and Clang's vector extension: they vectorise without -ffast-math, and no
// lane waits on a store of the last iteration (lanes kept in stack arrays did: 14 % of a
// 1M-particle step with bounds). The 16 lanes are held as vectors of the build's own width
// (one AVX-512 register, two AVX2 ones, four SSE2 ones): GCC lowers a ?: on a vector wider
// than the target's registers element by element, which made the AVX2 build's swept bounds
// ~40 % of a classic fountain's instructions.
constexpr std::size_t kLanes16 = 16;
#if defined(__AVX512F__)
constexpr std::size_t kNativeFloats = 16;
#elif defined(__AVX__)
constexpr std::size_t kNativeFloats = 8;
#else
constexpr std::size_t kNativeFloats = 4;
#endif
constexpr std::size_t kParts = kLanes16 / kNativeFloats;
using Floats = float __attribute__((vector_size(4 * kNativeFloats)));
using Words = std::uint32_t __attribute__((vector_size(4 * kNativeFloats)));
using Ints = std::int32_t __attribute__((vector_size(4 * kNativeFloats)));

// Spatial culling of one block over one sub-step: the block's swept bounds, taken when an
// action with a finite reach is reached and kept until an action that moves particles runs.
struct Culler {
  bool valid = false;
  bool finite = false;  // no NaN or infinity in the block: the bounds mean something
  float lo[3], hi[3];
  float scale = 0.0f;
  std::uint32_t culled = 0;

  // The box the block's straight paths p .. p + v·dt lie in.
  void gather(const Lanes& L, std::size_t n, float dt) {
    constexpr std::size_t W = kLanes16, N = kNativeFloats;
    using F = Floats;
    using U = Words;
    float check = 0.0f;
    scale = 0.0f;
    for (int c = 0; c < 3; ++c) {
      const float* __restrict p = L.p[c];
      const float* __restrict v = L.v[c];
      F mn[kParts], mx[kParts], sp[kParts], ck[kParts];
      for (std::size_t q = 0; q < kParts; ++q) {
        mn[q] = F{} + kInfinity;
        mx[q] = F{} - kInfinity;
        sp[q] = F{};
        ck[q] = F{};
      }
      std::size_t i = 0;
      for (; i + W <= n; i += W) {
        for (std::size_t q = 0; q < kParts; ++q) {
          F x, s;
          std::memcpy(&x, p + i + q * N, sizeof x);
          std::memcpy(&s, v + i + q * N, sizeof s);
          s = (F)((U)s & 0x7fffffffu);  // |v|
          mn[q] = x < mn[q] ? x : mn[q];
          mx[q] = x > mx[q] ? x : mx[q];
          sp[q] = s > sp[q] ? s : sp[q];
          ck[q] += (x - x) + (s - s);  // NaN if x or s is NaN or infinite
        }
      }
      float a = kInfinity, b = -kInfinity, s = 0.0f;
      for (std::size_t j = 0; j < W; ++j, ++i) {
        // The remainder into the lanes it would have had, then the lanes together.
        float lmn = mn[j / N][j % N], lmx = mx[j / N][j % N], lsp = sp[j / N][j % N],
              lck = ck[j / N][j % N];
        if (i < n) {
          const float x = p[i], sv = std::abs(v[i]);
          lmn = x < lmn ? x : lmn;
          lmx = x > lmx ? x : lmx;
          lsp = sv > lsp ? sv : lsp;
          lck += (x - x) + (sv - sv);
        }
        a = std::min(a, lmn);
        b = std::max(b, lmx);
        s = std::max(s, lsp);
        check += lck;
      }
      lo[c] = a - s * dt;
      hi[c] = b + s * dt;
      scale = std::max({scale, std::abs(lo[c]), std::abs(hi[c])});
    }
    finite = check == 0.0f && std::isfinite(scale);
    valid = true;
  }

  // Whether no particle of the block can reach `r` (kernels/math.h, the device's test too).
  bool apart(const ActionPlan::Reach& r) const {
    return finite && kernel::fl_reach_apart(lo, hi, scale, r.lo, r.hi, r.scale, r.quadratic);
  }
};

// What a culled action still does to particles out of its reach (to stay bitwise exact).
void applyCulled(const Action& a, const Lanes& L, std::size_t n, const cpu::BlockContext& c) {
  if (std::holds_alternative<Gravity>(a)) {
    // The kernel's v + a·(dt·w) with w = +0: turns -0 into +0 where a's component is >= +0.
    const float z = c.dt * 0.0f;
    const cl::FlXyz g = c.record().own.gravity.acceleration;
    cpu::addLoop(L.v[0], L.v[1], L.v[2], n, g.x * z, g.y * z, g.z * z);
  } else if (std::holds_alternative<Block>(a) && c.action == c.firstBlocker) {
    std::fill_n(L.visible, n, 1u);  // the first blocker starts from "visible"
  }
}

// The thread's scratch for an integrating Move's stages, and for a Bounce's state before it
// while the group records collisions: reached only where needed (in a shared library each
// reach of a thread_local is a call, and runActions runs a few times a small group's step).
cpu::IntegratorScratch& integratorScratch() {
  thread_local cpu::IntegratorScratch scratch;
  return scratch;
}
cpu::IntegratorScratch& keptScratch() {
  thread_local cpu::IntegratorScratch scratch;
  return scratch;
}

// Runs actions [first, last) of the list over one block, as the plan says; skips those
// that `cull` (null: never) finds out of the block's reach.
void runActions(const std::vector<Action>& acts, const Plan& plan, std::size_t first,
                std::size_t last, const Lanes& lanes, std::size_t n, cpu::BlockContext ctx,
                Culler* cull = nullptr) {
  for (std::size_t k = first; k < last; ++k) {
    ctx.action = std::uint32_t(k);
    if (plan.list.gathered[k]) continue;  // evaluated inside its Move
    if (cull) {
      if (plan.list.reach[k].cullable) {
        if (!cull->valid) cull->gather(lanes, n, ctx.dt);
        if (cull->apart(plan.list.reach[k])) {
          applyCulled(acts[k], lanes, n, ctx);
          ++cull->culled;
          continue;
        }
      }
      if (plan.list.moves[k]) cull->valid = false;  // taken again when next needed
    }
    if (plan.list.integrator != Integrator::SemiImplicitEuler &&
        std::holds_alternative<Move>(acts[k])) {
      cpu::IntegratorScratch& scratch = integratorScratch();
      cpu::withDt(ctx, [&](auto dt) {
        cpu::integrate(plan.list.integrator, acts, plan.list.forcesOf[k], lanes, n, ctx, scratch,
                       dt);
      });
      if (!plan.list.guardsOf[k].empty()) {
        for (std::uint32_t b : plan.list.guardsOf[k])
          guard(std::get<Bounce>(acts[b]), lanes, ctx.stepStart, n);
      }
      continue;
    }
    // While the group records collisions, a Bounce's state before it is kept to find them.
    float* before = nullptr;
    if (ctx.collisions && std::holds_alternative<Bounce>(acts[k])) {
      cpu::IntegratorScratch& keep = keptScratch();
      keep.reset(n, 6);
      before = keep.take(6 * n);
      cpu::keepState(lanes, n, before);
    }
    if (plan.list.curvedBy[k]) {
      // The acceleration the Move's integrator starts from, taken as constant over the step.
      cpu::IntegratorScratch& scratch = integratorScratch();
      scratch.reset(n, 3);
      float* acc[3] = {scratch.take(n), scratch.take(n), scratch.take(n)};
      cpu::startAcceleration(acts, plan.list.forcesOf[plan.list.curvedBy[k] - 1], lanes, n, ctx,
                             acc);
      const Bounce& b = std::get<Bounce>(acts[k]);
      cpu::applyAccelerated(b, lanes, n, ctx, acc);
      if (before) cpu::logCollisions(b, std::uint32_t(k), lanes, n, ctx, before, acc);
      continue;
    }
    std::visit([&](const auto& a) { cpu::apply(a, lanes, n, ctx); }, acts[k]);
    if (before)
      cpu::logCollisions(std::get<Bounce>(acts[k]), std::uint32_t(k), lanes, n, ctx, before,
                         nullptr);
  }
}

// A context for the particles from `by` on: where they began the step, too.
void shiftStart(cpu::BlockContext& c, std::size_t by) {
  for (const float*& s : c.stepStart)
    if (s) s += by;
}

// The thread's room for `count` step lengths (BlockContext::ownDt).
float* ownDtScratch(std::size_t count) {
  thread_local std::vector<float> store;
  std::vector<float>& own = store;  // one TLS lookup
  if (own.size() < count) own.resize(std::max<std::size_t>(count, 1024));
  return own.data();
}

// A newborn's sub-step: its part of the step, `remaining`, in plan.substeps.
float newbornDt(float remaining, const Plan& plan) {
  return float(double(remaining) / double(plan.substeps));
}

// Actions [first, last) of the list over a block's newborns, [0, count) of `lanes`: each
// lives only what is left of the step after its birth (remaining[i]). Most actions run over
// all of them at once with each one's own step length; what depends on the time runs per
// newborn. `ctx` is the sub-step's (sub of plan.substeps).
void runNewborns(const std::vector<Action>& acts, const Plan& plan, std::size_t first,
                 std::size_t last, const Lanes& lanes, std::size_t count,
                 const cpu::BlockContext& ctx, const float* remaining, std::uint32_t sub,
                 double t1) {
  // Each newborn's sub-step length.
  float* const own = ownDtScratch(count);
  for (std::size_t i = 0; i < count; ++i) own[i] = newbornDt(remaining[i], plan);
  cpu::BlockContext batch = ctx;
  batch.ownDt = own;
  for (std::size_t k = first; k < last; ++k) {
    if (plan.list.gathered[k]) continue;  // evaluated inside its Move
    if (plan.list.timeFree[k]) {
      runActions(acts, plan, k, k + 1, lanes, count, ctx);
      continue;
    }
    if (plan.list.ownDt[k]) {
      runActions(acts, plan, k, k + 1, lanes, count, batch);
      continue;
    }
    for (std::size_t i = 0; i < count; ++i) {
      cpu::BlockContext c = ctx;
      c.dt = own[i];
      c.time = (t1 - double(remaining[i])) + double(sub) * double(c.dt);
      c.base += i;
      c.dead += i;
      shiftStart(c, i);
      runActions(acts, plan, k, k + 1, lanes.offset(i), 1, c);
    }
  }
}

// Actions [first, last) over a block [0, m) of `lanes` (group index ctx.base) whose
// particles from `old` on are this step's newborns.
void runBlock(const std::vector<Action>& acts, const Plan& plan, std::size_t first,
              std::size_t last, const Lanes& lanes, std::size_t m, std::size_t old,
              const cpu::BlockContext& ctx, const float* remaining, std::uint32_t sub, double t1,
              Culler* cull = nullptr) {
  if (old == m) return runActions(acts, plan, first, last, lanes, m, ctx, cull);
  if (plan.list.newbornsWithBlock) {
    // One pass, each particle with its own sub-step: the whole one for those that began the
    // step (the arithmetic of a uniform step, bit for bit: both backends compute every
    // action from a particle's own length), what is left of it for the newborns. A small
    // group's few newborns then cost no runs of their own. The culling's swept bounds take
    // the whole sub-step, which covers the newborns' shorter paths.
    float* const own = ownDtScratch(m);
    std::fill_n(own, old, ctx.dt);
    for (std::size_t i = old; i < m; ++i) own[i] = newbornDt(remaining[i - old], plan);
    cpu::BlockContext batch = ctx;
    batch.ownDt = own;
    batch.newbornsFrom = old;
    return runActions(acts, plan, first, last, lanes, m, batch, old > 0 ? cull : nullptr);
  }
  // Newborns (the block's tail from `old` on) are never culled.
  if (old > 0) runActions(acts, plan, first, last, lanes, old, ctx, cull);
  cpu::BlockContext c = ctx;
  c.base += old;
  c.dead += old;
  shiftStart(c, old);
  runNewborns(acts, plan, first, last, lanes.offset(old), m - old, c, remaining, sub, t1);
}

// Whether a float's exponent bits are all ones: NaN or infinite.
inline std::uint32_t nonFinite(std::uint32_t bits) {
  return std::uint32_t((bits & 0x7f800000u) == 0x7f800000u);
}

// Whether any of the three lanes' n floats is NaN or infinite: one reduction with no stores,
// which vectorises (the loop that marks the dead may alias the lanes, and GCC gives it a
// scalar fallback).
bool anyNonFinite(const float* const* lane, std::size_t n) {
  const auto* __restrict x = reinterpret_cast<const std::uint32_t*>(lane[0]);
  const auto* __restrict y = reinterpret_cast<const std::uint32_t*>(lane[1]);
  const auto* __restrict z = reinterpret_cast<const std::uint32_t*>(lane[2]);
  std::uint32_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) bad |= nonFinite(x[i]) | nonFinite(y[i]) | nonFinite(z[i]);
  return bad != 0;
}

// Kills what a step left NaN or infinite (an extreme input, a user callback): counted, never
// propagated. Almost always none is: the lanes are scanned, and marked only when one is.
// Velocities only where the plan says a non-finite one may leave the position finite.
void guardFinite(const Lanes& L, std::size_t n, std::uint32_t* __restrict dead, bool velocity) {
  for (const float* const* lane : {L.p, L.v}) {
    if (lane == L.v && !velocity) break;
    if (!lane[0] || !anyNonFinite(lane, n)) continue;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t* __restrict bits = reinterpret_cast<const std::uint32_t*>(lane[c]);
      for (std::size_t i = 0; i < n; ++i) dead[i] = nonFinite(bits[i]) ? kNonFiniteCode : dead[i];
    }
  }
}

// The box of a block's live positions (the flagged dead left out) into out[0..6): min xyz,
// max xyz, taken while the block is in cache, for Group::bounds. Every live position is
// finite (guardFinite killed the others); a block of dead only gives an empty box.
void liveBounds(const Lanes& L, std::size_t n, const std::uint32_t* __restrict dead, float* out) {
  constexpr std::size_t W = kLanes16, N = kNativeFloats;
  using F = Floats;
  using U = Words;
  using I = Ints;
  const F inf = F{} + kInfinity, ninf = F{} - kInfinity;
  for (int c = 0; c < 3; ++c) {
    const float* __restrict p = L.p[c];
    F mn[kParts], mx[kParts];
    for (std::size_t q = 0; q < kParts; ++q) {
      mn[q] = inf;
      mx[q] = ninf;
    }
    std::size_t i = 0;
    for (; i + W <= n; i += W) {
      for (std::size_t q = 0; q < kParts; ++q) {
        F x;
        U d;
        std::memcpy(&x, p + i + q * N, sizeof x);
        std::memcpy(&d, dead + i + q * N, sizeof d);
        const I live = d == 0u;
        const F lo = live ? x : inf, hi = live ? x : ninf;
        mn[q] = lo < mn[q] ? lo : mn[q];
        mx[q] = hi > mx[q] ? hi : mx[q];
      }
    }
    float lo = kInfinity, hi = -kInfinity;
    for (std::size_t j = 0; j < W; ++j, ++i) {
      // The remainder into the lanes it would have had, then the lanes together.
      float a = mn[j / N][j % N], b = mx[j / N][j % N];
      if (i < n && dead[i] == 0u) {
        a = p[i] < a ? p[i] : a;
        b = p[i] > b ? p[i] : b;
      }
      lo = std::min(lo, a);
      hi = std::max(hi, b);
    }
    out[c] = lo;
    out[3 + c] = hi;
  }
}

// Records a block's dead (ascending) in the block's own slice of deadIndex and clears their
// flags, so that the flags are all zero again for the next block (no fill per block). Few
// die in a step: runs of 16 with none are skipped after one vectorised test, and a run with
// some is walked by the set bits of its mask.
std::uint32_t collectDead(PassScratch& pass, std::size_t base, std::size_t n,
                          std::uint32_t* __restrict dead) {
  constexpr std::size_t kRun = 16;
  std::uint32_t count = 0;
  std::uint32_t* __restrict idx = pass.deadIndex.data() + base;
  std::uint8_t* __restrict code = pass.deadCode.data() + base;
  auto take = [&](std::size_t i) {
    idx[count] = std::uint32_t(base + i);
    code[count] = std::uint8_t(dead[i]);
    dead[i] = 0u;
    ++count;
  };
  // A run of 16 flags is tested as vectors (most runs have none; in a busy effect, where a
  // tenth die, most have some). A run with some is packed without a branch per dead: a loop
  // over its mask's bits mispredicts its end about once a run, which cost more than the rest
  // of the work together where a tenth die. Each store stays inside this block's slices of
  // deadIndex and deadCode: it starts at `count`, at most i0, and ends by i0 + 16 <= n.
  std::size_t i0 = 0;
  for (; i0 + kRun <= n; i0 += kRun) {
#if defined(__AVX512F__)
    const __m512i flags = _mm512_loadu_si512(dead + i0);
    const __mmask16 mask = _mm512_test_epi32_mask(flags, flags);
    if (mask == 0) continue;
    const __m512i at =
        _mm512_add_epi32(_mm512_set1_epi32(int(base + i0)),
                         _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
    // Compressed in a register and stored whole: a compressing store to memory is
    // microcoded on AMD Zen 4 (it was 18 % of the Fountain's step there).
    _mm512_storeu_si512(idx + count, _mm512_maskz_compress_epi32(mask, at));
    const __m512i codes = _mm512_maskz_compress_epi32(mask, flags);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(code + count),
                     _mm512_maskz_cvtepi32_epi8(0xffff, codes));
    _mm512_storeu_si512(dead + i0, _mm512_setzero_si512());
    count += std::uint32_t(std::popcount(unsigned(mask)));
#elif defined(__AVX2__)
    // Per eight flags: the set ones' positions from a table, their indices and codes stored
    // eight at once.
    for (std::size_t h = 0; h < kRun; h += 8) {
      __m256i* flagsAt = reinterpret_cast<__m256i*>(dead + i0 + h);
      const __m256i flags = _mm256_loadu_si256(flagsAt);
      const unsigned bits = ~unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(
                                _mm256_cmpeq_epi32(flags, _mm256_setzero_si256())))) &
                            0xffu;
      if (bits == 0u) continue;
      const __m256i pos = _mm256_cvtepu8_epi32(
          _mm_loadl_epi64(reinterpret_cast<const __m128i*>(&cpu::kSetBitPositions.at[bits])));
      const __m256i at = _mm256_add_epi32(pos, _mm256_set1_epi32(int(base + i0 + h)));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(idx + count), at);
      const __m256i c = _mm256_permutevar8x32_epi32(flags, pos);
      const __m128i w = _mm_packus_epi32(_mm256_castsi256_si128(c), _mm256_extracti128_si256(c, 1));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(code + count), _mm_packus_epi16(w, w));
      _mm256_storeu_si256(flagsAt, _mm256_setzero_si256());
      count += std::uint32_t(std::popcount(bits));
    }
#else
    std::uint32_t mask = 0;
#if defined(__SSE2__)
    __m128i v[4];
    for (std::size_t q = 0; q < 4; ++q)
      v[q] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(dead + i0 + 4 * q));
    const __m128i o = _mm_or_si128(_mm_or_si128(v[0], v[1]), _mm_or_si128(v[2], v[3]));
    if (_mm_movemask_epi8(_mm_cmpeq_epi32(o, _mm_setzero_si128())) == 0xffff) continue;
    for (std::size_t q = 0; q < 4; ++q) {
      const __m128 z = _mm_castsi128_ps(_mm_cmpeq_epi32(v[q], _mm_setzero_si128()));
      mask |= (~std::uint32_t(_mm_movemask_ps(z)) & 0xfu) << (4 * q);
    }
#else
    for (std::size_t j = 0; j < kRun; ++j) mask |= std::uint32_t(dead[i0 + j] != 0u) << j;
    if (mask == 0u) continue;
#endif
    for (; mask != 0u; mask &= mask - 1u) take(i0 + std::size_t(std::countr_zero(mask)));
#endif
  }
  for (std::size_t i = i0; i < n; ++i)
    if (dead[i] != 0u) take(i);
  return count;
}

// The dead flags of a thread's blocks.
struct DeadFlags {
  std::vector<std::uint32_t> flags;
  bool clean = true;
  std::vector<float> start;  ///< the block's positions at the step's start (a guarded list)
};

// Blocks the back of the filling walk takes at a time (a few: the front waits for the first).
constexpr std::size_t kBackBlocks = 8;

// The pass's blocks, handed out from both ends: [lo, hi) are not taken yet. One word, so that
// a take from either end is one compare-and-swap.
class BlockEnds {
 public:
  explicit BlockEnds(std::size_t blocks) : ends_(std::uint64_t(blocks) << 32) {}
  /// The lowest block not taken; false when none is left.
  bool takeFront(std::size_t& b) {
    std::uint64_t e = ends_.load(std::memory_order_relaxed);
    do {
      if (lo(e) >= hi(e)) return false;
    } while (!ends_.compare_exchange_weak(e, e + 1, std::memory_order_relaxed));
    b = lo(e);
    return true;
  }
  /// The highest `most` blocks not taken (fewer where fewer are left), as [b, b + count);
  /// false when none is left.
  bool takeBack(std::size_t most, std::size_t& b, std::size_t& count) {
    std::uint64_t e = ends_.load(std::memory_order_relaxed);
    do {
      if (lo(e) >= hi(e)) return false;
      count = std::min(most, hi(e) - lo(e));
    } while (!ends_.compare_exchange_weak(e, e - (std::uint64_t(count) << 32),
                                          std::memory_order_relaxed));
    b = hi(e) - count;
    return true;
  }
  /// Takes block b from the back if it is the highest not taken (and above the front's);
  /// false if another worker has it already.
  bool takeBackAt(std::size_t b) {
    std::uint64_t e = ends_.load(std::memory_order_relaxed);
    do {
      if (hi(e) != b + 1 || lo(e) > b) return false;
    } while (
        !ends_.compare_exchange_weak(e, e - (std::uint64_t(1) << 32), std::memory_order_relaxed));
    return true;
  }

 private:
  static std::size_t lo(std::uint64_t e) { return std::size_t(e & 0xffffffffu); }
  static std::size_t hi(std::uint64_t e) { return std::size_t(e >> 32); }
  std::atomic<std::uint64_t> ends_;
};

// The blocks [0, blocks) run by `workers` threads (runOne(b)) so that the step's holes are
// closed while each block is still in cache: the first worker takes blocks from the front and,
// after each, moves into its holes the highest live particles, from the blocks the others take
// from the back (it runs such a block itself when none has taken it, as one thread alone
// does). Those are compact()'s moves, in its order (the lowest hole takes the last live
// particle), made here instead of in a pass of their own that would read and write every lane
// again; the front stops filling where it meets the back (a hole whose filler would be below
// it, or in its own block) and leaves compact() the rest (GroupImpl::holesFilled). Which
// worker ran a block changes nothing: the result is the same on any number of threads.
template <class RunOne>
void fillingWalk(GroupImpl& g, PassScratch& pass, std::size_t B, std::size_t blocks,
                 std::size_t workers, ThreadPool& pool, RunOne&& runOne) {
  assignFill(pass.blockDone, blocks, 0u);
  BlockEnds ends(blocks);
  std::atomic<bool> failed{false};  // a worker's block threw: nothing more to wait for
  auto markDone = [&](std::size_t b) {
    std::atomic_ref<std::uint32_t>(pass.blockDone[b]).store(1u, std::memory_order_release);
  };
  auto front = [&] {
    const std::size_t n = g.size;
    StoredLanes stored;
    const std::size_t laneCount = storedLanes(g, stored);
    std::uint32_t* const fillers = pass.spare.data();  // (room for a block: actFusedImpl)
    // The fillers come from block c down, the next candidate below index i; its dead (the
    // block's, ascending) are dead[0, k).
    std::size_t c = blocks, i = 0, first = 0, lo = 0;
    const std::uint32_t* dead = nullptr;
    std::uint32_t k = 0;
    // Whether block b (above the front's) has run, running it here if no one has taken it.
    auto ready = [&](std::size_t b) {
      if (ends.takeBackAt(b)) {
        runOne(b);
        return true;
      }
      std::atomic_ref<std::uint32_t> done(pass.blockDone[b]);
      for (unsigned spins = 0; done.load(std::memory_order_acquire) == 0u; ++spins) {
        if (failed.load(std::memory_order_relaxed)) return false;
        if (spins > 64) std::this_thread::yield();
      }
      return true;
    };
    auto nextFiller = [&](std::uint32_t& f) {
      for (;;) {
        while (i > first) {
          --i;
          if (k > 0 && dead[k - 1] == i) {
            --k;
            continue;
          }
          f = std::uint32_t(i);
          return true;
        }
        if (c <= lo + 1 || !ready(c - 1)) return false;  // the next block down is the front's
        --c;
        first = c * B;
        i = std::min(n, first + B);
        dead = pass.deadIndex.data() + first;
        k = pass.deadCount[c];
      }
    };
    bool filling = true;
    std::uint32_t filled = 0, from = 0;
    while (ends.takeFront(lo)) {
      runOne(lo);
      if (!filling) continue;
      const std::uint32_t* holes = pass.deadIndex.data() + lo * B;
      // The block's fillers first, then lane by lane: one stream at a time (the lanes the
      // actions did not touch are not in cache).
      std::uint32_t m = 0;
      for (const std::uint32_t count = pass.deadCount[lo]; m < count; ++m)
        if (!nextFiller(fillers[m])) {
          filling = false;
          break;
        }
      for (std::size_t l = 0; l < laneCount; ++l) {
        std::uint32_t* __restrict lane = stored[l];
        for (std::uint32_t j = 0; j < m; ++j) lane[holes[j]] = lane[fillers[j]];
      }
      if (m > 0) from = fillers[m - 1];
      filled += m;
    }
    g.holesFilled = filled;
    g.filledFrom = from;
    g.filledByPass += filled;
  };
  // The others take a few blocks at a time and run them upwards, as the memory streams best;
  // the front waits at most that long for its first fillers.
  auto back = [&] {
    std::size_t b = 0, count = 0;
    while (ends.takeBack(kBackBlocks, b, count)) {
      for (std::size_t j = b; j < b + count; ++j) {
        try {
          runOne(j);
        } catch (...) {
          failed.store(true, std::memory_order_relaxed);
          throw;
        }
        markDone(j);
      }
    }
  };
  pool.parallelFor(workers, [&](std::size_t w) { w == 0 ? front() : back(); });
}

}  // namespace

void actFusedImpl(GroupImpl& g, const StepParams& sp) {
  const bool diedBefore = !g.holes.empty();  // (the last step's dead)
  g.holes.clear();
  g.holesFilled = 0;
  g.trailRecorded = false;  // until the pass below records them
  const std::size_t n = g.size;
  // At most n die: room for all of them, grown geometrically, so that a step that kills
  // more than any before does not allocate.
  if (g.holes.capacity() < n) g.holes.reserve(std::max(n, 2 * g.holes.capacity()));
  const auto& acts = g.actions.actions();
  if (n == 0 || acts.empty()) return;

  const std::size_t B = sp.blockSize ? sp.blockSize : kDefaultBlock;
  const std::size_t blocks = (n + B - 1) / B;
  const std::size_t blocksPerTask = std::max<std::size_t>(1, kParticlesPerTask / B);
  const std::size_t tasks = (blocks + blocksPerTask - 1) / blocksPerTask;
  const PassScratchUse scratch(g);
  PassScratch& pass = *scratch;
  pass.deadIndex.resize(n);
  pass.deadCode.resize(n);
  assignFill(pass.deadCount, blocks, 0);
  assignFill(pass.culledCount, blocks, 0);
  const std::size_t killSlots = acts.size() + 1;  // the last: non-finite
  assignFill(pass.blockKills, blocks * killSlots, 0);
  // Tallies a block's dead by cause (codes: 1 + action, or kNonFiniteCode).
  auto tally = [&](std::size_t b, std::uint32_t k) {
    std::uint32_t* kills = pass.blockKills.data() + b * killSlots;
    const std::uint8_t* code = pass.deadCode.data() + b * B;
    for (std::uint32_t j = 0; j < k; ++j)
      ++kills[code[j] == kNonFiniteCode ? killSlots - 1 : code[j] - 1u];
  };
  const Lanes lanes = g.lanePointers();
  const bool bounds = g.boundsWanted && lanes.p[0];
  if (bounds) pass.blockBounds.resize(6 * blocks);  // grows, never shrinks
  const Plan plan{planActions(g), substepCount(g, sp, *sp.pool)};
  if (plan.list.guarded && !sp.fused) {
    // Where each particle began the step: the guard compares with it. (The fused pass keeps
    // each block's own while the block is in cache.)
    pass.stepStart.resize(3 * n);
    for (int c = 0; c < 3; ++c) std::copy_n(lanes.p[c], n, pass.stepStart.data() + c * n);
  }
  const float subDt = float(sp.dt / plan.substeps);
  cpu::BlockContext base{subDt, sp.seed, std::uint32_t(sp.step), g.streamKey() << 16, 0, nullptr};
  base.time = sp.time;
  base.firstBlocker = plan.list.firstBlocker;
  base.records = actionRecords(g, subDt);
  // Actions that read other particles read them as they were at the start of the step, so
  // the result does not depend on which block ran first.
  cpu::Snapshot snapshot;
  if (plan.list.readsNeighbours) {
    g.snapshot.resize(9 * n);
    float* out = g.snapshot.data();
    auto keep = [&](float* const* src, const float** dst) {
      for (int d = 0; d < 3; ++d, out += n) {
        if (!src[d]) continue;
        std::copy_n(src[d], n, out);
        dst[d] = out;
      }
    };
    keep(lanes.p, snapshot.p);
    keep(lanes.v, snapshot.v);
    keep(lanes.rot, snapshot.rot);
    snapshot.size = n;
    base.snapshot = &snapshot;
  }
  // This step's newborns are [bornFirst, n), and newborn r lives remaining[r] of it.
  const std::size_t bornFirst = g.bornCount > 0 ? g.bornFirst : n;
  const float* const remaining = g.bornRemaining.data();
  const double t1 = sp.end;
  // Of a block starting at `first` of m particles, how many come before the newborns; and
  // where the block's newborns' remaining times are.
  auto oldIn = [&](std::size_t first, std::size_t m) {
    return first < bornFirst ? std::min(m, bornFirst - first) : std::size_t(0);
  };
  auto remainingAt = [&](std::size_t first, std::size_t old) {
    return remaining ? remaining + (first + old - std::min(bornFirst, first + old)) : nullptr;
  };
  // Sub-step s draws its own random numbers: the substep number goes into the stream.
  auto atSubstep = [&](cpu::BlockContext c, std::uint32_t s) {
    c.time = sp.time + double(s) * double(subDt);
    c.streamBase += s << 8;
    return c;
  };

  // Culling needs velocities for the swept bounds (a list that moves nothing has none).
  const bool cull = sp.cull && plan.list.cullable && lanes.v[0];
  const bool logHits = g.collisionRoom() > 0 && lanes.v[0];
  if (logHits) g.beginCollisions(blocks);
  // Trails: each block's positions go into the ring's next slot while the block is in cache
  // (recordTrails then only turns the ring; compaction moves the slot with the rest).
  float* trailSlot[3] = {};
  std::uint32_t* const trailCount = sp.fused ? g.nextTrailSlot(trailSlot) : nullptr;
  const std::uint32_t trailMost = g.trail.length;
  if (sp.fused) {
    // A block through the whole list, then what is taken while it is in cache: its guard
    // against non-finite values, its trail slot, its bounds, its dead. The dead flags are all
    // zero between blocks (collectDead clears what it takes); filled again only after a
    // block that did not finish (an action threw).
    auto runOne = [&](std::size_t b, DeadFlags& store) {
      std::vector<std::uint32_t>& dead = store.flags;
      if (dead.size() < B) dead.resize(B);
      const std::size_t first = b * B, m = std::min(B, n - first);
      cpu::BlockContext ctx = base;
      ctx.base = first;
      if (!store.clean) std::fill(dead.begin(), dead.end(), 0u);
      store.clean = false;
      ctx.dead = dead.data();
      const Lanes blockLanes = lanes.offset(first);
      if (plan.list.guarded) {
        if (store.start.size() < 3 * B) store.start.resize(3 * B);
        for (int c = 0; c < 3; ++c) {
          std::copy_n(blockLanes.p[c], m, store.start.data() + c * B);
          ctx.stepStart[c] = store.start.data() + c * B;
        }
      }
      const std::size_t old = oldIn(first, m);
      cpu::CollisionLog log{&g, b, t1, plan.substeps, 0};
      ctx.collisions = logHits ? &log : nullptr;
      for (std::uint32_t s = 0; s < plan.substeps; ++s) {
        log.sub = s;
        Culler culler;  // the sub-step's own bounds
        runBlock(acts, plan, 0, acts.size(), blockLanes, m, old, atSubstep(ctx, s),
                 remainingAt(first, old), s, t1, cull ? &culler : nullptr);
        pass.culledCount[b] += culler.culled;
      }
      guardFinite(blockLanes, m, dead.data(), plan.list.guardVelocity);
      if (trailCount) {
        for (int c = 0; c < 3; ++c) std::copy_n(blockLanes.p[c], m, trailSlot[c] + first);
        std::uint32_t* __restrict count = trailCount + first;
        for (std::size_t i = 0; i < m; ++i) count[i] = std::min(count[i] + 1u, trailMost);
      }
      if (bounds) liveBounds(blockLanes, m, dead.data(), pass.blockBounds.data() + 6 * b);
      pass.deadCount[b] = collectDead(pass, first, m, dead.data());
      tally(b, pass.deadCount[b]);
      store.clean = true;
    };
    // The pass fills the holes as it goes (fillingWalk), unless the dead must stay in place
    // for their death events, or a user's action could throw midway (the group would keep a
    // particle twice). Threads that share a group out walk it so only where particles died
    // in the last step: where none die, each takes its own run of blocks, as the memory
    // streams best. (Either way the particles end in the same places.)
    const bool alone = sp.pool->size() == 1 || tasks == 1;
    const bool fill = blocks > 1 && (alone || diedBefore) && g.deathRoom() == 0 &&
                      std::none_of(acts.begin(), acts.end(), [](const Action& a) {
                        return std::holds_alternative<Callback>(a);
                      });
    if (fill) {
      if (pass.spare.size() < B) pass.spare.resize(B);  // grows, never shrinks
      // A group of one task's blocks is walked by one thread, as it would be stepped.
      const std::size_t workers = alone ? 1 : std::min<std::size_t>(sp.pool->size(), blocks);
      fillingWalk(g, pass, B, blocks, workers, *sp.pool, [&](std::size_t b) {
        thread_local DeadFlags deadStore;
        runOne(b, deadStore);
      });
    } else {
      sp.pool->parallelFor(tasks, [&](std::size_t t) {
        thread_local DeadFlags deadStore;
        DeadFlags& store = deadStore;  // one TLS lookup, not one per use
        const std::size_t end = std::min(blocks, (t + 1) * blocksPerTask);
        for (std::size_t b = t * blocksPerTask; b < end; ++b) runOne(b, store);
      });
    }
  } else {
    // The unfused baseline: one parallel pass over the whole group per action.
    assignFill(g.deadFlags, n, 0u);
    for (std::uint32_t s = 0; s < plan.substeps; ++s) {
      for (std::size_t k = 0; k < acts.size(); ++k) {
        sp.pool->parallelFor(tasks, [&](std::size_t t) {
          const std::size_t end = std::min(blocks, (t + 1) * blocksPerTask);
          for (std::size_t b = t * blocksPerTask; b < end; ++b) {
            const std::size_t first = b * B, m = std::min(B, n - first);
            cpu::BlockContext ctx = base;
            ctx.base = first;
            ctx.dead = g.deadFlags.data() + first;
            if (plan.list.guarded)
              for (int c = 0; c < 3; ++c) ctx.stepStart[c] = pass.stepStart.data() + c * n + first;
            cpu::CollisionLog log{&g, b, t1, plan.substeps, s};
            ctx.collisions = logHits ? &log : nullptr;
            const std::size_t old = oldIn(first, m);
            runBlock(acts, plan, k, k + 1, lanes.offset(first), m, old, atSubstep(ctx, s),
                     remainingAt(first, old), s, t1);
          }
        });
      }
    }
    sp.pool->parallelFor(blocks, [&](std::size_t b) {
      const std::size_t first = b * B, m = std::min(B, n - first);
      guardFinite(lanes.offset(first), m, g.deadFlags.data() + first, plan.list.guardVelocity);
      if (bounds)
        liveBounds(lanes.offset(first), m, g.deadFlags.data() + first,
                   pass.blockBounds.data() + 6 * b);
      pass.deadCount[b] = collectDead(pass, first, m, g.deadFlags.data() + first);
      tally(b, pass.deadCount[b]);
    });
  }

  for (std::size_t b = 0; b < blocks; ++b) {
    g.stats.blockActionsCulled += pass.culledCount[b];
    const std::uint32_t* idx = pass.deadIndex.data() + b * B;
    g.holes.insert(g.holes.end(), idx, idx + pass.deadCount[b]);  // within the capacity
  }
  if (g.deathRoom() > 0) g.recordDeaths(pass, B, blocks, sp.end, *sp.pool);
  if (logHits) g.endCollisions(blocks);
  if (bounds) {
    Bounds& box = g.stepBounds;
    box.min = Vec3(kInfinity);
    box.max = Vec3(-kInfinity);
    for (std::size_t b = 0; b < blocks; ++b)
      for (int c = 0; c < 3; ++c) {
        box.min[c] = std::min(box.min[c], pass.blockBounds[6 * b + c]);
        box.max[c] = std::max(box.max[c], pass.blockBounds[6 * b + 3 + c]);
      }
    box.empty = !(box.min.x <= box.max.x);  // every particle died (the group is empty then)
    g.boundsValid = true;
  }
  for (std::size_t a = 0; a < killSlots; ++a) {
    std::uint64_t killed = 0;
    for (std::size_t b = 0; b < blocks; ++b) killed += pass.blockKills[b * killSlots + a];
    if (killed == 0) continue;
    if (a == killSlots - 1)
      g.stats.killedNonFinite += killed;
    else {
      g.stats.killedByAction[a] += killed;
      (std::holds_alternative<KillOld>(acts[a]) ? g.stats.killedByAge : g.stats.absorbed) += killed;
    }
  }
}

}  // namespace flurry::detail::FLURRY_ISA
