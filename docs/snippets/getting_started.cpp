// docs/snippets/getting_started.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  // The context owns the groups, the seed, the step (seconds) and the worker threads.
  flurry::Context ctx({.seed = 1, .dt = 1.0 / 30});
  flurry::Group& water = ctx.createGroup("water", 20'000);  // a fixed capacity

  // What the emitter creates: velocity from a domain, scalars as fuzzy values.
  flurry::ParticleType drop;
  drop.velocity = flurry::Domain::cone({0, 0, 0}, {0, 8, 0}, 1.5f);  // up, spread 1.5 units/s
  drop.lifetime = flurry::Fuzzy::percent(3, 10);                     // 3 s ± 10 %
  drop.size = flurry::Fuzzy(0.03f, 0.01f);                           // radius 0.03 ± 0.01

  flurry::Emitter nozzle;
  nozzle.shape = flurry::Domain::disc({0, 0, 0}, {0, 1, 0}, 0.1f);  // where they are born
  nozzle.position = {0, 0.01f, 0};  // just above the floor: one born on it leaves it freely
  nozzle.rate = 2000;               // per second
  nozzle.types = {drop};
  water.addEmitter(nozzle);
  water.require({flurry::Attribute::Size});  // stored only if an action or a reader asks

  // What happens to them each step, in this order: forces, deflectors, Move, deaths.
  water.setActions({flurry::Gravity{{0, -9.81f, 0}},
                    flurry::Bounce{.surface = flurry::Domain::plane({0, 0, 0}, {0, 1, 0}),
                                   .restitution = 0.4f,
                                   .friction = 0.1f},
                    flurry::Move{}, flurry::KillOld{}});

  ctx.run(90);  // 90 steps: 3 s

  // Read the particles through a const reference: one array per component.
  const flurry::Group& g = water;
  std::span<const float> x = g.lane(flurry::Attribute::Position, 0);
  std::span<const float> y = g.lane(flurry::Attribute::Position, 1);
  std::span<const float> z = g.lane(flurry::Attribute::Position, 2);
  std::span<const float> size = g.lane(flurry::Attribute::Size);
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (y[i] < 0 || size[i] <= 0) return 1;  // the floor holds; every drop has a radius
  }
  std::printf("t = %.1f s: %zu drops, the first at (%.2f, %.2f, %.2f)\n", ctx.time(), g.size(),
              x[0], y[0], z[0]);

  // Every particle is accounted for.
  const flurry::GroupStats& s = g.stats();
  std::printf("emitted %llu = %zu alive + %llu killed by age\n", (unsigned long long)s.emitted,
              g.size(), (unsigned long long)s.killedByAge);
  return s.emitted == 6000 && s.emitted == g.size() + s.killedByAge ? 0 : 1;
}
