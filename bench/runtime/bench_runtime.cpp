// The game runtime: many instances of one small effect against the same particles as one
// group, in one run (issue #15's aim: 10,000 instances of a 100-particle effect within 1.5x
// of one group of 1M; 1,000 instances too, which stay in cache).
//
//   build/release/bench/bench_runtime --benchmark_repetitions=5
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
//
// (one command line).
//
// After the runs it prints the ratio of the medians, per thread count, what bounds every step
// cost, what a recorded death or collision event costs (Deaths, Collisions: recording on
// against off), what a trail of 8 positions costs a particle (Trails), and what instances
// out of sight cost stepped once every 4 frames (OutOfSight), and what re-placing every
// instance before each step costs, moved or set where it stands (Moving).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "sparks.hpp"

using namespace flurry;
using flurry::bench::kPerInstance;
using flurry::bench::placeOf;
using flurry::bench::sparks;

namespace {

std::map<std::int64_t, double> deathsPerStep_;  // Deaths' mean deaths a step, by threads

// `count` instances of the 100-particle effect, each placed on the grid, run until births and
// deaths balance (1.5 s: past the lifetime).
std::vector<EffectInstance> instances(Context& ctx, std::size_t count) {
  const Effect effect = parseEffect(sparks(kPerInstance));
  std::vector<EffectInstance> all;
  all.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    all.push_back(effect.instantiate(ctx, std::to_string(k)));
    all.back().setTransform(placeOf(k, count));
  }
  ctx.run(45);
  return all;
}

// The CPU backend's seconds in each part of a step (GroupStats::stepSeconds), summed over
// the instances' groups: where the instances' extra time goes against one group's.
GroupStats::StepSeconds phaseSeconds(const std::vector<EffectInstance>& all) {
  GroupStats::StepSeconds s;
  for (const EffectInstance& i : all)
    for (const Group* g : i.groups()) {
      s.emit += g->stats().stepSeconds.emit;
      s.act += g->stats().stepSeconds.act;
      s.compact += g->stats().stepSeconds.compact;
    }
  return s;
}

// The parts' milliseconds a step as counters (summed over the threads' groups).
void phaseCounters(benchmark::State& state, const GroupStats::StepSeconds& before,
                   const GroupStats::StepSeconds& after) {
  const double steps = double(state.iterations());
  state.counters["emit ms"] = (after.emit - before.emit) * 1e3 / steps;
  state.counters["act ms"] = (after.act - before.act) * 1e3 / steps;
  state.counters["compact ms"] = (after.compact - before.compact) * 1e3 / steps;
}

// `count` instances of the 100-particle effect (range 0), on `threads` (range 1); each step
// is Context::step() of them all, and with bounds (range 2) every instance's bounds, as an
// engine culls them.
void Instances(benchmark::State& state) {
  const auto count = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  const std::vector<EffectInstance> all = instances(ctx, count);
  double live = 0;
  const bool bounds = state.range(2) != 0;
  float sink = 0.0f;
  const GroupStats::StepSeconds before = phaseSeconds(all);
  for (auto _ : state) {
    ctx.step();
    if (bounds)
      for (const EffectInstance& i : all) sink += i.bounds().max.y;
    state.PauseTiming();
    for (const EffectInstance& i : all) live += double(i.groups()[0]->size());
    state.ResumeTiming();
  }
  phaseCounters(state, before, phaseSeconds(all));
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(std::int64_t(live));
  state.counters["live"] = live / double(state.iterations());
  state.counters["us/instance"] =
      benchmark::Counter(double(state.iterations()) * double(count) * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Instances a game re-places every frame: `count` (range 0) on `threads` (range 1), each given
// before every step (range 2) a new transform (1: a hundredth of a unit further along x, a
// hundredth of a radian more turned about y), or its own again (2: standing, set anyway), or
// none (0: as Instances).
void Moving(benchmark::State& state) {
  const auto count = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  std::vector<EffectInstance> all = instances(ctx, count);
  const int move = int(state.range(2));
  std::int64_t step = 0;
  for (auto _ : state) {
    ++step;
    for (std::size_t k = 0; move > 0 && k < count; ++k) {
      Transform t = placeOf(k, count);
      if (move == 1) {
        t.position.x += 0.01f * float(step);
        t.rotation = glm::angleAxis(float(k) * 0.37f + 0.01f * float(step), Vec3(0, 1, 0));
      }
      all[k].setTransform(t);
    }
    ctx.step();
  }
  state.counters["us/instance"] =
      benchmark::Counter(double(state.iterations()) * double(count) * 1e-6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// A level of detail: 10,000 instances out of sight, stepped once every `interval` frames
// (range 0; EffectInstance::setUpdateInterval) against every frame (1), on `threads` (range
// 1). The game's frame costs about 1/interval, the instances staying on time.
void OutOfSight(benchmark::State& state) {
  constexpr std::size_t count = 10000;
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  std::vector<EffectInstance> all = instances(ctx, count);
  for (EffectInstance& i : all) i.setUpdateInterval(std::uint32_t(state.range(0)));
  ctx.run(8);
  for (auto _ : state) ctx.step();
  state.counters["instances"] = double(count);
}

// The same particles as one group: the effect at `count` times the rate, one instance; with
// bounds (range 2) its bounds every step (kept by the pass: the same step or nearly).
void OneGroup(benchmark::State& state) {
  const auto count = std::size_t(state.range(0));
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  const Effect effect = parseEffect(sparks(kPerInstance * count));
  EffectInstance one = effect.instantiate(ctx, "all");
  one.setTransform(placeOf(1, 1));
  ctx.run(45);
  const bool bounds = state.range(2) != 0;
  float sink = 0.0f;
  double live = 0;
  const std::vector<EffectInstance> ones{one};
  const GroupStats::StepSeconds before = phaseSeconds(ones);
  for (auto _ : state) {
    ctx.step();
    if (bounds) sink += one.bounds().max.y;
    live += double(one.groups()[0]->size());
  }
  phaseCounters(state, before, phaseSeconds(ones));
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(std::int64_t(live));
  state.counters["live"] = live / double(state.iterations());
}

// Death events: a 1M-particle group of short-lived sparks (a third dying each step) with
// recording off (range 0 = 0) and on (1): the difference over the deaths is an event's cost.
void Deaths(benchmark::State& state) {
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  // Short lives (0.1 s, three steps): a third of the 1M die every step, so the events' cost
  // stands above the machine's noise.
  const Effect effect = parseEffect(sparks(kPerInstance * 10000 * 10, 0.1));
  EffectInstance one = effect.instantiate(ctx, "all");
  Group& g = *one.groups()[0];
  g.recordDeaths(state.range(0) != 0 ? g.capacity() : 0);
  ctx.run(45);
  double died = 0;
  for (auto _ : state) {
    const GroupStats before = g.stats();
    ctx.step();
    state.PauseTiming();
    died +=
        double(g.stats().killedByAge - before.killedByAge + g.stats().absorbed - before.absorbed);
    state.ResumeTiming();
  }
  benchmark::DoNotOptimize(g.deaths().data());
  state.counters["deaths"] = died / double(state.iterations());
  deathsPerStep_[state.range(1)] = died / double(state.iterations());
}

std::map<std::int64_t, double> collisionsPerStep_;  // Collisions' mean events a step, by threads

// Collision events: a 1M-particle group of sparks falling on a floor (a third of them are
// deflected every step, many resting on it) with recording off (range 0 = 0) and on (1): the
// difference over the events is an event's cost.
void Collisions(benchmark::State& state) {
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  const Effect effect = parseEffect(sparks(kPerInstance * 10000));
  EffectInstance one = effect.instantiate(ctx, "all");
  Group& g = *one.groups()[0];
  g.recordCollisions(state.range(0) != 0 ? 4 * g.capacity() : 0);
  ctx.run(45);
  double events = 0;
  for (auto _ : state) {
    ctx.step();
    events += double(g.collisions().size());
  }
  benchmark::DoNotOptimize(g.collisions().data());
  state.counters["events"] = events / double(state.iterations());
  if (state.range(0) != 0) collisionsPerStep_[state.range(1)] = events / double(state.iterations());
}

std::map<std::int64_t, double> trailParticles_;  // Trails' mean live particles, by threads

// Trails: the same 1M sparks keeping their last 8 positions (range 0 = 8) or none (0): the
// difference over the live particles is a trail's cost per particle and step (the ring's copy
// and, in compaction, its 24 lanes moved).
void Trails(benchmark::State& state) {
  ContextOptions o;
  o.threads = unsigned(state.range(1));
  Context ctx(o);
  const Effect effect = parseEffect(sparks(kPerInstance * 10000));
  EffectInstance one = effect.instantiate(ctx, "all");
  Group& g = *one.groups()[0];
  g.setTrail({.length = std::uint32_t(state.range(0))});
  ctx.run(45);
  double live = 0;
  for (auto _ : state) {
    ctx.step();
    live += double(g.size());
  }
  state.counters["live"] = live / double(state.iterations());
  if (state.range(0) != 0) trailParticles_[state.range(1)] = live / double(state.iterations());
}

void args(benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int bounds : {0, 1}) b->Args({10000, t, bounds});
    // A thousand instances stay in the caches between steps: their cost is the per-group
    // work alone, where ten thousand also wait on memory.
    b->Args({1000, t, 0});
    if (cores == 1) break;
  }
  b->ArgNames({"instances", "threads", "bounds"})->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(Instances)->Apply(args);
BENCHMARK(OneGroup)->Apply(args);
BENCHMARK(Moving)->Apply([](benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int move : {0, 1, 2}) b->Args({10000, t, move});
    if (cores == 1) break;
  }
  b->ArgNames({"instances", "threads", "move"})->Unit(benchmark::kMillisecond)->UseRealTime();
});
BENCHMARK(OutOfSight)->Apply([](benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int interval : {1, 4}) b->Args({interval, t});
    if (cores == 1) break;
  }
  b->ArgNames({"interval", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
});
BENCHMARK(Deaths)->Apply([](benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int record : {0, 1}) b->Args({record, t});
    if (cores == 1) break;
  }
  b->ArgNames({"record", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
});

BENCHMARK(Collisions)->Apply([](benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int record : {0, 1}) b->Args({record, t});
    if (cores == 1) break;
  }
  b->ArgNames({"record", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
});

BENCHMARK(Trails)->Apply([](benchmark::internal::Benchmark* b) {
  const auto cores = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int t : {1, cores}) {
    for (int length : {0, 8}) b->Args({length, t});
    if (cores == 1) break;
  }
  b->ArgNames({"length", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
});

// Prints the ratio of the medians (or single runs) of the two, per thread count.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (r.run_type == Run::RT_Iteration && r.repetitions > 1) continue;
      if (r.run_type == Run::RT_Aggregate && !median) continue;
      const std::string name = r.run_name.function_name + "/" + r.run_name.args;
      ms_[name] = r.GetAdjustedRealTime();
      const auto emit = r.counters.find("emit ms");
      if (emit != r.counters.end())
        phases_[name] = {emit->second.value, r.counters.at("act ms").value,
                         r.counters.at("compact ms").value};
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nSummary (medians of this run, CPU backend's %s build):\n", cpuInstructionSet());
    for (const auto& [name, ms] : ms_) {
      if (name.rfind("Instances/", 0) != 0) continue;
      const std::string args = name.substr(10);
      const auto one = ms_.find("OneGroup/" + args);
      if (one == ms_.end()) continue;
      std::printf(
          "  %s: %.2f ms a step, the same particles as one group %.2f ms: %.2fx (goal <= 1.5)\n",
          args.c_str(), ms, one->second, ms / one->second);
      // Where the time goes (the parts summed over the threads; the rest is Context::step's
      // own: scheduling, asking the memory ahead, timing).
      const auto pi = phases_.find(name), po = phases_.find("OneGroup/" + args);
      if (pi != phases_.end() && po != phases_.end())
        std::printf(
            "    emit / act / compact ms a step: instances %.2f / %.2f / %.2f, one group %.2f / "
            "%.2f / %.2f\n",
            pi->second[0], pi->second[1], pi->second[2], po->second[0], po->second[1],
            po->second[2]);
    }
    for (const auto& [name, ms] : ms_) {
      const std::string lod = "OutOfSight/interval:4/threads:";
      if (name.rfind(lod, 0) != 0) continue;
      const std::string threads = name.substr(lod.size());
      const auto every = ms_.find("OutOfSight/interval:1/threads:" + threads);
      if (every == ms_.end()) continue;
      std::printf(
          "  10,000 instances out of sight, threads:%s: a step every 4 frames %.2f ms a frame, "
          "every frame %.2f ms: %.2fx\n",
          threads.c_str(), ms, every->second, ms / every->second);
    }
    for (const auto& [name, ms] : ms_) {
      const std::string moved = "Moving/instances:10000/threads:";
      if (name.rfind(moved, 0) != 0 || name.substr(name.size() - 7) != "/move:1") continue;
      const std::string threads = name.substr(moved.size(), name.size() - 7 - moved.size());
      const auto same = ms_.find(moved + threads + "/move:2");
      const auto still = ms_.find(moved + threads + "/move:0");
      if (same == ms_.end() || still == ms_.end()) continue;
      std::printf(
          "  10,000 instances re-placed every step, threads:%s: moved %.2f ms (%.2fx), the same "
          "transform again %.2f ms (%.2fx), none set %.2f ms\n",
          threads.c_str(), ms, ms / still->second, same->second, same->second / still->second,
          still->second);
    }
    // What keeping the bounds costs: the same run with and without asking every step.
    for (const auto& [name, ms] : ms_) {
      const auto at = name.rfind("/bounds:1");
      if (at == std::string::npos) continue;
      const auto without = ms_.find(name.substr(0, at) + "/bounds:0");
      if (without == ms_.end()) continue;
      std::printf("  %s: bounds every step %.2f ms, none %.2f ms: %.3fx\n",
                  name.substr(0, at).c_str(), ms, without->second, ms / without->second);
    }
    // What a recorded death costs: the step with recording on less off, over the deaths.
    for (const auto& [name, ms] : ms_) {
      const auto at = name.find("Deaths/record:1/threads:");
      if (at != 0) continue;
      const std::string threads = name.substr(std::string("Deaths/record:1/threads:").size());
      const auto off = ms_.find("Deaths/record:0/threads:" + threads);
      const auto died = deathsPerStep_.find(std::stoll(threads));
      if (off == ms_.end() || died == deathsPerStep_.end() || died->second <= 0) continue;
      std::printf(
          "  death events, threads:%s: %.0f deaths a step, recorded %.3f ms, off %.3f ms: "
          "%.1f ns an event\n",
          threads.c_str(), died->second, ms, off->second, (ms - off->second) * 1e6 / died->second);
    }
    for (const auto& [name, ms] : ms_) {
      const std::string on = "Collisions/record:1/threads:";
      if (name.rfind(on, 0) != 0) continue;
      const std::string threads = name.substr(on.size());
      const auto off = ms_.find("Collisions/record:0/threads:" + threads);
      const auto hits = collisionsPerStep_.find(std::stoll(threads));
      if (off == ms_.end() || hits == collisionsPerStep_.end() || hits->second <= 0) continue;
      std::printf(
          "  collision events, threads:%s: %.0f a step, recorded %.3f ms, off %.3f ms: "
          "%.1f ns an event\n",
          threads.c_str(), hits->second, ms, off->second, (ms - off->second) * 1e6 / hits->second);
    }
    for (const auto& [name, ms] : ms_) {
      const std::string on = "Trails/length:8/threads:";
      if (name.rfind(on, 0) != 0) continue;
      const std::string threads = name.substr(on.size());
      const auto off = ms_.find("Trails/length:0/threads:" + threads);
      const auto live = trailParticles_.find(std::stoll(threads));
      if (off == ms_.end() || live == trailParticles_.end() || live->second <= 0) continue;
      std::printf(
          "  trails of 8, threads:%s: %.0f live, %.3f ms a step, none %.3f ms: %.2f ns a "
          "particle\n",
          threads.c_str(), live->second, ms, off->second, (ms - off->second) * 1e6 / live->second);
    }
  }

 private:
  std::map<std::string, double> ms_;
  std::map<std::string, std::array<double, 3>> phases_;  // emit, act, compact ms a step
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
