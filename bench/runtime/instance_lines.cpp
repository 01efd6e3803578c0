// What one step of an effect instance asks of the memory: the cache lines of its state, of
// what its vectors hold and of its lanes. Run under Valgrind's lackey by
// scripts/instance_lines.py, which reads the step's loads and stores between the two marks
// this program makes and counts the lines touched in each region it names here.
//
//   instance_lines [INSTANCES]    (10 by default; the regions are instance INSTANCES / 2's)
//   instance_lines INSTANCES one  (the same particles as one group, stepped as many times,
//                                  no marks: the baseline for an instruction count, e.g.
//                                  valgrind --tool=callgrind
//                                  --toggle-collect='flurry::Context::step()' on both)
//
// Prints "MARK address" (a word written just before and just after the step) and, per region,
// "REGION name address bytes", on stderr.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "group_impl.hpp"
#include "sparks.hpp"

using namespace flurry;

namespace {

volatile int mark = 0;

void region(const char* name, const void* at, std::size_t bytes) {
  if (at && bytes > 0) std::fprintf(stderr, "REGION %s %p %zu\n", name, at, bytes);
}
template <class V>
void vectorRegion(const char* name, const V& v) {
  region(name, v.data(), v.size() * sizeof(v[0]));
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t count = argc > 1 ? std::size_t(std::atoi(argv[1])) : 10;
  if (count < 1 || count > 100000) {
    std::fprintf(stderr, "instance_lines: INSTANCES must be 1 to 100000\n");
    return 2;
  }
  ContextOptions o;
  o.threads = 1;
  Context ctx(o);
  if (argc > 2 && std::string(argv[2]) == "one") {
    EffectInstance one =
        parseEffect(bench::sparks(bench::kPerInstance * count)).instantiate(ctx, "one");
    one.setTransform(bench::placeOf(0, 1));
    ctx.run(46);  // as many steps as the instances take below
    return 0;
  }
  const Effect effect = parseEffect(bench::sparks(bench::kPerInstance));
  std::vector<EffectInstance> all;
  for (std::size_t k = 0; k < count; ++k) {
    all.push_back(effect.instantiate(ctx, std::to_string(k)));
    all.back().setTransform(bench::placeOf(k, count));
  }
  ctx.run(45);  // births and deaths balance

  const detail::GroupImpl& g = detail::implOf(*all[count / 2].groups()[0]);
  std::fprintf(stderr, "MARK %p\n", static_cast<const void*>(const_cast<const int*>(&mark)));
  // The state up to its lane table (which a step does not read: laneCache).
  region("state", &g,
         std::size_t(reinterpret_cast<const char*>(&g.lanes) - reinterpret_cast<const char*>(&g)));
  vectorRegion("actions", g.actions.actions());
  vectorRegion("emitters", g.emitters);
  for (const Emitter& e : g.emitters) vectorRegion("emitter.types", e.types);
  vectorRegion("emitterState", g.emitterState);
  vectorRegion("stats.killedByAction", g.stats.killedByAction);
  vectorRegion("stats.emittedByGeneration", g.stats.emittedByGeneration);
  vectorRegion("bornRemaining", g.bornRemaining);
  region("holes", g.holes.data(), g.holes.capacity() * sizeof(std::uint32_t));
  vectorRegion("plan.records", g.plan.records);
  vectorRegion("plan.gathered", g.plan.gathered);
  vectorRegion("plan.curvedBy", g.plan.curvedBy);
  vectorRegion("plan.timeFree", g.plan.timeFree);
  vectorRegion("plan.reach", g.plan.reach);
  vectorRegion("plan.moves", g.plan.moves);
  if (g.frame) region("frame", g.frame.get(), sizeof(detail::Frame));
  detail::forEachSlot(g.laneCache, g.laneSlots, [&](const std::uint32_t* lane) {
    region("lane", lane, g.capacity * sizeof(float));
  });
  mark = 1;
  ctx.step();
  mark = 2;
  return 0;
}
