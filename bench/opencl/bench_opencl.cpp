// The OpenCL backend on PoCL against the native CPU backend, measured in one run:
//   - the fused update pass and the whole fountain step at 1M and 4M particles,
//   - the whole step of a heavy effect (curl-noise turbulence, an orbit, a bounce and a sink),
//   - time per step of a small (1k particle) fountain: the launch overhead,
//   - what death and collision events and trails of 8 positions cost,
//   - kernel compile time, cold and cached (in memory, and on disk),
//   - the machine's in-place read-modify-write bandwidth: the ceiling of an in-place update.
//
//   build/release/bench/bench_opencl --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
//
// OpenCL steps are queued without waiting; every timed iteration runs a batch of steps and
// then waits for the device (detail::ocl::finishGroup), so queued work is always counted.
#include <benchmark/benchmark.h>

#include "common/read_modify_write.hpp"
#include "common/scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "builtin.hpp"
#include "flurry/flurry.hpp"
#include "flurry/opencl.hpp"
#include "opencl/backend.hpp"
#include "opencl/runtime.hpp"

using namespace flurry;

namespace {

unsigned threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

// Bytes the fountain's update reads and writes per particle-step: position and velocity read
// and written (24 + 24), age read and written (4 + 4), lifetime read (4).
constexpr double kUpdateBytes = 60.0;
constexpr int kLanes = 9;  // position 3, velocity 3, age, lifetime, id

bool haveDevice() {
  try {
    return !openclDevices().empty();
  } catch (const std::exception&) {
    return false;
  }
}

ActionList fountainActions() {
  return {Gravity{Vec3(0.0f, -9.81f, 0.0f)},
          Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f}, Move{},
          KillOld{}};
}

ContextOptions options(Backend b) {
  ContextOptions o;
  o.threads = threads();
  o.backend = b;
  return o;
}

void finish(Group& g) {
  detail::ocl::finishGroup(detail::implOf(g));
}

// Runs `steps` steps per timed iteration, then waits for the device.
void timedSteps(benchmark::State& state, Context& ctx, Group& g, int steps) {
  for (auto _ : state) {
    for (int s = 0; s < steps; ++s) ctx.step();
    finish(g);
  }
  state.counters["us/step"] =
      benchmark::Counter(double(state.iterations()) * steps * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// n immortal fountain particles: the update pass alone, no deaths, no births.
void UpdatePass(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  const auto n = std::size_t(state.range(0));
  Context ctx(options(backend));
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
  ctx.run(4);  // emits all n, builds the program, and launches every kernel once (PoCL
  finish(g);   // specialises a kernel for its local size at its first launch)
  const int steps = 10;
  timedSteps(state, ctx, g, steps);
  state.SetItemsProcessed(std::int64_t(state.iterations()) * steps * std::int64_t(n));
  state.SetBytesProcessed(
      std::int64_t(double(state.iterations()) * steps * double(n) * kUpdateBytes));
}

// The whole step at steady state: about n alive, n/10 born and dying per step.
void FountainStep(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  const auto n = std::size_t(state.range(0));
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, n + n / 2, 3.0 * double(n), 1.0f / 3.0f);
  g.setActions(fountainActions());
  ctx.run(30);
  const double live = double(g.size());
  const int steps = 10;
  timedSteps(state, ctx, g, steps);
  state.SetItemsProcessed(std::int64_t(double(state.iterations()) * steps * live));
  state.SetBytesProcessed(std::int64_t(double(state.iterations()) * steps * live * kUpdateBytes));
  state.counters["live"] = live;
}

// A heavy effect at steady state (about n alive, n/10 born and dying per step): two octaves
// of curl-noise turbulence, a softened orbit, a bounce and a sink: compute, not bandwidth.
ActionList heavyActions() {
  return {Turbulence{2.0f, 0.8f, 2, Vec3(0.0f, 0.3f, 0.0f)},
          OrbitPoint{Vec3(0.0f, 2.0f, 0.0f), 4.0f, 0.05f},
          Gravity{Vec3(0.0f, -9.81f, 0.0f)},
          Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f, 0.1f, 0.0f},
          Sink{Domain::sphere(Vec3(0.0f, 2.0f, 0.0f), 0.1f), 0.0f},
          Move{},
          KillOld{}};
}

void HeavyStep(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  const auto n = std::size_t(state.range(0));
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, n + n / 2, 3.0 * double(n), 1.0f / 3.0f);
  g.setActions(heavyActions());
  ctx.run(30);
  const double live = double(g.size());
  const int steps = 5;
  timedSteps(state, ctx, g, steps);
  state.SetItemsProcessed(std::int64_t(double(state.iterations()) * steps * live));
  state.counters["live"] = live;
}

// A small fountain (~1k alive): what a step costs when there is almost nothing to compute.
void SmallStep(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, 4096, 1000.0, 1.0f);
  g.setActions(fountainActions());
  ctx.run(60);
  state.counters["live"] = double(g.size());
  timedSteps(state, ctx, g, 200);
}

// Skip what a scene doesn't need (issue #17), on both backends: 1M particles bouncing on a
// floor in 32 pieces, of which each particle reaches one, against the same floor in 2
// (bench/common/scenes.hpp; the CPU backend culls per block of particles, the OpenCL backend
// per work-group)...
void Deflectors(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  const auto deflectors = int(state.range(0));
  constexpr std::size_t n = std::size_t(1) << 20;
  Context ctx(options(backend));
  Group& g = flurry::bench::deflectorCells(ctx, n, deflectors);
  ctx.run(2);
  finish(g);
  const int steps = 5;
  timedSteps(state, ctx, g, steps);
  state.SetItemsProcessed(std::int64_t(state.iterations()) * steps * std::int64_t(n));
}

// ... and a level of 100 small effects of which 10 are alive, against the 10 alone: an idle
// group costs no pass and no launch.
void IdleGroups(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  const auto groups = std::size_t(state.range(0)), alive = std::size_t(state.range(1));
  ContextOptions o = options(backend);
  o.threads = 1;
  Context ctx(o);
  flurry::bench::levelOfEffects(ctx, groups, alive);
  ctx.run(90);
  const int steps = 20;
  for (auto _ : state) {
    for (int s = 0; s < steps; ++s) ctx.step();
    for (Group* g : ctx.groups()) finish(*g);
  }
  state.counters["us/step"] =
      benchmark::Counter(double(state.iterations()) * steps * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Ten small fountains a game moves every frame (range 0 = 1: each given a new transform
// before every step, a little further along x and turned a little more about y) or leaves
// standing (0): on the device a move uploads the actions' constants behind the steps in
// flight.
void MovedGroups(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  ContextOptions o = options(backend);
  o.threads = 1;
  Context ctx(o);
  std::vector<Group*> groups;
  for (int k = 0; k < 10; ++k)
    groups.push_back(&flurry::bench::smallFountain(ctx, "group" + std::to_string(k)));
  const bool move = state.range(0) != 0;
  int frame = 0;
  auto place = [&] {
    ++frame;
    for (std::size_t k = 0; k < groups.size(); ++k) {
      const float f = move ? float(frame) : 0.0f;
      groups[k]->setTransform({Vec3(float(k) * 4.0f + 0.01f * f, 0.0f, 0.0f),
                               glm::angleAxis(0.01f * f, Vec3(0.0f, 1.0f, 0.0f)), 1.0f});
    }
  };
  for (int s = 0; s < 90; ++s) {
    place();
    ctx.step();
  }
  const int steps = 20;
  for (auto _ : state) {
    for (int s = 0; s < steps; ++s) {
      place();
      ctx.step();
    }
    for (Group* g : groups) finish(*g);
  }
  state.counters["us/step"] =
      benchmark::Counter(double(state.iterations()) * steps * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Death events (Group::recordDeaths) on both backends: ~300k short-lived fountain particles,
// a third dying every step, recorded (range 0 = 1) or not (0). The difference over the deaths
// is an event's cost; on the device it includes waiting for the step and reading the events
// back, which a step that does not record never does.
void DeathEvents(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, std::size_t(1) << 19, 3.0e6, 0.1f);
  g.setActions(fountainActions());
  g.recordDeaths(state.range(0) != 0 ? g.capacity() : 0);
  ctx.run(10);
  finish(g);
  const int steps = 10;
  const GroupStats before = g.stats();
  timedSteps(state, ctx, g, steps);
  const double died =
      double(g.stats().killedByAge - before.killedByAge + g.stats().absorbed - before.absorbed);
  state.counters["deaths/step"] = died / (double(state.iterations()) * steps);
}

// Collision events (Group::recordCollisions) on both backends: the fountain's ~300k particles
// bouncing on the floor (many resting on it, deflected every step), recorded (range 0 = 1) or
// not (0). The difference over the events is an event's cost; on the device it includes the
// program that logs them, waiting for the step, reading them back and sorting them.
void CollisionEvents(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, std::size_t(1) << 19, 1.0e5, 3.0f);
  g.setActions(fountainActions());
  const bool record = state.range(0) != 0;
  g.recordCollisions(record ? 4 * g.capacity() : 0);
  ctx.run(90);
  finish(g);
  const int steps = 10;
  double events = 0;
  for (auto _ : state) {
    for (int s = 0; s < steps; ++s) {
      ctx.step();
      events += double(g.collisions().size());
    }
    finish(g);
  }
  state.counters["us/step"] =
      benchmark::Counter(double(state.iterations()) * steps * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  if (record) state.counters["events/step"] = events / (double(state.iterations()) * steps);
}

// Trails (Group::setTrail) on both backends: the fountain's ~300k particles keeping their
// last 8 positions (range 0 = 8) or none (0). The difference over the live particles is a
// trail's cost a particle and step: on the device three kernels of their own (start, move with
// the compaction, record), on the CPU the fused pass's extra stores and compaction's rows.
void Trails(benchmark::State& state, Backend backend) {
  if (backend == Backend::OpenCL && !haveDevice()) return state.SkipWithError("no OpenCL device");
  Context ctx(options(backend));
  Group& g = samples::buildFountain(ctx, std::size_t(1) << 19, 1.0e5, 3.0f);
  g.setActions(fountainActions());
  g.setTrail({.length = std::uint32_t(state.range(0))});
  ctx.run(90);
  finish(g);
  const int steps = 10;
  double live = 0;
  for (auto _ : state) {
    for (int s = 0; s < steps; ++s) ctx.step();
    finish(g);
    live += double(g.size());
  }
  state.counters["us/step"] =
      benchmark::Counter(double(state.iterations()) * steps * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["live"] = live / double(state.iterations());
}

// The ceiling, measured the same way in every benchmark (bench/common).
void ReadModifyWrite(benchmark::State& state) {
  flurry::bench::readModifyWrite(state, kLanes, threads());
}

// Seconds from a new Context to its first step done (the program build dominates).
double firstStepSeconds(float gravity) {
  const auto t0 = std::chrono::steady_clock::now();
  Context ctx(options(Backend::OpenCL));
  Group& g = ctx.createGroup("compile", 1024);
  g.setActions({Gravity{Vec3(0.0f, gravity, 0.0f)}, Damping{Vec3(0.25f)}, Move{}, KillOld{}});
  Particle p;
  g.add(p);
  ctx.step();
  finish(g);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct CompileTimes {
  double cold = 0, memory = 0, disk = 0;
  bool measured = false;
} gCompile;

void measureCompileTimes() {
  if (!haveDevice()) return;
  // Cold: no Flurry disk cache, and PoCL's own kernel cache off (set in main before PoCL
  // loads), with the program not yet in memory.
  const auto dir = std::filesystem::temp_directory_path() / "flurry-bench-cl-cache";
  std::filesystem::remove_all(dir);
  ::setenv("FLURRY_OPENCL_CACHE", dir.c_str(), 1);
  detail::ocl::Runtime::clearMemoryCache();
  gCompile.cold = firstStepSeconds(-9.81f);
  gCompile.memory = firstStepSeconds(-1.0f);  // other numbers, same program: in memory
  detail::ocl::Runtime::clearMemoryCache();
  gCompile.disk = firstStepSeconds(-2.0f);  // a binary from Flurry's disk cache
  ::setenv("FLURRY_OPENCL_CACHE", "off", 1);
  std::filesystem::remove_all(dir);
  gCompile.measured = true;
}

// Prints the comparisons between the medians (or single runs) of this process's benchmarks.
class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (r.run_type == Run::RT_Iteration && r.repetitions > 1) continue;
      if (r.run_type == Run::RT_Aggregate && !median) continue;
      const std::string name = r.run_name.function_name + "/" + r.run_name.args;
      auto get = [&](const char* c) {
        auto it = r.counters.find(c);
        return it == r.counters.end() ? 0.0 : double(it->second);
      };
      bytes_[name] = get("bytes_per_second");
      items_[name] = get("items_per_second");
      usPerStep_[name] = get("us/step");
      deathsPerStep_[name] = get("deaths/step");
      eventsPerStep_[name] = get("events/step");
      live_[name] = get("live");
      if (name.rfind("Deflectors", 0) == 0) ms_[name] = r.GetAdjustedRealTime();
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf(
        "\nSummary (%u threads, CPU backend's %s build; OpenCL = PoCL on this CPU; GB/s count "
        "the bytes of the attributes read and written):\n",
        threads(), cpuInstructionSet());
    for (const char* n : {"1048576", "4194304"}) {
      const std::string N = n;
      const double rmw = bytes_["ReadModifyWrite/" + N];
      if (rmw <= 0) continue;
      std::printf("  %s particles: read-modify-write %.1f GB/s\n", n, rmw / 1e9);
      for (const char* b : {"cpu", "opencl"}) {
        const double upd = bytes_[std::string("UpdatePass/") + b + "/" + N];
        const double step = items_[std::string("FountainStep/") + b + "/" + N];
        if (upd > 0)
          std::printf(
              "    %-6s update %5.1f GB/s = %3.0f %% of it, %.2f G particle-steps/s; "
              "whole step %.2f G particle-steps/s\n",
              b, upd / 1e9, 100 * upd / rmw, items_[std::string("UpdatePass/") + b + "/" + N] / 1e9,
              step / 1e9);
      }
      const double c = items_["UpdatePass/cpu/" + N], o = items_["UpdatePass/opencl/" + N];
      const double cs = items_["FountainStep/cpu/" + N], os = items_["FountainStep/opencl/" + N];
      if (c > 0 && o > 0)
        std::printf("    cpu / opencl: update %.2fx, whole step %.2fx (aim: <= 1.25x)\n", c / o,
                    os > 0 ? cs / os : 0.0);
      const double hc = items_["HeavyStep/cpu/" + N], ho = items_["HeavyStep/opencl/" + N];
      if (hc > 0 && ho > 0)
        std::printf(
            "    heavy effect (turbulence + orbit + bounce + sink), whole step: cpu %.3f, "
            "opencl %.3f G particle-steps/s; opencl / cpu time %.2fx\n",
            hc / 1e9, ho / 1e9, hc / ho);
    }
    const double sc = usPerStep_["SmallStep/cpu/"], so = usPerStep_["SmallStep/opencl/"];
    if (sc > 0 || so > 0)
      std::printf(
          "  small group (~1k particles): cpu %.1f us/step, opencl %.1f us/step "
          "(aim: opencl <= 20)\n",
          sc, so);
    for (const char* b : {"cpu", "opencl"}) {
      const std::string B = b;
      const double d32 = ms_["Deflectors/" + B + "/deflectors:32"];
      const double d2 = ms_["Deflectors/" + B + "/deflectors:2"];
      if (d32 > 0 && d2 > 0)
        std::printf(
            "  %-6s 1M particles, a floor in 32 pieces / in 2: %.2fx the time (aim <= 1.3)\n", b,
            d32 / d2);
      const double i100 = usPerStep_["IdleGroups/" + B + "/groups:100/alive:10"];
      const double i10 = usPerStep_["IdleGroups/" + B + "/groups:10/alive:10"];
      if (i100 > 0 && i10 > 0)
        std::printf(
            "  %-6s 100 groups of which 10 alive / the 10 alone: %.2fx (%.1f / %.1f us a step; "
            "aim <= 1.2)\n",
            b, i100 / i10, i100, i10);
      const double moved = usPerStep_["MovedGroups/" + B + "/move:1"];
      const double still = usPerStep_["MovedGroups/" + B + "/move:0"];
      if (moved > 0 && still > 0)
        std::printf(
            "  %-6s 10 small groups moved every step / standing: %.2fx (%.1f / %.1f us "
            "a step)\n",
            b, moved / still, moved, still);
    }
    // What a feature costs a unit: the step with it against without, over the units
    // (`count`: the per-step counter of the run with it).
    auto perUnit = [&](const char* what, const std::string& bench, const char* with,
                       const char* without, const std::map<std::string, double>& count,
                       const char* unit) {
      for (const char* b : {"cpu", "opencl"}) {
        const std::string on = bench + "/" + b + "/" + with, off = bench + "/" + b + "/" + without;
        const auto n = count.find(on);
        if (usPerStep_[on] > 0 && usPerStep_[off] > 0 && n != count.end() && n->second > 0)
          std::printf("  %-6s %s: %.0f us a step with %.0f %ss, %.0f us without: %.2f ns per %s\n",
                      b, what, usPerStep_[on], n->second, unit, usPerStep_[off],
                      (usPerStep_[on] - usPerStep_[off]) * 1e3 / n->second, unit);
      }
    };
    perUnit("death events", "DeathEvents", "record:1", "record:0", deathsPerStep_, "event");
    perUnit("collision events", "CollisionEvents", "record:1", "record:0", eventsPerStep_, "event");
    perUnit("trails of 8", "Trails", "length:8", "length:0", live_, "particle");
    if (gCompile.measured)
      std::printf(
          "  kernel program build, first step of a new Context: cold %.0f ms, cached in "
          "memory %.1f ms, from the disk cache %.0f ms\n",
          gCompile.cold * 1e3, gCompile.memory * 1e3, gCompile.disk * 1e3);
  }

 private:
  std::map<std::string, double> bytes_, items_, usPerStep_, ms_, deathsPerStep_, eventsPerStep_,
      live_;
};

}  // namespace

BENCHMARK(ReadModifyWrite)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(UpdatePass, cpu, Backend::Cpu)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(UpdatePass, opencl, Backend::OpenCL)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(FountainStep, cpu, Backend::Cpu)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(FountainStep, opencl, Backend::OpenCL)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(HeavyStep, cpu, Backend::Cpu)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(HeavyStep, opencl, Backend::OpenCL)
    ->Arg(1 << 20)
    ->Arg(1 << 22)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Deflectors, cpu, Backend::Cpu)
    ->ArgName("deflectors")
    ->Arg(2)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Deflectors, opencl, Backend::OpenCL)
    ->ArgName("deflectors")
    ->Arg(2)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(IdleGroups, cpu, Backend::Cpu)
    ->ArgNames({"groups", "alive"})
    ->Args({10, 10})
    ->Args({100, 10})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(IdleGroups, opencl, Backend::OpenCL)
    ->ArgNames({"groups", "alive"})
    ->Args({10, 10})
    ->Args({100, 10})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(MovedGroups, cpu, Backend::Cpu)
    ->ArgName("move")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(MovedGroups, opencl, Backend::OpenCL)
    ->ArgName("move")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(DeathEvents, cpu, Backend::Cpu)
    ->ArgName("record")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(DeathEvents, opencl, Backend::OpenCL)
    ->ArgName("record")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(CollisionEvents, cpu, Backend::Cpu)
    ->ArgName("record")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(CollisionEvents, opencl, Backend::OpenCL)
    ->ArgName("record")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Trails, cpu, Backend::Cpu)
    ->ArgName("length")
    ->Arg(0)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(Trails, opencl, Backend::OpenCL)
    ->ArgName("length")
    ->Arg(0)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(SmallStep, cpu, Backend::Cpu)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(SmallStep, opencl, Backend::OpenCL)->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
  // Cold compile times mean PoCL's own kernel cache off too; it is read when PoCL loads.
  ::setenv("POCL_KERNEL_CACHE", "0", 1);
  ::setenv("FLURRY_OPENCL_CACHE", "off", 1);
  setLogCallback(logToStderr);  // FLURRY_OPENCL_PROFILE=1's per-kernel times
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  measureCompileTimes();
  SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
