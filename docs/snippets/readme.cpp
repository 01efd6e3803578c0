// docs/snippets/readme.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <algorithm>
#include <cstdio>

int main() {
  flurry::Context ctx({.seed = 7, .dt = 1.0 / 60});
  flurry::Group& water = ctx.createGroup("water", 100'000);

  flurry::Emitter nozzle;
  nozzle.shape = flurry::Domain::disc({0, 0, 0}, {0, 1, 0}, 0.1f);
  nozzle.position = {0, 0.01f, 0};  // above the floor, not on it
  nozzle.rate = 2000;               // particles per second, exact
  nozzle.types[0].velocity = flurry::Domain::cone({0, 0, 0}, {0, 8, 0}, 1.5f);
  nozzle.types[0].lifetime = flurry::Fuzzy::percent(3, 10);  // 3 s ± 10 %
  water.addEmitter(nozzle);

  water.setActions({flurry::Gravity{{0, -9.81f, 0}},
                    flurry::Bounce{flurry::Domain::plane({0, 0, 0}, {0, 1, 0}), 0.4f, 0.1f},
                    flurry::Move{}, flurry::KillOld{}});
  for (int frame = 0; frame < 300; ++frame) ctx.step();

  const flurry::Group& read = water;  // const: reading does not mark the particles changed
  std::span<const float> y = read.lane(flurry::Attribute::Position, 1);  // size() long
  float lowest = y.empty() ? 0.0f : *std::ranges::min_element(y);
  std::printf("%zu particles alive, lowest y %g\n", y.size(), lowest);
  return y.size() == water.size() && lowest >= 0 ? 0 : 1;  // none fell through the floor
}
