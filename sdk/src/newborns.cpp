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

// What the curves over life scale: the colour and size just stored (Particle's defaults for
// a lane not stored).
void storeBirth(const Lanes& L, std::size_t slot) {
  for (int c = 0; c < 4; ++c)
    if (L.birthColor[c]) L.birthColor[c][slot] = L.color[c] ? L.color[c][slot] : 1.0f;
  if (L.birthSize) L.birthSize[slot] = L.size ? L.size[slot] : Particle().size;
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

// v += n·speed, per newborn (Vec3 arithmetic, element by element).
void normalVelocity(float* __restrict vx, float* __restrict vy, float* __restrict vz,
                    const float* __restrict nx, const float* __restrict ny,
                    const float* __restrict nz, const float* __restrict speed, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) {
    vx[k] += nx[k] * speed[k];
    vy[k] += ny[k] * speed[k];
    vz[k] += nz[k] * speed[k];
  }
}

// chooseType for n newborns from their draws u: FL_CHOOSE_TYPE's walk over the weights (the
// same subtractions in the same order, so the same choices) with the newborns inside, a
// vector loop per type, rather than a walk per newborn.
void chooseTypes(const std::vector<ParticleType>& types, const float* __restrict u, std::size_t n,
                 float* __restrict left, std::uint32_t* __restrict type) {
  float total = 0;
  for (const auto& t : types) total += t.weight;
  const auto last = std::uint32_t(types.size() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    left[i] = u[i] * total;
    type[i] = ~0u;  // not chosen yet
  }
  for (std::uint32_t k = 0; k < last; ++k) {
    const float w = types[k].weight;
    for (std::size_t i = 0; i < n; ++i) {
      type[i] = type[i] == ~0u && left[i] < w ? k : type[i];
      left[i] -= w;
    }
  }
  for (std::size_t i = 0; i < n; ++i) type[i] = type[i] == ~0u ? last : type[i];
}

// A batch's values before they are placed and stored: one row of kBatch per value and
// component, in this order (rows kNormalSpeed and after are shaping's own scratch).
enum Row : int {
  kVelocity = 0,  // 0-2
  kPosition = 3,  // 3-5: on the shape; the emitter's place is added after
  kLifetime = 6,
  kColor = 7,  // 7-9, then alpha
  kAlpha = 10,
  kSize = 11,
  kMass = 12,
  kCharge = 13,
  kUp = 14,           // 14-16
  kRotVelocity = 17,  // 17-19
  kNormalSpeed = 20,
  kNormal = 21,  // 21-23
  kRows = 24
};
struct Values {
  float row[kRows][kBatch];
};

// The values of newborns [0, n) of `type` from their draws row[0 .. at.total) into v: what
// the group stores of them (each newborn's from its own draws only). Returns the rows it
// wrote below kNormalSpeed, a bit each.
std::uint32_t shapeNewborns(const Lanes& L, const Emitter& em, const ParticleType& type,
                            const kernel::FlNewbornDraws& at, const float* const* row,
                            std::size_t n, Values& v) {
  std::uint32_t wrote = 0;
  auto vec = [&](const Domain& d, kernel::uint from, int a) {
    sampleBatch(d, row + from, n, v.row[a], v.row[a + 1], v.row[a + 2]);
    wrote |= 7u << a;
  };
  auto scalar = [&](const Fuzzy& f, kernel::uint from, int a) {
    sampleBatch(f, row + from, n, v.row[a]);
    wrote |= 1u << a;
  };
  vec(type.velocity, at.velocity, kVelocity);
  vec(em.shape, at.shape, kPosition);
  if (!(em.normalSpeed.constant() && em.normalSpeed.center == 0.0f)) {
    // Every face emits along its normal: the shape's normal where the particle was born.
    sampleBatch(em.normalSpeed, row + at.normal, n, v.row[kNormalSpeed]);
    float(*nrm)[kBatch] = v.row + kNormal;
    sampledNormals(em.shape, row + at.shape, n, v.row[kPosition], v.row[kPosition + 1],
                   v.row[kPosition + 2], nrm[0], nrm[1], nrm[2]);
    normalVelocity(v.row[kVelocity], v.row[kVelocity + 1], v.row[kVelocity + 2], nrm[0], nrm[1],
                   nrm[2], v.row[kNormalSpeed], n);
  }
  if (L.lifetime) scalar(type.lifetime, at.lifetime, kLifetime);
  if (L.color[0]) {
    vec(type.color, at.color, kColor);
    scalar(type.alpha, at.alpha, kAlpha);
  }
  if (L.size) scalar(type.size, at.size, kSize);
  if (L.mass) scalar(type.mass, at.mass, kMass);
  if (L.charge) scalar(type.charge, at.charge, kCharge);
  if (L.up[0]) vec(type.up, at.up, kUp);
  if (L.rot[0]) vec(type.rotVelocity, at.rot, kRotVelocity);
  return wrote;
}

// A batch of m newborns of one emitter: every draw at once (see sampling.hpp), then each
// value shaped for the whole batch. With several particle types each newborn picks its type
// with its first draw, and each type's newborns are gathered and shaped together.
void emitBatch(const NewbornContext& nc, const BirthRun& run, const Emitter& em, std::uint64_t q0,
               std::size_t i0, std::size_t m) {
  const Lanes& L = nc.L;
  // Scratch per thread, on the heap and reached through a pointer read once: in a shared
  // library every access to a thread_local object goes through __tls_get_addr, and GCC
  // folds a reference to one back into such accesses, once per element of the loops below.
  struct Scratch {
    float rows[kMaxDraws][kBatch];
    Values values;
    float age[kBatch];    // zeros
    double time[kBatch];  // birth times
    // Several types: each newborn's type, one type's newborns, their draws and values.
    std::uint32_t type[kBatch];
    float left[kBatch];
    std::uint16_t of[kBatch];
    float gathered[kMaxDraws][kBatch];
    Values typed;
  };
  thread_local std::unique_ptr<Scratch> scratch;
  if (!scratch) scratch = std::make_unique<Scratch>();  // once per thread
  Scratch& sc = *scratch;
  auto& rows = sc.rows;
  auto& v = sc.values.row;
  auto& age = sc.age;
  const float* row[kMaxDraws];
  for (int k = 0; k < kMaxDraws; ++k) row[k] = rows[k];

  const std::uint32_t firstId = nc.firstId + std::uint32_t(i0);
  // Drawn and shaped in whole vectors (of this build's width: 16 floats would cost an AVX2
  // build twice the work): a small group's few newborns a step then run the vector loops
  // alone, not their scalar remainders. Each newborn's values depend on its own draws only;
  // the extra lanes are never stored.
  const std::size_t mv = std::min(kBatch, (m + kVector - 1) / kVector * kVector);
  auto draw = [&](int draws) {
    for (int blk = 0; blk * 4 < draws; ++blk)
      uniformBatch(nc.sp.seed, firstId, nc.g.streamKey(), stream::kEmission, std::uint32_t(blk), mv,
                   rows[4 * blk], rows[4 * blk + 1], rows[4 * blk + 2], rows[4 * blk + 3]);
  };
  if (em.types.size() == 1) {
    const kernel::FlNewbornDraws at = newbornDraws(L, em, em.types[0]);
    draw(int(at.total));
    shapeNewborns(L, em, em.types[0], at, row, mv, sc.values);
  } else {
    int most = 0;
    for (const ParticleType& t : em.types) most = std::max(most, int(newbornDraws(L, em, t).total));
    draw(most);
    // (kernels/newborn.h: the type's draw is a newborn's first)
    chooseTypes(em.types, rows[0], m, sc.left, sc.type);
    const float* gathered[kMaxDraws];
    for (int d = 0; d < kMaxDraws; ++d) gathered[d] = sc.gathered[d];
    for (std::size_t t = 0; t < em.types.size(); ++t) {
      std::size_t c = 0;
      for (std::size_t k = 0; k < m; ++k) {
        sc.of[c] = std::uint16_t(k);
        c += sc.type[k] == t;
      }
      if (c == 0) continue;
      // Padded with copies of the first to whole vectors, as the batch is.
      const std::size_t cv = std::min(kBatch, (c + kVector - 1) / kVector * kVector);
      for (std::size_t j = c; j < cv; ++j) sc.of[j] = sc.of[0];
      const kernel::FlNewbornDraws at = newbornDraws(L, em, em.types[t]);
      for (kernel::uint d = 0; d < at.total; ++d)
        for (std::size_t j = 0; j < cv; ++j) sc.gathered[d][j] = rows[d][sc.of[j]];
      const std::uint32_t wrote = shapeNewborns(L, em, em.types[t], at, gathered, cv, sc.typed);
      for (int r = 0; r < kNormalSpeed; ++r)
        if (wrote >> r & 1u)
          for (std::size_t j = 0; j < c; ++j) v[r][sc.of[j]] = sc.typed.row[r][j];
    }
  }

  // Birth places: where the emitter was at the birth time; and the time left of the step.
  float* const px = v[kPosition];
  float* const py = v[kPosition + 1];
  float* const pz = v[kPosition + 2];
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
    put(L.p[c], v[kPosition + c]);
    put(L.v[c], v[kVelocity + c]);
    put(L.prev[c], v[kPosition + c]);
    put(L.posB[c], v[kPosition + c]);
    if (L.velB[c]) std::fill_n(L.velB[c] + first, m, 0.0f);
    put(L.up[c], v[kUp + c]);
    put(L.rot[c], v[kRotVelocity + c]);
  }
  putNonNegative(L.lifetime, v[kLifetime]);
  for (int c = 0; c < 4; ++c) put(L.color[c], v[kColor + c]);
  putNonNegative(L.size, v[kSize]);
  put(L.mass, v[kMass]);
  put(L.charge, v[kCharge]);
  put(L.age, age);
  if (L.birthColor[0] || L.birthSize)
    for (std::size_t k = 0; k < m; ++k) storeBirth(L, first + k);
  for (std::size_t k = 0; k < m; ++k) L.id[first + k] = firstId + std::uint32_t(k);
  if (L.visible) std::fill_n(L.visible + first, m, 1u);
  if (L.user) std::fill_n(L.user + first, m, 0.0f);
}

}  // namespace

void writeNewborns(GroupImpl& g, const StepParams& sp, const BirthRun* runs,
                   const std::uint64_t* runStart, std::size_t runCount, std::size_t accepted) {
  const double t1 = sp.end;
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
        emitBatch(nc, runs[r], em, j - runStart[r], j, m);
      }
      i = end;
    }
  });
}

}  // namespace flurry::detail::FLURRY_ISA
