// The classic Particle System API's demo effects (Fountain, WaterfallA, Orbit2, Fireflies,
// Atom) at the workload shape of issue #11: 500k capacity, dt = 1 (the demos' units are per
// step), 50,000 births a step and about as many deaths, so ~10 % of the group is born and
// ~10 % dies each step. Each effect runs on 1 and 2 threads, with the renderer's attributes
// (colour, size) stored and without, beside the machine's in-place read-modify-write
// bandwidth measured in the same run (bench/common) on as many threads:
//
//   build/release/bench/bench_classic --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
//
// Counters: items_per_second is particle-steps/s of the whole Context::step() (the particles
// in the group at the start of each step × steps / s); bytes_per_second is what those
// particle-steps would move at the memory's pace (float lanes stored × 4 B × 2, read and
// written) and RMW% that against the read-modify-write bandwidth on the same thread count;
// emit% / act% / compact% are the parts of the step's wall time the CPU backend spent in
// emission, in the action pass and in compaction (GroupStats::stepSeconds). A summary of the
// medians follows the runs.
#include <benchmark/benchmark.h>

#include "common/read_modify_write.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

constexpr std::size_t kCapacity = 500'000;
constexpr double kBirthsPerStep = 50'000;  // the rate, per second = per step at dt = 1
// The classic demos let particles live until a sink takes them or the group is full (then
// births are dropped). To hold the shape (~10 % dying each step) every effect also
// kills by age at ~9 steps; its own sinks and deflectors still run over every particle.
const Fuzzy kLifetime = Fuzzy::percent(9.0f, 10.0f);
// The classic API's gravity vector (ParticleEffects::GravityVec), z up, per step².
const Vec3 kGravity(0.0f, 0.0f, -0.01f);

// FountainExact: the Fountain with the Exact integrator (its bounce then follows the
// parabola), not a classic demo: how much a closed-form Move costs in the same workload.
enum class Effect { Fountain, Waterfall, Orbit2, Fireflies, Atom, FountainExact };
constexpr const char* kEffectNames[] = {"Fountain",  "Waterfall", "Orbit2",
                                        "Fireflies", "Atom",      "FountainExact"};

// The classic Damping(s) scales the velocity by s each step; Flurry's is exp(-rate·dt).
float dampingRate(float scalePerStep) {
  return -std::log(scalePerStep);
}
// The classic TargetColor(c, a, k) moves k of the way each step; Flurry's 1 - exp(-rate·dt).
float approachRate(float fractionPerStep) {
  return -std::log1p(-fractionPerStep);
}

Emitter emitter(Domain shape, ParticleType type) {
  Emitter e;
  e.shape = shape;
  e.rate = kBirthsPerStep;
  type.lifetime = kLifetime;
  e.types = {type};
  return e;
}

// Orbit2's emitter: the classic BoxPoint moves it by djet each frame and reverses an axis
// when it leaves [-10, 10] (the classic also nudges another axis by a random amount there:
// left out, so the path is the same every run). Keyframes at the reversals, for more steps
// than any run takes; a birth inside a step is placed on the segment at its birth time.
std::vector<Keyframe> boxPointPath() {
  Vec3 jet(-4.0f, 0.0f, -2.4f), djet(0.31f, 0.17f, 0.23f);
  std::vector<Keyframe> path{{0.0, jet}};
  for (int step = 1; step <= 200'000; ++step) {
    jet += djet;
    bool turned = false;
    for (int d = 0; d < 3; ++d)
      if (jet[d] > 10.0f || jet[d] < -10.0f) {
        djet[d] = -djet[d];
        turned = true;
      }
    if (turned) path.push_back({double(step), jet});
  }
  return path;
}

// The demos' action lists, in their order, translated one action for one.
void buildEffect(Group& g, Effect effect) {
  ParticleType t;
  t.size = 1.0f;
  switch (effect) {
    case Effect::Fountain: {
      t.velocity =
          Domain::cylinder(Vec3(0.0f, -0.01f, 0.35f), Vec3(0.0f, -0.01f, 0.37f), 0.021f, 0.019f);
      t.color = Domain::line(Vec3(0.8f, 0.9f, 1.0f), Vec3(1.0f));
      g.addEmitter(emitter(Domain::line(Vec3(0.0f), Vec3(0.0f, 0.0f, 0.405f)), t));
      // Classic friction -0.05 (speeds the tangential motion up): Flurry takes [0, 1], so 0.
      g.setActions({Gravity{kGravity},
                    Bounce{Domain::disc(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f), 5.0f), 0.35f, 0.0f},
                    Move{},
                    Sink{.region = Domain::plane(Vec3(0.0f, 0.0f, -3.0f), Vec3(0.0f, 0.0f, 1.0f)),
                         .mode = Sink::Mode::Outside},
                    SinkVelocity{Domain::sphere(Vec3(0.0f), 0.01f), true}, KillOld{}});
      break;
    }
    case Effect::FountainExact: {
      buildEffect(g, Effect::Fountain);
      ActionList list = g.actions();
      list.setIntegrator(Integrator::Exact);
      g.setActions(std::move(list));
      return;
    }
    case Effect::Waterfall: {  // the classic WaterfallA
      t.velocity = Domain::blob(Vec3(0.03f, -0.001f, 0.01f), 0.002f);
      t.color = Domain::line(Vec3(0.8f, 0.9f, 1.0f), Vec3(1.0f));
      t.size = 1.5f;
      g.addEmitter(emitter(Domain::line(Vec3(-5.0f, -1.0f, 8.0f), Vec3(-5.0f, -3.0f, 8.0f)), t));
      // Classic friction -0.01 on the ground plane: 0 here, as for the fountain.
      g.setActions(
          {Gravity{kGravity},
           Bounce{Domain::rectangle(Vec3(-7.0f, -4.0f, 7.0f), Vec3(3.0f, 0.0f, 0.0f),
                                    Vec3(0.0f, 3.0f, 0.0f)),
                  0.35f, 0.0f},
           Bounce{Domain::sphere(Vec3(-4.0f, -2.0f, 4.0f), 0.2f), 0.5f, 0.0f},
           Bounce{Domain::sphere(Vec3(-3.5f, 0.0f, 2.0f), 2.0f), 0.5f, 0.0f},
           Bounce{Domain::sphere(Vec3(3.8f, 0.0f, 0.0f), 2.0f), 0.5f, 0.0f},
           Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)), 0.35f, 0.0f}, Move{},
           KillOld{},
           Sink{.region = Domain::sphere(Vec3(0.0f), 20.0f), .mode = Sink::Mode::Outside}});
      break;
    }
    case Effect::Orbit2: {
      t.velocity = Domain::blob(Vec3(0.02f, -0.2f, 0.0f), 0.015f);
      // The classic colours by the emitter's place (|jet|·0.1 + 0.4): a fixed sphere here.
      t.color = Domain::sphere(Vec3(0.9f), 0.1f);
      Emitter e = emitter(Domain::point(Vec3(0.0f)), t);
      e.path = boxPointPath();
      g.addEmitter(e);
      g.setActions({OrbitPoint{Vec3(2.0f, 0.0f, 3.0f), 0.1f, 1.5f},
                    OrbitPoint{Vec3(-2.0f, 0.0f, -3.0f), 0.1f, 1.5f},
                    Damping{Vec3(dampingRate(0.994f))}, Move{}, KillOld{}});
      break;
    }
    case Effect::Fireflies: {
      t.color = Domain::line(Vec3(0.1f, 0.5f, 0.0f), Vec3(0.9f, 0.9f, 0.1f));
      g.addEmitter(emitter(Domain::blob(Vec3(0.0f, 0.0f, 2.0f), 2.0f), t));
      g.setActions(
          {RandomAccel{Domain::sphere(Vec3(0.0f, 0.0f, 0.00001f), 0.002f)}, Move{}, KillOld{}});
      break;
    }
    case Effect::Atom: {
      t.velocity = Domain::sphere(Vec3(0.0f), 0.2f);
      // The classic PDBox((1, 0, 0), (1, 0, 1)) has no volume (Flurry refuses such a box): it
      // is the segment it spans.
      t.color = Domain::line(Vec3(1.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 1.0f));
      t.size = 1.5f;
      g.addEmitter(emitter(Domain::sphere(Vec3(0.0f), 6.0f), t));
      // TargetColor stores colour even when the renderer's attributes are not asked for.
      g.setActions({OrbitPoint{Vec3(0.0f), 0.05f, 1.5f},
                    TargetColor{Vec3(0.0f, 1.0f, 0.0f), 1.0f, approachRate(0.001f)}, Move{},
                    Sink{.region = Domain::sphere(Vec3(0.0f), 1.0f)},
                    Sink{.region = Domain::sphere(Vec3(0.0f), 8.0f), .mode = Sink::Mode::Outside},
                    KillOld{}});
      break;
    }
  }
}

// 32-bit float lanes the group stores (Id and Visible are integer lanes).
int floatLanes(AttributeSet s) {
  int n = 0;
  for (int a = 0; a < int(Attribute::Count); ++a)
    if (s.has(Attribute(a)) && Attribute(a) != Attribute::Id && Attribute(a) != Attribute::Visible)
      n += componentCount(Attribute(a));
  return n;
}

// Steps until the particle count settles: the last 10 counts within 1 % of their mean.
int settle(Context& ctx, const Group& g) {
  std::vector<double> sizes;
  for (int k = 1; k <= 400; ++k) {
    ctx.step();
    sizes.push_back(double(g.size()));
    if (k < 30) continue;
    const auto last = sizes.end() - 10;
    const auto [lo, hi] = std::minmax_element(last, sizes.end());
    double mean = 0;
    for (auto it = last; it != sizes.end(); ++it) mean += *it / 10.0;
    if (*hi - *lo <= 0.01 * mean) return k;
  }
  return 400;
}

// Args: threads, render (1: colour and size stored for a renderer).
void Classic(benchmark::State& state, Effect effect) {
  ContextOptions o;
  o.threads = unsigned(state.range(0));
  o.dt = 1.0;
  Context ctx(o);
  Group& g = ctx.createGroup(kEffectNames[int(effect)], kCapacity);
  buildEffect(g, effect);
  if (state.range(1) != 0) g.require({Attribute::Color, Attribute::Size});
  const int warm = settle(ctx, g);

  const GroupStats before = g.stats();
  double particleSteps = 0;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    particleSteps += double(g.size());
    ctx.step();
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const GroupStats& after = g.stats();
  const double steps = double(state.iterations());
  const int lanes = floatLanes(g.attributes());
  state.SetItemsProcessed(std::int64_t(particleSteps));
  state.SetBytesProcessed(std::int64_t(particleSteps * lanes * 8.0));
  state.counters["live"] = particleSteps / steps;
  state.counters["born/step"] = double(after.emitted - before.emitted) / steps;
  state.counters["lanes"] = lanes;
  state.counters["warmup"] = warm;
  const auto share = [&](double GroupStats::StepSeconds::*part) {
    return 100.0 * (after.stepSeconds.*part - before.stepSeconds.*part) / wall;
  };
  state.counters["emit%"] = share(&GroupStats::StepSeconds::emit);
  state.counters["act%"] = share(&GroupStats::StepSeconds::act);
  state.counters["compact%"] = share(&GroupStats::StepSeconds::compact);
}

// The ceiling, measured as in every benchmark (bench/common), at the groups' capacity and
// with the lanes an effect stores without (9: position, velocity, age, lifetime, id) and
// with the renderer's attributes (14: + colour, size). Args: lanes, threads.
void ReadModifyWrite(benchmark::State& state) {
  flurry::bench::readModifyWrite(state, int(state.range(1)), unsigned(state.range(2)));
}

std::string argOf(const std::string& args, const std::string& name) {
  const auto at = args.find(name + ":");
  if (at == std::string::npos) return "";
  const auto from = at + name.size() + 1;
  return args.substr(from, args.find('/', from) - from);
}

// Adds RMW% to every effect run (the fraction of the read-modify-write bandwidth on as many
// threads, with the matching lanes, median of this run) and prints a summary at the end.
class ClassicReporter : public benchmark::ConsoleReporter {
 public:
  using ConsoleReporter::ConsoleReporter;
  void ReportRuns(const std::vector<Run>& runs) override {
    std::vector<Run> out = runs;
    for (Run& r : out) {
      const bool aggregate = r.run_type == Run::RT_Aggregate;
      if (aggregate && r.aggregate_name != "median" && r.aggregate_name != "mean") continue;
      const std::string& fn = r.run_name.function_name;
      const std::string& args = r.run_name.args;
      const auto bytes = r.counters.find("bytes_per_second");
      if (bytes == r.counters.end()) continue;
      if (fn == "ReadModifyWrite") {
        if (!aggregate || r.aggregate_name == "median")
          rmw_[argOf(args, "lanes") + "/" + argOf(args, "threads")] = bytes->second;
        continue;
      }
      const std::string threads = argOf(args, "threads"), render = argOf(args, "render");
      const auto found = rmw_.find(std::string(render == "1" ? "14" : "9") + "/" + threads);
      const double ceiling = found == rmw_.end() ? 0.0 : found->second;
      if (ceiling > 0) r.counters["RMW%"] = 100.0 * bytes->second / ceiling;
      if (aggregate && r.aggregate_name == "mean") continue;
      Row& row = rows_[fn][render + "/" + threads];  // the median, or the single run
      const auto get = [&](const char* k) {
        const auto it = r.counters.find(k);
        return it == r.counters.end() ? 0.0 : double(it->second);
      };
      row = {get("items_per_second"), get("RMW%"), get("emit%"), get("act%"),
             get("compact%"),         get("live")};
    }
    ConsoleReporter::ReportRuns(out);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    if (rows_.empty()) return;
    std::printf(
        "\nSummary (medians; M particle-steps/s of the whole step, %% of the read-modify-write\n"
        "bandwidth on as many threads, and the step's split emit/act/compact in %% of its "
        "time), CPU backend's %s build:\n",
        cpuInstructionSet());
    for (const auto& [rmwKey, bps] : rmw_)
      std::printf("  read-modify-write, lanes/threads %s: %.1f GB/s\n", rmwKey.c_str(), bps / 1e9);
    for (const auto& [fn, byKey] : rows_) {
      for (const auto& [key, r] : byKey) {
        // No ceiling when --benchmark_filter left ReadModifyWrite out.
        const std::string rmw = r.rmw > 0 ? std::to_string(int(std::lround(r.rmw))) + " %" : "n/a";
        std::printf(
            "  %-22s render/threads %s: %6.1f M/s  %6s RMW  %3.0f/%3.0f/%3.0f  "
            "(%.0fk live)\n",
            fn.c_str(), key.c_str(), r.items / 1e6, rmw.c_str(), r.emit, r.act, r.compact,
            r.live / 1e3);
      }
    }
  }

 private:
  struct Row {
    double items = 0, rmw = 0, emit = 0, act = 0, compact = 0, live = 0;
  };
  std::map<std::string, double> rmw_;
  std::map<std::string, std::map<std::string, Row>> rows_;
};

}  // namespace

// First: the effects' RMW% needs it.
BENCHMARK(ReadModifyWrite)
    ->ArgNames({"n", "lanes", "threads"})
    ->ArgsProduct({{std::int64_t(kCapacity)}, {9, 14}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
#define FLURRY_CLASSIC(E)                  \
  BENCHMARK_CAPTURE(Classic, E, Effect::E) \
      ->ArgNames({"threads", "render"})    \
      ->ArgsProduct({{1, 2}, {0, 1}})      \
      ->Unit(benchmark::kMillisecond)      \
      ->UseRealTime()
FLURRY_CLASSIC(Fountain);
FLURRY_CLASSIC(Waterfall);
FLURRY_CLASSIC(Orbit2);
FLURRY_CLASSIC(Fireflies);
FLURRY_CLASSIC(Atom);
FLURRY_CLASSIC(FountainExact);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // Colours only on a terminal (a reporter of our own does not read --benchmark_color).
  ClassicReporter reporter(isatty(STDOUT_FILENO) ? benchmark::ConsoleReporter::OO_ColorTabular
                                                 : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
