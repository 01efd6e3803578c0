// Emission on the device: the host's planning of births and the generated fl_emit.
//
// The planning is sdk/src/emission.cpp's, rule for rule (it runs on a handful of emitters,
// so the host does it exactly as the CPU backend does): rates, bursts, emission by
// distance, prime emitters spawning live emitters that fly, emit and die with bursts and
// children. Its runs become FlBirthRuns in the CPU's order, so newborn r of a step gets the
// same id (firstId + r) and the same random stream on both backends; each run points at an
// FlEmitter entry packed from the (static or live) emitter as it is this step.
#include "emission.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include "../emission_plan.hpp"
#include "../sampling.hpp"
#include "flurry/error.hpp"
#include "flurry/random.hpp"

namespace flurry::detail::ocl {

namespace {

// ---- The generated code: one fl_emit case per distinct emitter code ------------------------

cl::FlFuzzy packFuzzy(const Fuzzy& f) {
  return {f.center, f.spread, f.distribution == Fuzzy::Distribution::Normal ? 1u : 0u, 0u};
}

int fuzzyMode(const Fuzzy& f) {
  return f.spread == 0.0f ? 0 : f.distribution == Fuzzy::Distribution::Normal ? 2 : 1;
}

// 0 without a speed along the normal (emission.cpp's alongNormal), else 1 + its fuzzy mode.
int normalMode(const Emitter& e) {
  const bool alongNormal = !(e.normalSpeed.constant() && e.normalSpeed.center == 0.0f);
  return alongNormal ? 1 + fuzzyMode(e.normalSpeed) : 0;
}

std::size_t kindOf(const Domain& d) {
  return d.shape().index();
}

std::string newbornCall(const Emitter& e, std::size_t t) {
  const ParticleType& p = e.types[t];
  std::ostringstream c;
  c << "fl_newborn(FL_LANE_ARGS, slot, id, at, em, types + em->typeFirst + " << t
    << "u, rng, shapes, " << (e.types.size() > 1 ? 1 : 0) << "u, " << kindOf(e.shape) << "u, "
    << kindOf(p.velocity) << "u, " << kindOf(p.color) << "u, " << kindOf(p.up) << "u, "
    << kindOf(p.rotVelocity) << "u, " << normalMode(e) << "u, " << fuzzyMode(p.lifetime) << "u, "
    << fuzzyMode(p.alpha) << "u, " << fuzzyMode(p.size) << "u, " << fuzzyMode(p.mass) << "u, "
    << fuzzyMode(p.charge) << "u);";
  return c.str();
}

// The statements of one emitter's case: what its kinds and modes make of fl_newborn.
std::string variantCode(const Emitter& em) {
  if (em.types.size() == 1) return "      " + newbornCall(em, 0) + "\n";
  std::string s = "      switch (fl_choose_type(em, types, rng)) {\n";
  for (std::size_t t = 0; t < em.types.size(); ++t)
    s += "        case " + std::to_string(t) + "u: " + newbornCall(em, t) + " break;\n";
  return s + "      }\n";
}

// The distinct emitter codes of a group, in a fixed order: its emitters, then every level
// of its prime emitters' children (as given, and as the copies live emitters are spawned
// from), then of its live emitters' (whose primes may be gone), so that the live emitters
// a step spawns find theirs in the program built before it.
Variants variantsOf(const GroupImpl& g) {
  Variants v;
  for (const Emitter& e : g.emitters) v.add(e);
  for (const PrimeEmitter& p : g.primes) v.addChain(&p.child);
  for (const auto& spec : g.primeSpecs) v.addChain(spec.get());
  for (const LiveEmitter& e : g.live) v.addChain(e.spec);
  return v;
}

// What of each static emitter variantCode() depends on, as numbers: comparing them costs
// no allocation, and catches edits through an Emitter& kept from addEmitter().
void emitterKeys(const GroupImpl& g, std::vector<std::uint32_t>& out) {
  out.clear();
  for (const Emitter& e : g.emitters) {
    out.insert(out.end(), {std::uint32_t(kindOf(e.shape)), std::uint32_t(normalMode(e)),
                           std::uint32_t(e.types.size())});
    for (const ParticleType& p : e.types)
      out.insert(out.end(), {std::uint32_t(kindOf(p.velocity)), std::uint32_t(kindOf(p.color)),
                             std::uint32_t(kindOf(p.up)), std::uint32_t(kindOf(p.rotVelocity)),
                             std::uint32_t(fuzzyMode(p.lifetime)),
                             std::uint32_t(fuzzyMode(p.alpha)), std::uint32_t(fuzzyMode(p.size)),
                             std::uint32_t(fuzzyMode(p.mass)), std::uint32_t(fuzzyMode(p.charge))});
  }
}

// ---- The step's tables -------------------------------------------------------------------

void setWord(float& f, std::uint32_t w) {
  std::memcpy(&f, &w, sizeof w);
}

void setDouble(std::vector<float>& d, std::size_t at, double x) {
  const std::uint64_t b = doubleBits(x);
  setWord(d[at], std::uint32_t(b));
  setWord(d[at + 1], std::uint32_t(b >> 32));
}

// One emitter as fl_birth and fl_newborn read it; returns its index in t.emitters.
std::uint32_t packEmitter(const Emitter& em, std::uint32_t variant, StepTables& t,
                          ShapePacker& shapes) {
  cl::FlEmitter o{};
  o.shape = shapes.pack(em.shape);
  o.start = doubleBits(em.start);
  o.rate = doubleBits(em.rate);
  for (int c = 0; c < 3; ++c) {
    o.position[c] = em.position[c];
    o.velocity[c] = em.velocity[c];
  }
  o.normalSpeed = packFuzzy(em.normalSpeed);
  o.pathFirst = cl::fl_u32(t.keys.size());
  o.pathCount = cl::fl_u32(em.path.size());
  o.pathLoop = em.pathLoop ? 1u : 0u;
  for (const Keyframe& k : em.path)
    t.keys.push_back({doubleBits(k.time), {k.position.x, k.position.y, k.position.z, 0.0f}});
  o.typeFirst = cl::fl_u32(t.types.size());
  o.typeCount = cl::fl_u32(em.types.size());
  float totalWeight = 0;
  for (const ParticleType& p : em.types) {
    totalWeight += p.weight;
    cl::FlParticleType q{};
    q.velocity = shapes.pack(p.velocity);
    q.color = shapes.pack(p.color);
    q.up = shapes.pack(p.up);
    q.rotVelocity = shapes.pack(p.rotVelocity);
    q.alpha = packFuzzy(p.alpha);
    q.size = packFuzzy(p.size);
    q.mass = packFuzzy(p.mass);
    q.lifetime = packFuzzy(p.lifetime);
    q.charge = packFuzzy(p.charge);
    q.weight = p.weight;
    t.types.push_back(q);
  }
  o.totalWeight = totalWeight;
  o.variant = variant;
  t.emitters.push_back(o);
  return cl::fl_u32(t.emitters.size() - 1);
}

}  // namespace

void Variants::add(const Emitter& e) {
  std::string c = variantCode(e);
  if (index.emplace(c, std::uint32_t(code.size())).second) code.push_back(std::move(c));
}

void Variants::addChain(const EmitterSpec* s) {
  std::set<const EmitterSpec*> seen;  // a `next` chain may loop back
  for (; s && seen.insert(s).second; s = s->next.get()) add(s->emitter);
}

std::uint32_t Variants::of(const Emitter& e) const {
  const auto it = index.find(variantCode(e));
  if (it == index.end())
    throw Error("OpenCL backend: an emitter's code is missing from the group's program");
  return it->second;
}

bool EmitterCodes::refresh(const GroupImpl& g) {
  if (version == g.emittersVersion) {
    emitterKeys(g, scratch);
    if (scratch == keys) return false;
  }
  version = g.emittersVersion;
  variants = variantsOf(g);
  staticVariant.clear();
  for (const Emitter& e : g.emitters) staticVariant.push_back(variants.of(e));
  emitterKeys(g, keys);
  return true;
}

// ---- Domains with data ------------------------------------------------------------------

std::uint32_t ShapePacker::mesh(const MeshData& m) {
  const auto it = meshes.find(&m);
  if (it != meshes.end()) return it->second;
  const auto off = cl::fl_u32(data.size());
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    const glm::uvec3 t = m.triangles[k];
    data.resize(data.size() + 2);
    setDouble(data, data.size() - 2, m.cumulativeArea[k]);
    for (const Vec3& x : {m.vertices[t.x], m.vertices[t.y], m.vertices[t.z], m.normals[k]})
      data.insert(data.end(), {x.x, x.y, x.z});
  }
  meshes.emplace(&m, off);
  return off;
}

void ShapePacker::leavesOf(const Domain& d, std::vector<const Domain*>& out) {
  if (const auto* u = std::get_if<UnionDomain>(&d.shape()))
    for (const Domain& part : u->parts->parts) leavesOf(part, out);
  else
    out.push_back(&d);
}

void ShapePacker::put(std::size_t at, const cl::FlDomain& o) {
  static_assert(sizeof(cl::FlDomain) == 18 * sizeof(float));
  std::memcpy(data.data() + at, &o, sizeof o);
}

cl::FlDomain ShapePacker::pack(const Domain& d) {
  cl::FlDomain o{};
  if (const auto* m = std::get_if<MeshDomain>(&d.shape())) {
    o.kind = FL_DOMAIN_MESH;
    setWord(o.v[0], mesh(*m->mesh));
    setWord(o.v[1], cl::fl_u32(m->mesh->triangles.size()));
    putVec(o.v, 2, m->mesh->min);  // the bounds, for containment (fl_inside_mesh)
    putVec(o.v, 5, m->mesh->max);
    return o;
  }
  const auto* u = std::get_if<UnionDomain>(&d.shape());
  if (!u) return packDomain(d);
  const UnionData& un = *u->parts;
  auto it = unions.find(&un);
  if (it == unions.end()) {
    // The record first, then its parts' own data after it (the vector may move: indices).
    const std::size_t off = data.size();
    data.resize(off + un.parts.size() * 20);
    for (std::size_t j = 0; j < un.parts.size(); ++j) {
      const cl::FlDomain part = pack(un.parts[j]);
      setDouble(data, off + j * 20, un.cumulativeMeasure[j]);
      put(off + j * 20 + 2, part);
    }
    std::vector<const Domain*> leaves;
    leavesOf(d, leaves);
    const std::size_t at = data.size();
    data.resize(at + leaves.size() * 18);
    for (std::size_t j = 0; j < leaves.size(); ++j) {
      const cl::FlDomain leaf = pack(*leaves[j]);
      put(at + j * 18, leaf);
    }
    it = unions
             .emplace(&un, std::array<std::uint32_t, 3>{cl::fl_u32(off), cl::fl_u32(at),
                                                        cl::fl_u32(leaves.size())})
             .first;
  }
  o.kind = FL_DOMAIN_UNION;
  setWord(o.v[0], it->second[0]);
  setWord(o.v[1], cl::fl_u32(un.parts.size()));
  setWord(o.v[2], cl::fl_u32(drawCount(d)));
  setWord(o.v[3], it->second[1]);
  setWord(o.v[4], it->second[2]);
  return o;
}

std::string emitterSignature(const Variants& v) {
  std::string s;
  for (const std::string& c : v.code) s += c + '|';
  return s;
}

std::string emissionSource(const GroupImpl& g) {
  return emissionSource(variantsOf(g));
}

std::string emissionSource(const Variants& v) {
  std::ostringstream s;
  // The newborns of each emitter code, with its kinds as literals.
  s << "/* ---- generated: emission per emitter code */\n"
       "FL_INLINE void fl_emit(FL_LANE_PARAMS, uint variant, uint slot, uint id, float3 at,\n"
       "                       __global const FlEmitter* em,\n"
       "                       __global const FlParticleType* types, FlRandom* rng,\n"
       "                       __global const float* shapes) {\n"
       "  switch (variant) {\n";
  for (std::size_t k = 0; k < v.code.size(); ++k)
    s << "    case " << k << "u:\n" << v.code[k] << "      break;\n";
  s << "  }\n}\n";
  return s.str();
}

// What the device does not run yet is refused, naming it, rather than silently ignored.
void checkEmissionSupported(const GroupImpl& g) {
  (void)g;  // everything the CPU emits runs on the device (hair mode in backend.cpp)
}

std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, StepTables& t, EmitterCodes& codes) {
  // The codes as the program was built from them (refreshed just now): planning spawns
  // emitters and may renew the primes' copies.
  const Variants& variants = codes.variants;
  thread_local std::vector<BirthRun> runsStore;
  auto& runs = runsStore;
  runs.clear();
  std::uint64_t total = detail::planBirths(g, sp, runs);
  g.stats.emitted += total;
  // Under a particle budget the context brought the live count up to date (shareBudget): the
  // host fits the births as the CPU does. Otherwise the device drops what does not fit.
  if (g.birthAllowance != ~std::uint64_t(0)) total = detail::fitBirths(g, total, runs);
  t.runs.clear();
  t.emitters.clear();
  t.types.clear();
  t.keys.clear();
  t.shapes.clear();
  if (total > 0) {
    ShapePacker shapes{t.shapes, {}, {}};
    constexpr std::uint32_t kNone = ~0u;
    codes.entryOfStatic.assign(g.emitters.size(), kNone);
    codes.entryOfLive.assign(g.live.size(), kNone);
    codes.specVariant.clear();  // live emitters share their spec's code
    std::uint64_t start = 0;
    for (const BirthRun& run : runs) {
      std::uint32_t& entry =
          run.live ? codes.entryOfLive[run.index] : codes.entryOfStatic[run.index];
      if (entry == kNone) {
        std::uint32_t variant = kNone;
        if (run.live) {
          const LiveEmitter& e = g.live[run.index];
          for (const auto& [spec, v] : codes.specVariant)
            if (spec == e.spec) variant = v;
          if (variant == kNone) {
            variant = variants.of(e.emitter);
            codes.specVariant.emplace_back(e.spec, variant);
          }
        } else {
          variant = codes.staticVariant[run.index];
        }
        const Emitter& em = run.live ? g.live[run.index].emitter : g.emitters[run.index];
        entry = packEmitter(em, variant, t, shapes);
      }
      cl::FlBirthRun r{};
      r.first = run.first;
      r.time = doubleBits(run.time);
      r.start = start;
      r.s0 = doubleBits(run.s0);
      r.spacing = doubleBits(run.spacing);
      r.span = doubleBits(run.span);
      r.dt = doubleBits(run.dt);
      r.emitter = entry;
      r.kind = run.kind == BirthRun::Rate    ? FL_RUN_RATE
               : run.kind == BirthRun::Burst ? FL_RUN_BURST
                                             : FL_RUN_DISTANCE;
      t.runs.push_back(r);
      start += run.count;
    }
  }
  // Live emitters that died this step go after their last births are packed.
  retireDead(g, sp.end);
  if (t.keys.empty()) t.keys.push_back({});
  if (t.shapes.empty()) t.shapes.push_back(0.0f);
  return total;
}

}  // namespace flurry::detail::ocl
