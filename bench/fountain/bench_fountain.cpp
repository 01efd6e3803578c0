// The fountain workload: the fused update and the whole step against the machine's
// in-place read-modify-write bandwidth and against an unfused baseline, in one run.
//
//   build/release/bench/bench_fountain --benchmark_repetitions=5
//
// Small groups (a game steps hundreds of ~1k-particle groups a frame) are measured apart:
//
//   build/release/bench/bench_fountain --benchmark_filter=Small --benchmark_repetitions=5
//
// Deflectors culled (1M particles on a floor in 32 pieces against 2):
//
//   build/release/bench/bench_fountain --benchmark_filter='Deflectors|ReadModifyWrite6'
//       --benchmark_repetitions=5   (one command)
//
// One force alone over 1M particles, against the read-modify-write of their 6 lanes:
//
//   build/release/bench/bench_fountain --benchmark_filter='Forces|ReadModifyWrite6'
//
// Idle groups (100 groups of which 10 are alive, against the 10 alone):
//
//   build/release/bench/bench_fountain --benchmark_filter=Idle --benchmark_repetitions=5
//
// After the runs it prints a summary of ratios between the medians of this run.
#include <benchmark/benchmark.h>

#include "common/read_modify_write.hpp"
#include "common/scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "builtin.hpp"
#include "flurry/flurry.hpp"
#include "pass_options.hpp"  // sdk/src: the unfused baseline is not public API

using namespace flurry;

namespace {

unsigned threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

// Bytes the fountain's update reads and writes per particle-step: position and velocity
// read and written (24 + 24), age read and written (4 + 4), lifetime read (4).
constexpr double kUpdateBytes = 60.0;
constexpr int kLanes = 9;  // position 3, velocity 3, age, lifetime, id

ActionList fountainActions() {
  return {Gravity{Vec3(0.0f, -9.81f, 0.0f)},
          Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f}, Move{},
          KillOld{}};
}

// A group of n immortal fountain particles: the update pass alone, no deaths, no births.
void UpdatePass(benchmark::State& state, bool fused) {
  const auto n = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = threads();
  Context ctx(o);
  detail::setPassOptions(ctx, {.fused = fused});
  Group& g = ctx.createGroup("fountain", n);
  Emitter e;
  e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.1f);
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 8.0f, 0.0f), 1.5f);
  t.lifetime = 1e30f;
  e.types = {t};
  e.bursts = {{0.0, std::uint32_t(n), 0.0, 1}};
  g.addEmitter(e);
  g.setActions(fountainActions());
  ctx.step();  // emits all n
  for (auto _ : state) ctx.step();
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n));
  state.SetBytesProcessed(std::int64_t(double(state.iterations()) * double(n) * kUpdateBytes));
  state.counters["B/particle"] = g.attributes().bytesPerParticle();
}

// The whole step at steady state: 10 % of the particles die and are born every step.
void FountainStep(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = threads();
  Context ctx(o);
  // Mean lifetime 10 steps of 1/30 s, rate 3n/s: about n alive, n/10 born per step.
  Group& g = samples::buildFountain(ctx, n + n / 2, 3.0 * double(n), 1.0f / 3.0f);
  g.setActions(fountainActions());
  ctx.run(30);
  std::uint64_t born = g.stats().emitted;
  double live = 0;
  for (auto _ : state) {
    ctx.step();
    live += double(g.size());
  }
  born = g.stats().emitted - born;
  const double mean = live / double(state.iterations());
  state.SetItemsProcessed(std::int64_t(live));
  state.SetBytesProcessed(std::int64_t(live * kUpdateBytes));
  state.counters["live"] = mean;
  state.counters["born/step"] = double(born) / double(state.iterations());
  state.counters["B/particle"] = g.attributes().bytesPerParticle();
}

// Steps a group whose newborns all die in their birth step (Move, KillOld), timing the
// steps after three, and reports the births a second and ns a newborn per thread.
void timeBirths(benchmark::State& state, Context& ctx, Group& g) {
  g.setActions({Move{}, KillOld{}});
  ctx.run(3);
  const std::uint64_t before = g.stats().emitted;
  for (auto _ : state) ctx.step();
  const double born = double(g.stats().emitted - before);
  state.SetItemsProcessed(std::int64_t(born));
  state.counters["ns/newborn/core"] = benchmark::Counter(
      born / threads() * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Births and deaths alone (nearly): n are born per step and every one dies in its birth
// step (it lives what is left of the step after its birth, longer than its lifetime).
void Emission(benchmark::State& state) {
  const auto n = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = threads();
  Context ctx(o);
  Group& g = samples::buildFountain(ctx, n, double(n) / o.dt, 1e-6f);
  timeBirths(state, ctx, g);
}

// A closed lat-long sphere of about `triangles` faces (2·rings·segments), radius 1.
Domain latLongSphere(std::size_t triangles) {
  const auto rings = std::max<std::size_t>(2, std::size_t(std::sqrt(double(triangles) / 4.0)));
  const std::size_t segments = std::max<std::size_t>(3, triangles / (2 * rings));
  std::vector<Vec3> v;
  std::vector<glm::uvec3> t;
  for (std::size_t r = 0; r <= rings; ++r)
    for (std::size_t s = 0; s < segments; ++s) {
      const double th = 3.14159265358979 * double(r) / double(rings),
                   ph = 2.0 * 3.14159265358979 * double(s) / double(segments);
      v.emplace_back(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
    }
  for (std::size_t r = 0; r < rings; ++r)
    for (std::size_t s = 0; s < segments; ++s) {
      const auto a = std::uint32_t(r * segments + s),
                 b = std::uint32_t(r * segments + (s + 1) % segments);
      const auto c = std::uint32_t(a + segments), d = std::uint32_t(b + segments);
      if (r > 0) t.emplace_back(a, b, c);  // (the poles' rings are points: no empty faces)
      if (r + 1 < rings) t.emplace_back(b, d, c);
    }
  return Domain::mesh(v, t);
}

// ColorOverLife and SizeOverLife on curves of range 0 keys over 1M particles at every point
// of their lives (lifetimes 0.1 to 3.9 s, half a second in): up to 8 keys a curve is
// evaluated a segment at a time, past that searched per particle.
void OverLifeCurves(benchmark::State& state) {
  const auto keys = int(state.range(0));
  constexpr std::size_t n = 1 << 20;
  ContextOptions o;
  o.threads = threads();
  o.dt = 1.0 / 60.0;
  Context ctx(o);
  Group& g = ctx.createGroup("particles", n);
  g.require({Attribute::Color, Attribute::Size});
  Emitter e;
  e.shape = Domain::box(Vec3(-4.0f), Vec3(4.0f));
  e.types[0].lifetime = Fuzzy(2.0f, 1.9f);
  e.bursts = {{0.0, std::uint32_t(n), 0.0, 1}};
  g.addEmitter(e);
  std::vector<ColorOverLife::Key> color;
  std::vector<SizeOverLife::Key> size;
  for (int k = 0; k < keys; ++k) {
    const float t = float(k) / float(keys - 1), w = float(k % 3) / 2.0f;
    color.push_back({t, Vec4(w, 1.0f - w, t, 1.0f - t)});
    size.push_back({t, 0.1f + w});
  }
  g.setActions({ColorOverLife{color, OverLifeMode::Replace},
                SizeOverLife{size, OverLifeMode::Replace}, Move{}});
  ctx.run(30);
  for (auto _ : state) ctx.step();
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n));
}

// 65,536 births a step from `e` (its rate set to that), each dying in its birth step, the
// group storing `stored` too (timeBirths).
void timeEmitter(benchmark::State& state, Emitter e, AttributeSet stored = {}) {
  constexpr std::size_t n = 1 << 16;
  ContextOptions o;
  o.threads = threads();
  Context ctx(o);
  Group& g = ctx.createGroup("newborns", n + n / 4);
  g.require(stored);
  e.rate = double(n) / o.dt;
  g.addEmitter(e);
  timeBirths(state, ctx, g);
}

// Births along the shape's normal (Emitter::normalSpeed) from a sphere's surface (range 0:
// 0) or a mesh sphere of about range 0 triangles (timeEmitter), to set beside Emission's.
void EmissionAlongNormals(benchmark::State& state) {
  const auto triangles = std::size_t(state.range(0));
  Emitter e;
  e.shape = triangles == 0 ? Domain::sphere(Vec3(0.0f), 1.0f, 1.0f) : latLongSphere(triangles);
  e.normalSpeed = Fuzzy(1.0f, 0.2f);
  e.types[0].velocity = Domain::point(Vec3(0.0f));
  e.types[0].lifetime = 1e-6f;
  timeEmitter(state, e);
}

// Births from a union of range 0 spheres along a spiral (the galaxy sample's arms are such a
// union; timeEmitter).
void EmissionUnion(benchmark::State& state) {
  std::vector<Domain> parts;
  for (int k = 0; k < int(state.range(0)); ++k) {
    const float a = 0.3f * float(k), r = 1.0f + 0.05f * float(k);
    parts.push_back(Domain::sphere(Vec3(r * std::cos(a), 0.0f, r * std::sin(a)), 0.2f));
  }
  Emitter e;
  e.shape = Domain::unite(parts);
  e.types[0].velocity = Domain::sphere(Vec3(0.0f), 0.1f);
  e.types[0].lifetime = 1e-6f;
  timeEmitter(state, e);
}

// Births from an emitter with range 0 particle types of equal weight, each its own velocity,
// lifetime, colour and size (stored; timeEmitter).
void EmissionTypes(benchmark::State& state) {
  const auto types = std::size_t(state.range(0));
  Emitter e;
  e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 1.0f);
  e.types.clear();
  for (std::size_t k = 0; k < types; ++k) {
    ParticleType t;
    t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 3.0f + float(k), 0.0f), 1.0f);
    t.lifetime = Fuzzy(1e-6f, 1e-7f);
    t.color = Domain::box(Vec3(0.1f * float(k)), Vec3(1.0f));
    t.size = Fuzzy(0.05f, 0.01f);
    e.types.push_back(t);
  }
  timeEmitter(state, e, {Attribute::Color, Attribute::Size});
}

using flurry::bench::kSmallLive;
using flurry::bench::smallFountain;

// The whole Context::step() of `groups` small groups, on `threads` threads; reports the
// time per group-step.
void SmallGroups(benchmark::State& state) {
  const auto groups = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  std::vector<Group*> all;
  for (std::size_t k = 0; k < groups; ++k)
    all.push_back(&smallFountain(ctx, "small" + std::to_string(k)));
  ctx.run(90);  // 3 s: past the longest lifetime (2.2 s), births and deaths balance
  double live = 0;
  for (auto _ : state) {
    ctx.step();
    live += double(all[0]->size());
  }
  state.counters["live"] = live / double(state.iterations());
  state.counters["us/group-step"] =
      benchmark::Counter(double(state.iterations()) * double(groups) * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// `alive` small fountains among `groups` groups, the others idle (their emitter stopped
// long ago and their particles are gone: a level's effects that have played), on one
// thread; reports the time of a whole Context::step().
void IdleGroups(benchmark::State& state) {
  const auto groups = std::size_t(state.range(0)), alive = std::size_t(state.range(1));
  ContextOptions o;
  o.threads = 1;
  Context ctx(o);
  flurry::bench::levelOfEffects(ctx, groups, alive);
  ctx.run(90);
  for (auto _ : state) ctx.step();
  state.counters["us/step"] = benchmark::Counter(
      double(state.iterations()) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// 1M particles bouncing on a floor in `deflectors` pieces (32: each particle reaches one;
// 2: halves; bench/common/scenes.hpp), culling on or off.
void Deflectors(benchmark::State& state) {
  const auto deflectors = int(state.range(0));
  constexpr std::size_t n = std::size_t(1) << 20;
  ContextOptions o;
  o.threads = threads();
  o.cull = state.range(1) != 0;
  Context ctx(o);
  Group& g = flurry::bench::deflectorCells(ctx, n, deflectors);
  ctx.step();
  const std::uint64_t culled = g.stats().blockActionsCulled;
  for (auto _ : state) ctx.step();
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n));
  // Position and velocity read and written.
  state.SetBytesProcessed(std::int64_t(double(state.iterations()) * double(n) * 48.0));
  state.counters["culled/step"] =
      double(g.stats().blockActionsCulled - culled) / double(state.iterations());
}

// A built-in sample with its emitters' rates scaled so that about `stars` particles live at
// once (a rate times its mean lifetime), the renderer's attributes stored. One whole
// Context::step() of the effect's dt, on all threads: the frame a game has for it.
void scaledSample(benchmark::State& state, const char* name) {
  const double stars = double(state.range(0));
  const samples::Sample* sample = samples::findSample(name);
  if (!sample || !sample->effect) {
    state.SkipWithError((std::string("the sample ") + name + " did not load").c_str());
    return;
  }
  const Effect& base = *sample->effect;
  double steady = 0.0;
  for (const EffectGroup& g : base.groups)
    for (const Emitter& e : g.emitters)
      for (const ParticleType& t : e.types) steady += e.rate * double(t.lifetime.center);
  // The effect's rates scaled to `count` stars by rate x lifetime (its start-up bursts as
  // they are), run well past its longest lifetime so that the count has settled; room for
  // all, so that no birth is dropped on the way.
  const auto settled = [&](double count) {
    Effect fx = base;
    const double scale = count / steady;
    for (EffectGroup& g : fx.groups) {
      g.capacity = std::size_t(2.0 * count);
      for (Emitter& e : g.emitters) e.rate *= scale;
    }
    ContextOptions o = fx.contextOptions();
    o.threads = threads();
    auto ctx = std::make_unique<Context>(o);
    for (Group* g : fx.build(*ctx)) g->require({Attribute::Color, Attribute::Size});
    ctx->run(int(10.0 / fx.dt));
    std::size_t live = 0;
    for (const Group* g : ctx->groups()) live += g->size();
    return std::pair{std::move(ctx), double(live)};
  };
  // Some stars die before their lifetime (the estimate knows only the lifetimes): when the
  // first run settles short of the count, it is run again scaled by the shortfall.
  auto [ctxOwner, live] = settled(stars);
  if (live < stars) std::tie(ctxOwner, live) = settled(stars * stars / std::max(live, 1.0));
  Context& ctx = *ctxOwner;
  for (auto _ : state) ctx.step();
  live = 0;
  for (const Group* g : ctx.groups()) live += double(g->size());
  state.counters["live"] = live;
  state.counters["dt_ms"] = base.dt * 1e3;
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(live));
}

// The galaxy sample (samples/effects/galaxy.json: arms, a softened orbit, a vortex) with a
// million stars.
void GalaxyStars(benchmark::State& state) {
  scaledSample(state, "galaxy");
}

// The campfire sample (flames, smoke and sparks: Turbulence, ColorOverLife and SizeOverLife in
// each group) with a million particles: what curves over life and curl noise cost.
void CampfireMillion(benchmark::State& state) {
  scaledSample(state, "campfire");
}

// One force alone (then Move) over 1M immortal particles spread through a box 8 m wide: what
// each costs a particle-step against the read-modify-write of the position and velocity it
// reads and writes (ReadModifyWrite6, the summary's "of RMW"). Where an action ran a scalar
// loop, this is where it shows.
ActionList forceAloneEuler(const std::string& name);
// A name ending in "RK4": the force integrated by RK4 (each stage's acceleration summed).
ActionList forceAlone(const std::string& name) {
  const std::string rk4 = "RK4";
  if (name.size() > rk4.size() && name.compare(name.size() - rk4.size(), rk4.size(), rk4) == 0) {
    ActionList list = forceAloneEuler(name.substr(0, name.size() - rk4.size()));
    list.setIntegrator(Integrator::RK4);
    return list;
  }
  return forceAloneEuler(name);
}

ActionList forceAloneEuler(const std::string& name) {
  Falloff fade;
  fade.center = Vec3(0.0f, 4.0f, 0.0f);
  fade.radius = 5.0f;
  fade.power = name.find("Pow2_5") != std::string::npos ? 2.5f : 1.0f;  // (no "." in a name)
  if (name.rfind("Gravity", 0) == 0) {
    Gravity g{Vec3(0.0f, -9.81f, 0.0f)};
    if (name != "Gravity") g.falloff = fade;
    return {g, Move{}};
  }
  if (name.rfind("Damping", 0) == 0) {
    Damping d{Vec3(0.3f)};
    d.falloff = fade;
    return {d, Move{}};
  }
  if (name == "Vortex") {
    Vortex v;
    v.center = Vec3(0.0f, 4.0f, 0.0f);
    v.aroundSpeed = 3.0f;
    v.coreRadius = 1.0f;
    v.tightness = 0.8f;
    v.inSpeed = 0.5f;
    return {v, Move{}};
  }
  if (name == "Explosion") {
    Explosion e;
    e.center = Vec3(0.0f, 4.0f, 0.0f);
    e.speed = 0.01f;  // (its front stays among the particles)
    return {e, Move{}};
  }
  if (name == "Turbulence") return {Turbulence{}, Move{}};
  if (name == "ElectricField") {
    ElectricField e;
    e.field = Vec3(0.0f, 1.0f, 0.5f);
    e.falloff = fade;
    return {e, Move{}};
  }
  if (name == "MagneticField") {
    MagneticField m{Vec3(0.0f, 2.0f, 1.0f)};
    m.falloff = fade;
    return {m, Move{}};
  }
  if (name.rfind("SampledField", 0) == 0) {  // a swirl on a 32^3 grid over the box
    auto field = std::make_shared<VectorField>();
    field->origin = Vec3(-4.0f, 0.0f, -4.0f);
    field->voxelSize = 8.0f / 31.0f;
    field->dims = glm::ivec3(32);
    for (int z = 0; z < 32; ++z)
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
          field->data.push_back(Vec3(float(z - 16), 0.1f * float(y), float(16 - x)) * 0.1f);
    SampledField f;
    f.field = field;
    if (name == "SampledFieldCarry") f.mode = SampledField::Mode::Velocity;
    return {f, Move{}};
  }
  if (name == "Spin") return {Move{}};  // Move turning the up vector (Forces stores it)
  if (name == "OrbitPoint") return {OrbitPoint{}, Move{}};
  if (name == "Follow") return {Follow{0.5f, 0.01f}, Move{}};  // each towards the next
  if (name == "Constrain2D")
    return {Constrain2D{Vec3(0.0f, 4.0f, 0.0f), glm::normalize(Vec3(0.3f, 0.2f, 1.0f))}, Move{}};
  if (name == "Restore") return {Restore{0.0f, 1000.0f}, Move{}};  // towards where each began
  if (name == "BounceBoxInside") {  // a room around the box: a few hit its walls each step
    Bounce b{Domain::box(Vec3(-4.01f, -0.01f, -4.01f), Vec3(4.01f, 8.01f, 4.01f)), 0.8f};
    b.inside = true;
    return {b, Move{}};
  }
  if (name == "BounceBoxOutside")  // a crate in the middle
    return {Bounce{Domain::box(Vec3(-1.0f, 3.0f, -1.0f), Vec3(1.0f, 5.0f, 1.0f)), 0.8f}, Move{}};
  if (name == "BounceSphereInside") {  // a sphere around it
    Bounce b{Domain::sphere(Vec3(0.0f, 4.0f, 0.0f), 7.0f), 0.8f};
    b.inside = true;
    return {b, Move{}};
  }
  if (name.rfind("Jet", 0) == 0) {
    Jet j;
    j.center = Vec3(0.0f, 4.0f, 0.0f);
    j.radius = 3.0f;
    if (name == "JetDrawn") {  // random kicks over most of the box, which stays full
      j.radius = 6.0f;
      j.acceleration = Domain::box(Vec3(-6.0f), Vec3(6.0f));
    }
    return {j, Move{}};
  }
  if (name == "Avoid") {
    Avoid a;
    a.obstacle = Domain::sphere(Vec3(0.0f, 4.0f, 0.0f), 2.0f);
    return {a, Move{}};
  }
  if (name == "AvoidPlane") {
    Avoid a;
    a.obstacle = Domain::plane(Vec3(0.0f, 4.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f));
    return {a, Move{}};
  }
  if (name == "SinkHit") {  // a disc above the box: every path tested, none absorbed
    const Domain disc = Domain::disc(Vec3(0.0f, 9.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 3.0f);
    return {Sink{disc, 0.0f, Sink::Mode::Hit}, Move{}};
  }
  if (name == "SinkHitRectangle") {  // the same above the box, a rectangle's nearest point
    const Domain r =
        Domain::rectangle(Vec3(-3.0f, 9.0f, -3.0f), Vec3(6.0f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 6.0f));
    return {Sink{r, 0.0f, Sink::Mode::Hit}, Move{}};
  }
  if (name == "AvoidTriangle") {  // a triangle across the box, its crossings tested
    Avoid a;
    a.obstacle =
        Domain::triangle(Vec3(-4.0f, 4.0f, -4.0f), Vec3(4.0f, 4.0f, -4.0f), Vec3(0.0f, 4.0f, 4.0f));
    return {a, Move{}};
  }
  return {};
}

// A group of n immortal particles in `box`, moving at up to `speed` (charged, spinning), all
// born in one burst at the first step; 60 steps a second.
Group& burstOf(Context& ctx, std::size_t n, const Domain& box, float speed) {
  Group& g = ctx.createGroup("particles", n);
  Emitter e;
  e.shape = box;
  ParticleType t;
  t.velocity = Domain::sphere(Vec3(0.0f), speed);
  t.lifetime = 1e30f;
  t.charge = Fuzzy(1.0f, 0.5f);
  t.rotVelocity = Domain::sphere(Vec3(0.0f), 3.0f);
  e.types = {t};
  e.bursts = {{0.0, std::uint32_t(n), 0.0, 1}};
  g.addEmitter(e);
  return g;
}
ContextOptions sixtyHertz() {
  ContextOptions o;
  o.threads = threads();
  o.dt = 1.0 / 60.0;
  return o;
}

void Forces(benchmark::State& state, const char* name) {
  const auto n = std::size_t(state.range(0));
  Context ctx(sixtyHertz());
  Group& g = burstOf(ctx, n, Domain::box(Vec3(-4.0f, 0.0f, -4.0f), Vec3(4.0f, 8.0f, 4.0f)), 0.5f);
  const bool spin = std::string(name) == "Spin";
  if (spin) g.require({Attribute::Up, Attribute::RotVelocity});
  const ActionList actions = forceAlone(name);
  if (actions.actions().empty()) {
    state.SkipWithError((std::string("no force named ") + name).c_str());
    return;
  }
  g.setActions(actions);
  ctx.step();  // emits all n
  for (auto _ : state) ctx.step();
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n));
  // Position and velocity read and written (the charge and mass an electric or magnetic field
  // reads too; a spin: the up vector too, and the angular velocity read).
  const std::string f = name;
  const bool charged = f.rfind("ElectricField", 0) == 0 || f.rfind("MagneticField", 0) == 0;
  const double bytes = charged ? 56.0 : spin ? 84.0 : 48.0;
  state.SetBytesProcessed(std::int64_t(double(state.iterations()) * double(n) * bytes));
}

// A flock: MatchVelocity (or Gravitate, alone or under RK4) over `n` particles in a 4 m box, each
// against all the others (the classic API's neighbour actions are O(n^2)): items are particle
// pairs.
void Flock(benchmark::State& state, const char* action) {
  const auto n = std::size_t(state.range(0));
  Context ctx(sixtyHertz());
  Group& g = burstOf(ctx, n, Domain::box(Vec3(-2.0f), Vec3(2.0f)), 1.0f);
  const std::string name = action;
  if (name.rfind("Gravitate", 0) == 0) {
    ActionList list{Gravitate{0.01f, 0.01f}, Move{}};
    if (name == "GravitateRK4") list.setIntegrator(Integrator::RK4);  // four scans a step
    g.setActions(list);
  } else {
    g.setActions({MatchVelocity{}, Move{}});
  }
  ctx.step();
  for (auto _ : state) ctx.step();
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n) * std::int64_t(n));
}

// The ceiling for it: the six lanes it reads and writes.
void ReadModifyWrite6(benchmark::State& state) {
  flurry::bench::readModifyWrite(state, 6, threads());
}

// One small group alone.
void SmallGroupStep(benchmark::State& state) {
  SmallGroups(state);
}

// The ceiling, measured the same way in every benchmark (bench/common).
void ReadModifyWrite(benchmark::State& state) {
  flurry::bench::readModifyWrite(state, kLanes, threads());
}

// Prints ratios between the medians (or single runs) of this process's benchmarks.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (r.run_type == Run::RT_Iteration && r.repetitions > 1) continue;
      if (r.run_type == Run::RT_Aggregate && !median) continue;
      const auto it = r.counters.find("bytes_per_second");
      const auto items = r.counters.find("items_per_second");
      std::string name = r.run_name.function_name + "/" + r.run_name.args;
      if (it != r.counters.end()) bytes_[name] = it->second;
      if (name.rfind("Small", 0) == 0 || name.rfind("Idle", 0) == 0) {
        auto per = r.counters.find("us/group-step");
        if (per == r.counters.end()) per = r.counters.find("us/step");
        if (per != r.counters.end()) small_[name] = per->second;
      }
      if (items != r.counters.end()) items_[name] = items->second;
      if (name.rfind("Deflectors", 0) == 0 || name.rfind("GalaxyStars", 0) == 0)
        ms_[name] = r.GetAdjustedRealTime();  // in the benchmark's unit (ms)
      if (name.rfind("GalaxyStars", 0) == 0) {
        const auto live = r.counters.find("live"), dt = r.counters.find("dt_ms");
        if (live != r.counters.end()) galaxyLive_ = live->second;
        if (dt != r.counters.end()) galaxyDt_ = dt->second;
      }
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf(
        "\nSummary (%u threads, CPU backend's %s build; GB/s count the bytes of the attributes "
        "read and written):\n",
        threads(), cpuInstructionSet());
    for (const char* n : {"1048576", "4194304"}) {
      const std::string N = n;
      const double rmw = bytes_["ReadModifyWrite/" + N];
      const double upd = bytes_["UpdatePass/fused/" + N];
      const double unf = bytes_["UpdatePass/unfused/" + N];
      const double step = bytes_["FountainStep/" + N];
      if (rmw <= 0) continue;
      std::printf("  %s particles: read-modify-write %.1f GB/s\n", n, rmw / 1e9);
      if (upd > 0)
        std::printf("    fused update   %.1f GB/s = %3.0f %% of it, %.2f G particle-steps/s\n",
                    upd / 1e9, 100 * upd / rmw, items_["UpdatePass/fused/" + N] / 1e9);
      if (step > 0)
        std::printf(
            "    whole step     %.1f GB/s = %3.0f %% of it (10 %% born and dying per step)\n",
            step / 1e9, 100 * step / rmw);
      if (upd > 0 && unf > 0) std::printf("    fused / unfused: %.2fx\n", upd / unf);
    }
    const double idle100 = small_["IdleGroups/groups:100/alive:10"];
    const double idle10 = small_["IdleGroups/groups:10/alive:10"];
    if (idle100 > 0 && idle10 > 0)
      std::printf(
          "  100 groups of which 10 alive: %.2f us/step, the 10 alone %.2f: %.2fx (goal <= 1.2)\n",
          idle100, idle10, idle100 / idle10);
    const double d32 = ms_["Deflectors/deflectors:32/cull:1"];
    const double d2 = ms_["Deflectors/deflectors:2/cull:1"];
    const double d2off = ms_["Deflectors/deflectors:2/cull:0"];  // every particle tests both
    const double d32off = ms_["Deflectors/deflectors:32/cull:0"];
    if (d32 > 0 && d2 > 0) {
      std::printf(
          "  1M particles on a floor in 32 pieces, culled %.2f ms / in 2 pieces, culled %.2f ms "
          "= %.2fx (goal <= 1.3)\n",
          d32, d2, d32 / d2);
      if (d2off > 0)
        std::printf("    2 pieces, every particle testing both: %.2f ms = %.2fx\n", d2off,
                    d2off / d2);
      if (d32off > 0)
        std::printf("    32 pieces without culling: %.2f ms = %.2fx\n", d32off, d32off / d2);
      const double rmw = bytes_["ReadModifyWrite6/1048576"];
      if (rmw > 0)
        std::printf(
            "    read-modify-write of its 6 lanes %.1f GB/s; 32 culled %.1f GB/s, 2 %.1f GB/s\n",
            rmw / 1e9, bytes_["Deflectors/deflectors:32/cull:1"] / 1e9,
            bytes_["Deflectors/deflectors:2/cull:1"] / 1e9);
    }
    const double rmw6 = bytes_["ReadModifyWrite6/1048576"];
    bool forcesTitle = false;
    for (const auto& [name, rate] : bytes_) {
      if (name.rfind("Forces/", 0) != 0 || rmw6 <= 0) continue;
      if (!forcesTitle)
        std::printf(
            "  one force and Move over 1M particles, against the read-modify-write of "
            "their 6 lanes (%.1f GB/s):\n",
            rmw6 / 1e9);
      forcesTitle = true;
      std::printf("    %-32s %6.1f M particle-steps/s = %3.0f %% of it\n",
                  name.substr(7, name.find('/', 7) - 7).c_str(), items_[name] / 1e6,
                  100 * rate / rmw6);
    }
    const double galaxy = ms_["GalaxyStars/1000000"];
    if (galaxy > 0 && galaxyDt_ > 0)
      std::printf(
          "  galaxy, %.0f stars alive: %.2f ms a step of %.1f ms (dt): %.2fx real time (goal >= "
          "1)\n",
          galaxyLive_, galaxy, galaxyDt_, galaxyDt_ / galaxy);
    if (small_.find("SmallGroupStep/groups:1/threads:1") == small_.end()) return;
    std::printf("  small groups (%zu live particles each), us per group-step (goal <= 5):\n",
                kSmallLive);
    for (const char* n : {"SmallGroupStep/groups:1", "SmallGroups/groups:100"}) {
      const std::string N = n;
      const double t1 = small_[N + "/threads:1"], t2 = small_[N + "/threads:2"];
      if (t1 <= 0) continue;
      std::printf("    %-24s 1 thread %6.2f", n, t1);
      if (t2 > 0) std::printf(", 2 threads %6.2f (2 / 1 thread: %.2fx)", t2, t2 / t1);
      std::printf("\n");
    }
    const double one = small_["SmallGroupStep/groups:1/threads:1"];
    const double many = small_["SmallGroups/groups:100/threads:1"];
    if (one > 0 && many > 0)
      std::printf("    100 groups / 1 group (1 thread): %.2fx per group-step\n", many / one);
  }

 private:
  std::map<std::string, double> bytes_, items_, small_, ms_;
  double galaxyLive_ = 0.0, galaxyDt_ = 0.0;
};

}  // namespace

BENCHMARK(ReadModifyWrite)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(UpdatePass, fused, true)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(UpdatePass, unfused, false)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(FountainStep)->Arg(1 << 20)->Arg(1 << 22)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Emission)->Arg(1 << 18)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(OverLifeCurves)
    ->ArgName("keys")
    ->Arg(4)
    ->Arg(16)
    ->Arg(64)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(EmissionTypes)
    ->ArgName("types")
    ->Arg(1)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(EmissionUnion)
    ->ArgName("parts")
    ->Arg(8)
    ->Arg(60)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(EmissionAlongNormals)
    ->ArgName("triangles")
    ->Arg(0)
    ->Arg(80)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(ReadModifyWrite6)->Arg(1 << 20)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Deflectors)
    ->ArgNames({"deflectors", "cull"})
    ->Args({32, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({32, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
#define FLURRY_FORCE(F) \
  BENCHMARK_CAPTURE(Forces, F, #F)->Arg(1 << 20)->Unit(benchmark::kMillisecond)->UseRealTime();
FLURRY_FORCE(Gravity)
FLURRY_FORCE(GravityFalloff)
FLURRY_FORCE(GravityFalloffPow2_5)
FLURRY_FORCE(DampingFalloffPow2_5)
FLURRY_FORCE(Vortex)
FLURRY_FORCE(Explosion)
FLURRY_FORCE(Turbulence)
FLURRY_FORCE(ElectricField)
FLURRY_FORCE(MagneticField)
FLURRY_FORCE(Spin)
FLURRY_FORCE(VortexRK4)
FLURRY_FORCE(ElectricFieldRK4)
FLURRY_FORCE(JetDrawnRK4)
FLURRY_FORCE(SampledFieldRK4)
FLURRY_FORCE(Follow)
FLURRY_FORCE(FollowRK4)
FLURRY_FORCE(Constrain2D)
FLURRY_FORCE(Restore)
FLURRY_FORCE(BounceBoxInside)
FLURRY_FORCE(BounceBoxOutside)
FLURRY_FORCE(BounceSphereInside)
FLURRY_FORCE(SampledField)
FLURRY_FORCE(SampledFieldCarry)
FLURRY_FORCE(OrbitPoint)
FLURRY_FORCE(Jet)
FLURRY_FORCE(JetDrawn)
FLURRY_FORCE(Avoid)
FLURRY_FORCE(AvoidPlane)
FLURRY_FORCE(SinkHit)
FLURRY_FORCE(SinkHitRectangle)
FLURRY_FORCE(AvoidTriangle)
BENCHMARK_CAPTURE(Flock, MatchVelocity, "MatchVelocity")
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Flock, Gravitate, "Gravitate")
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Flock, GravitateRK4, "GravitateRK4")
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(GalaxyStars)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(CampfireMillion)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(IdleGroups)
    ->ArgNames({"groups", "alive"})
    ->Args({10, 10})
    ->Args({100, 10})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(SmallGroupStep)
    ->ArgNames({"groups", "threads"})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(SmallGroups)
    ->ArgNames({"groups", "threads"})
    ->Args({100, 1})
    ->Args({100, 2})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
