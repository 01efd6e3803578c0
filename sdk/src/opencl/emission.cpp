// Emission on the device: the host's planning of births and the generated fl_emit.
#include "emission.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "flurry/error.hpp"

namespace flurry::detail::ocl {

namespace {

std::uint64_t doubleBits(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

// emission.cpp producedBy: births a rate has produced by time t.
std::uint64_t producedBy(const Emitter& e, double t) {
  const double elapsed = std::min(t, e.stop) - e.start;
  if (elapsed <= 0) return 0;
  const double x = e.rate * elapsed;
  return std::uint64_t(std::floor(x + 1e-9 * std::max(1.0, x)));
}

cl::FlFuzzy packFuzzy(const Fuzzy& f) {
  return {f.center, f.spread, f.distribution == Fuzzy::Distribution::Normal ? 1u : 0u, 0u};
}

int fuzzyMode(const Fuzzy& f) {
  return f.spread == 0.0f ? 0 : f.distribution == Fuzzy::Distribution::Normal ? 2 : 1;
}

std::size_t kindOf(const Domain& d) {
  packDomain(d);  // throws for a kind the device cannot sample
  return d.shape().index();
}

std::string newbornCall(const Emitter& e, std::size_t t, bool oneType) {
  const ParticleType& p = e.types[t];
  std::ostringstream c;
  c << "fl_newborn(FL_LANE_ARGS, slot, id, age, at, " << (oneType ? 1 : 0)
    << ", em, types + em->typeFirst + " << t << "u, rng, " << kindOf(e.shape) << "u, "
    << kindOf(p.velocity) << "u, " << kindOf(p.color) << "u, " << kindOf(p.up) << "u, "
    << kindOf(p.rotVelocity) << "u, " << fuzzyMode(p.lifetime) << "u, " << fuzzyMode(p.alpha)
    << "u, " << fuzzyMode(p.size) << "u, " << fuzzyMode(p.mass) << "u, " << fuzzyMode(p.charge)
    << "u);";
  return c.str();
}

}  // namespace

std::string emitterSignature(const GroupImpl& g) {
  const std::vector<Emitter>& emitters = g.emitters;
  std::string s;
  for (const Emitter& e : emitters) {
    for (std::size_t t = 0; t < e.types.size(); ++t) s += newbornCall(e, t, e.types.size() == 1);
    s += '|';
  }
  return s;
}

std::string emissionSource(const GroupImpl& g) {
  const std::vector<Emitter>& emitters = g.emitters;
  std::ostringstream s;
  // The newborns of each emitter and type, with their kinds as literals.
  s << "/* ---- generated: emission per emitter and type */\n"
       "FL_INLINE void fl_emit(FL_LANE_PARAMS, uint emitter, uint slot, uint id, float age,\n"
       "                       float3 at, __global const FlEmitter* em,\n"
       "                       __global const FlParticleType* types, FlRandom* rng) {\n"
       "  switch (emitter) {\n";
  for (std::size_t e = 0; e < emitters.size(); ++e) {
    const Emitter& em = emitters[e];
    s << "    case " << e << "u:\n";
    if (em.types.size() == 1) {
      s << "      " << newbornCall(em, 0, true) << "\n";
    } else {
      s << "      switch (fl_choose_type(em, types, rng)) {\n";
      for (std::size_t t = 0; t < em.types.size(); ++t)
        s << "        case " << t << "u: " << newbornCall(em, t, false) << " break;\n";
      s << "      }\n";
    }
    s << "      break;\n";
  }
  s << "  }\n}\n";
  return s.str();
}

// What the device does not run yet is refused, naming it, rather than silently ignored.
void checkEmissionSupported(const GroupImpl& g) {
  auto refuse = [&](const std::string& what) {
    throw Error("OpenCL backend: group '" + g.name + "' uses " + what +
                ", which does not run on the device yet; use Backend::Cpu");
  };
  if (!g.primes.empty() || !g.live.empty()) refuse("prime emitters");
  if (g.hair.enabled) refuse("hair mode");
  for (std::size_t i = 0; i < g.emitters.size(); ++i) {
    const auto& e = g.emitters[i];
    const std::string name = "emitters[" + std::to_string(i) + "]";
    if (e.spacing > 0) refuse(name + ".spacing (emission by distance)");
    if (e.normalSpeed.center != 0.0f || e.normalSpeed.spread != 0.0f) refuse(name + ".normalSpeed");
  }
}

std::uint64_t planBirths(GroupImpl& g, const StepParams& sp, StepTables& t) {
  // emission.cpp step 1, verbatim in effect: which emitter gives birth, how many, when.
  const double t0 = sp.time, t1 = sp.time + sp.dt;
  std::uint64_t total = 0;
  for (std::uint32_t e = 0; e < g.emitters.size(); ++e) {
    const Emitter& em = g.emitters[e];
    auto& state = g.emitterState[e];
    if (em.rate > 0) {
      const std::uint64_t target = producedBy(em, t1);
      if (target > state.emittedByRate) {
        t.runs.push_back({state.emittedByRate, 0, total, e, 0u});
        total += target - state.emittedByRate;
        state.emittedByRate = target;
      }
    }
    for (const Burst& b : em.bursts)
      for (std::uint32_t r = 0; r < b.repeat; ++r) {
        const double tb = b.time + r * b.interval;
        if (tb >= t0 && tb < t1 && b.count > 0) {
          t.runs.push_back({0, doubleBits(tb), total, e, 1u});
          total += b.count;
        }
      }
  }
  g.stats.emitted += total;
  if (total == 0) return 0;
  for (const Emitter& em : g.emitters) {
    cl::FlEmitter o{};
    o.shape = packDomain(em.shape);
    o.start = doubleBits(em.start);
    o.rate = doubleBits(em.rate);
    for (int c = 0; c < 3; ++c) {
      o.position[c] = em.position[c];
      o.velocity[c] = em.velocity[c];
    }
    o.pathFirst = cl::fl_u32(t.keys.size());
    o.pathCount = cl::fl_u32(em.path.size());
    for (const Keyframe& k : em.path)
      t.keys.push_back({doubleBits(k.time), {k.position.x, k.position.y, k.position.z, 0.0f}});
    o.typeFirst = cl::fl_u32(t.types.size());
    o.typeCount = cl::fl_u32(em.types.size());
    float totalWeight = 0;
    for (const ParticleType& p : em.types) {
      totalWeight += p.weight;
      cl::FlParticleType q{};
      q.velocity = packDomain(p.velocity);
      q.color = packDomain(p.color);
      q.up = packDomain(p.up);
      q.rotVelocity = packDomain(p.rotVelocity);
      q.alpha = packFuzzy(p.alpha);
      q.size = packFuzzy(p.size);
      q.mass = packFuzzy(p.mass);
      q.lifetime = packFuzzy(p.lifetime);
      q.charge = packFuzzy(p.charge);
      q.weight = p.weight;
      t.types.push_back(q);
    }
    o.totalWeight = totalWeight;
    t.emitters.push_back(o);
  }
  if (t.keys.empty()) t.keys.push_back({});
  return total;
}

}  // namespace flurry::detail::ocl
