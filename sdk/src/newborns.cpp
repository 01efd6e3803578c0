// Writing a step's newborns into the group's lanes: every draw of a batch at once, sampled
// by the vectorised shapes of sampling.cpp. Compiled once per instruction set, like the fused
// pass (sdk/CMakeLists.txt), and picked at run time (cpu/dispatch.cpp): random numbers and
// shapes are compute-bound, and AVX2 doubles their width.
#include <algorithm>
#include <cmath>
#include <memory>

#include "emission_plan.hpp"
#include "isa_namespace.hpp"
#include "kernel_compat.hpp"
#include "sampling.hpp"

#ifndef FLURRY_ISA
#define FLURRY_ISA baseline
#endif

namespace flurry::detail::FLURRY_ISA {

namespace {

constexpr std::size_t kNewbornsPerTask = 8192;  // a multiple of kBatch

constexpr std::size_t kBatch = 256;
// The floats in this build's widest vector: a batch is drawn and shaped in whole ones.
constexpr std::size_t kVector = FLURRY_ISA_FLOATS;
static_assert(kBatch % kVector == 0, "a batch pads its newborns to whole vectors");
// The most draws a newborn takes (kernels/newborn.h): its type's, five domains of at most
// kMaxDomainDraws each and six fuzzy values of at most two.
constexpr int kMaxDraws = 1 + 5 * kMaxDomainDraws + 6 * 2;

struct NewbornContext {
  GroupImpl& g;
  Lanes L;
  const StepParams& sp;
  double t1;              // end of the step
  std::uint32_t firstId;  // id of newborn 0 of this step
  std::size_t oldSize;    // newborn i is in slot oldSize + i
  float* remaining;       // newborn i lives remaining[i] of this step

  std::size_t slot(std::size_t i) const { return oldSize + i; }
  // What is left of the step after a birth at tb.
  float left(double tb) const { return float(std::max(0.0, t1 - tb)); }
};

// One newborn, where and as it was born.
struct Newborn {
  Vec3 pos, vel;
  float lifetime, r, gr, bl, alpha, size, mass, charge;
  Vec3 up, rot;
};

// What the curves over life scale: the colour and size just stored (Particle's defaults for
// a lane not stored).
void storeBirth(const Lanes& L, std::size_t slot) {
  for (int c = 0; c < 4; ++c)
    if (L.birthColor[c]) L.birthColor[c][slot] = L.color[c] ? L.color[c][slot] : 1.0f;
  if (L.birthSize) L.birthSize[slot] = L.size ? L.size[slot] : Particle().size;
}

void store(const NewbornContext& nc, std::size_t slot, std::uint32_t id, const Newborn& b) {
  const Lanes& L = nc.L;
  for (int c = 0; c < 3; ++c) {
    L.p[c][slot] = b.pos[c];
    if (L.v[c]) L.v[c][slot] = b.vel[c];
    if (L.prev[c]) L.prev[c][slot] = b.pos[c];
    // A newborn's rest pose is where it was born, still (as ensureStorage gives a new lane).
    if (L.posB[c]) L.posB[c][slot] = b.pos[c];
    if (L.velB[c]) L.velB[c][slot] = 0.0f;
    if (L.up[c]) L.up[c][slot] = b.up[c];
    if (L.rot[c]) L.rot[c][slot] = b.rot[c];
  }
  if (L.lifetime) L.lifetime[slot] = std::max(b.lifetime, 0.0f);
  if (L.color[0]) {
    L.color[0][slot] = b.r;
    L.color[1][slot] = b.gr;
    L.color[2][slot] = b.bl;
    L.color[3][slot] = b.alpha;
  }
  if (L.size) L.size[slot] = std::max(b.size, 0.0f);
  storeBirth(L, slot);
  if (L.mass) L.mass[slot] = b.mass;
  if (L.charge) L.charge[slot] = b.charge;
  if (L.age) L.age[slot] = 0.0f;
  L.id[slot] = id;
  if (L.visible) L.visible[slot] = 1u;
  if (L.user) L.user[slot] = 0.0f;
}

// Where a newborn of `type` from `em` starts each value's draws: the draw counts of what the
// group stores, in kernels/newborn.h's order (the device's too).
kernel::FlNewbornDraws newbornDraws(const Lanes& L, const Emitter& em, const ParticleType& type) {
  const bool alongNormal = !(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f);
  // (a domain's count is a visit: taken only for what is stored)
  auto n = [](bool stored, const auto& value) {
    return kernel::uint(stored ? drawCount(value) : 0);
  };
  return kernel::fl_newborn_draws(
      em.types.size() > 1 ? 1u : 0u, n(true, type.velocity), n(true, em.shape),
      n(alongNormal, em.normalSpeed), n(L.lifetime, type.lifetime), n(L.color[0], type.color),
      n(L.color[0], type.alpha), n(L.size, type.size), n(L.mass, type.mass),
      n(L.charge, type.charge), n(L.up[0], type.up), n(L.rot[0], type.rotVelocity));
}

// Adds where a path emitter was at each birth time t[0..m) to p: a search for the key's
// segment of a birth, then the births after it inside that segment in one loop (the same
// kernels/path.h interpolation pathPositionAt takes, so bitwise the same place). A step's
// births come in increasing time, so a segment's are consecutive; births at or before the
// first key, at or after the last, or wrapping around a loop go one by one.
void placeOnPath(const Emitter& em, const double* t, std::size_t m, float* px, float* py,
                 float* pz) {
  const std::vector<Keyframe>& path = em.path;
  std::size_t key = 0;  // the path's key the last birth found
  for (std::size_t k = 0; k < m;) {
    const Vec3 e = pathPositionAt(em, t[k], key);
    px[k] += e.x;
    py[k] += e.y;
    pz[k] += e.z;
    ++k;
    if (key == 0 || key >= path.size()) continue;
    const double ta = path[key - 1].time, tz = path[key].time, first = path.front().time;
    const Vec3 a = path[key - 1].position, b = path[key].position;
    std::size_t end = k;
    while (end < m && t[end] >= ta && t[end] < tz && t[end] > first) ++end;
    for (; k < end; ++k) {
      const Vec3 q = kernel::fl_path_between(t[k], ta, a, tz, b);
      px[k] += q.x;
      py[k] += q.y;
      pz[k] += q.z;
    }
  }
}

// birthTime for births q0 .. q0 + m of a run, in vector loops: the run's kind chosen once.
void birthTimes(const BirthRun& run, const Emitter& em, std::uint64_t q0, std::size_t m,
                double* __restrict tb) {
  switch (run.kind) {
    case BirthRun::Rate: {
      const double first = double(run.first + q0 + 1);
      for (std::size_t k = 0; k < m; ++k)
        tb[k] = rateBirthTime(em, first + double(std::uint32_t(k)));
      return;
    }
    case BirthRun::Burst:
      std::fill_n(tb, m, run.time);
      return;
    default: {
      const double q = double(q0);
      for (std::size_t k = 0; k < m; ++k)
        tb[k] = distanceBirthTime(run, q + double(std::uint32_t(k)));
      return;
    }
  }
}

// Emitters with one particle type: every draw of a batch at once (see sampling.hpp).
void emitBatch(const NewbornContext& nc, const BirthRun& run, const Emitter& em, std::uint64_t q0,
               std::size_t i0, std::size_t m) {
  const Lanes& L = nc.L;
  const ParticleType& type = em.types[0];
  // Scratch per thread, on the heap and reached through a pointer read once: in a shared
  // library every access to a thread_local object goes through __tls_get_addr, and GCC
  // folds a reference to one back into such accesses, once per element of the loops below.
  struct Scratch {
    float rows[kMaxDraws][kBatch];
    float attr[16][kBatch];
    float up[3][kBatch], rot[3][kBatch];
    float age[kBatch];    // zeros
    double time[kBatch];  // birth times
  };
  thread_local std::unique_ptr<Scratch> scratch;
  if (!scratch) scratch = std::make_unique<Scratch>();  // once per thread
  Scratch& sc = *scratch;
  auto& rows = sc.rows;
  auto& attr = sc.attr;
  auto& up = sc.up;
  auto& rot = sc.rot;
  auto& age = sc.age;
  const float* row[kMaxDraws];
  for (int k = 0; k < kMaxDraws; ++k) row[k] = rows[k];

  const bool alongNormal = !(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f);
  const kernel::FlNewbornDraws at = newbornDraws(L, em, type);
  const int draws = int(at.total);
  const std::uint32_t firstId = nc.firstId + std::uint32_t(i0);
  // Drawn and shaped in whole vectors (of this build's width: 16 floats would cost an AVX2
  // build twice the work): a small group's few newborns a step then run the vector loops
  // alone, not their scalar remainders. Each newborn's values depend on its own draws only;
  // the extra lanes are never stored.
  const std::size_t mv = std::min(kBatch, (m + kVector - 1) / kVector * kVector);
  for (int blk = 0; blk * 4 < draws; ++blk)
    uniformBatch(nc.sp.seed, firstId, nc.g.streamKey(), stream::kEmission, std::uint32_t(blk), mv,
                 rows[4 * blk], rows[4 * blk + 1], rows[4 * blk + 2], rows[4 * blk + 3]);

  auto vec = [&](const Domain& d, kernel::uint from, int a) {
    sampleBatch(d, row + from, mv, attr[a], attr[a + 1], attr[a + 2]);
  };
  auto scalar = [&](const Fuzzy& f, kernel::uint from, int a) {
    sampleBatch(f, row + from, mv, attr[a]);
  };
  vec(type.velocity, at.velocity, 0);  // attr 0-2
  vec(em.shape, at.shape, 3);          // 3-5
  if (alongNormal) {
    // Every face emits along its normal: the shape's normal where the particle was born.
    scalar(em.normalSpeed, at.normal, 15);
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 nrm = em.shape.normal(Vec3(attr[3][k], attr[4][k], attr[5][k]));
      for (int d = 0; d < 3; ++d) attr[d][k] += nrm[d] * attr[15][k];
    }
  }
  if (L.lifetime) scalar(type.lifetime, at.lifetime, 6);
  if (L.color[0]) {
    vec(type.color, at.color, 7);  // 7-9
    scalar(type.alpha, at.alpha, 10);
  }
  if (L.size) scalar(type.size, at.size, 11);
  if (L.mass) scalar(type.mass, at.mass, 12);
  if (L.charge) scalar(type.charge, at.charge, 13);
  if (L.up[0]) sampleBatch(type.up, row + at.up, mv, up[0], up[1], up[2]);
  if (L.rot[0]) sampleBatch(type.rotVelocity, row + at.rot, mv, rot[0], rot[1], rot[2]);

  // Birth places: where the emitter was at the birth time; and the time left of the step.
  float* const px = attr[3];
  float* const py = attr[4];
  float* const pz = attr[5];
  double* const tb = sc.time;
  birthTimes(run, em, q0, m, tb);
  for (std::size_t k = 0; k < m; ++k) {
    nc.remaining[i0 + k] = nc.left(tb[k]);
    age[k] = 0.0f;
  }
  if (em.path.empty()) {
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 e = kernel::fl_path_linear(em.position, em.velocity, em.start, tb[k]);
      px[k] += e.x;
      py[k] += e.y;
      pz[k] += e.z;
    }
  } else {
    placeOnPath(em, tb, m, px, py, pz);
  }
  // Into the batch's slots (consecutive), one lane at a time.
  const std::size_t first = nc.slot(i0);
  auto put = [&](float* lane, const float* src) {
    if (lane) std::copy_n(src, m, lane + first);
  };
  auto putNonNegative = [&](float* lane, float* src) {
    if (!lane) return;
    for (std::size_t k = 0; k < m; ++k) src[k] = std::max(src[k], 0.0f);
    put(lane, src);
  };
  for (int c = 0; c < 3; ++c) {
    put(L.p[c], attr[3 + c]);
    put(L.v[c], attr[c]);
    put(L.prev[c], attr[3 + c]);
    put(L.posB[c], attr[3 + c]);
    if (L.velB[c]) std::fill_n(L.velB[c] + first, m, 0.0f);
    put(L.up[c], up[c]);
    put(L.rot[c], rot[c]);
  }
  putNonNegative(L.lifetime, attr[6]);
  for (int c = 0; c < 4; ++c) put(L.color[c], attr[7 + c]);
  putNonNegative(L.size, attr[11]);
  put(L.mass, attr[12]);
  put(L.charge, attr[13]);
  put(L.age, age);
  if (L.birthColor[0] || L.birthSize)
    for (std::size_t k = 0; k < m; ++k) storeBirth(L, first + k);
  for (std::size_t k = 0; k < m; ++k) L.id[first + k] = firstId + std::uint32_t(k);
  if (L.visible) std::fill_n(L.visible + first, m, 1u);
  if (L.user) std::fill_n(L.user + first, m, 0.0f);
}

// Several particle types: each newborn picks its type with its first draw, then takes its
// values from its draws as emitBatch does (a batch of one).
void emitOneByOne(const NewbornContext& nc, const BirthRun& run, const Emitter& em,
                  std::uint64_t q0, std::size_t i0, std::size_t m) {
  const Lanes& L = nc.L;
  std::size_t key = 0;  // the path's key the last birth found
  float u[kMaxDraws];
  const float* row[kMaxDraws];
  for (int d = 0; d < kMaxDraws; ++d) row[d] = u + d;
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t id = nc.firstId + std::uint32_t(i0 + k);
    Random rng(nc.sp.seed, id, nc.g.streamKey(), stream::kEmission);
    const float pick = rng.uniform();
    const ParticleType& type = em.types[chooseType(em.types, pick)];
    const kernel::FlNewbornDraws at = newbornDraws(L, em, type);
    u[at.type] = pick;
    for (kernel::uint d = at.type + 1; d < at.total; ++d) u[d] = rng.uniform();
    const double tb = birthTime(run, em, q0 + k);
    nc.remaining[i0 + k] = nc.left(tb);
    Newborn b{};
    auto vec = [&](const Domain& dom, kernel::uint from) {
      Vec3 r;
      sampleBatch(dom, row + from, 1, &r.x, &r.y, &r.z);
      return r;
    };
    auto scalar = [&](const Fuzzy& f, kernel::uint from) {
      float r;
      sampleBatch(f, row + from, 1, &r);
      return r;
    };
    b.vel = vec(type.velocity, at.velocity);
    const Vec3 local = vec(em.shape, at.shape);
    if (!(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f))
      b.vel += em.shape.normal(local) * scalar(em.normalSpeed, at.normal);
    b.pos = local + pathPositionAt(em, tb, key);
    if (L.lifetime) b.lifetime = scalar(type.lifetime, at.lifetime);
    if (L.color[0]) {
      const Vec3 rgb = vec(type.color, at.color);
      b.r = rgb.x;
      b.gr = rgb.y;
      b.bl = rgb.z;
      b.alpha = scalar(type.alpha, at.alpha);
    }
    if (L.size) b.size = scalar(type.size, at.size);
    if (L.mass) b.mass = scalar(type.mass, at.mass);
    if (L.charge) b.charge = scalar(type.charge, at.charge);
    if (L.up[0]) b.up = vec(type.up, at.up);
    if (L.rot[0]) b.rot = vec(type.rotVelocity, at.rot);
    store(nc, nc.slot(i0 + k), id, b);
  }
}

}  // namespace

void writeNewborns(GroupImpl& g, const StepParams& sp, const BirthRun* runs,
                   const std::uint64_t* runStart, std::size_t runCount, std::size_t accepted) {
  const double t1 = sp.time + sp.dt;
  NewbornContext nc{g, g.lanePointers(), sp, t1, g.nextId, g.size, g.bornRemaining.data()};
  const std::size_t tasks = (accepted + kNewbornsPerTask - 1) / kNewbornsPerTask;
  sp.pool->parallelFor(tasks, [&](std::size_t task) {
    const std::size_t a = task * kNewbornsPerTask;
    const std::size_t b = std::min(accepted, a + kNewbornsPerTask);
    std::size_t r =
        std::size_t(std::upper_bound(runStart, runStart + runCount + 1, a) - runStart) - 1;
    // Split the task at run boundaries: a batch shares one emitter and birth rule.
    for (std::size_t i = a; i < b;) {
      while (i >= runStart[r + 1]) ++r;
      const std::size_t end = std::min<std::size_t>(b, runStart[r + 1]);
      const Emitter& em = emitterOf(g, runs[r]);
      for (std::size_t j = i; j < end; j += kBatch) {
        const std::size_t m = std::min(kBatch, end - j);
        if (em.types.size() == 1)
          emitBatch(nc, runs[r], em, j - runStart[r], j, m);
        else
          emitOneByOne(nc, runs[r], em, j - runStart[r], j, m);
      }
      i = end;
    }
  });
}

}  // namespace flurry::detail::FLURRY_ISA
