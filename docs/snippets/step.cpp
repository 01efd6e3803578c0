// docs/snippets/step.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  flurry::Context ctx({.dt = 0.125});  // one step: t = 0 to 0.125 s
  flurry::Group& g = ctx.createGroup("g", 16);

  // Two emitters, one particle each, both born at t = 0.03125, inside the first step.
  flurry::Emitter lasting;
  lasting.bursts = {flurry::Burst{.time = 0.03125, .count = 1}};
  lasting.types[0].velocity = flurry::Domain::point({1, 0, 0});  // 1 unit/s along x
  lasting.types[0].lifetime = 5.0f;
  flurry::Emitter brief = lasting;
  brief.types[0].lifetime = 0.0625f;  // dies before the step ends
  g.addEmitter(lasting);
  g.addEmitter(brief);
  g.setActions({flurry::Move{}, flurry::KillOld{}});

  ctx.step();

  // The newborn ran Move for the 0.09375 s left after its birth; the brief one was born,
  // aged past its lifetime and was removed inside the same step.
  flurry::Particle p = g.particle(0);
  std::printf("%zu alive, age %g, x %g; killed by age %llu\n", g.size(), p.age, p.position.x,
              (unsigned long long)g.stats().killedByAge);
  bool ok =
      g.size() == 1 && p.age == 0.09375f && p.position.x == 0.09375f && g.stats().killedByAge == 1;
  return ok ? 0 : 1;
}
