// docs/snippets/game_loop.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

struct Vertex {
  float x, y, z, r, g, b, a, radius;
};

// Appends a group's live particles to a vertex buffer.
static void gather(const flurry::Group& group, std::vector<Vertex>& out) {
  using flurry::Attribute;
  auto x = group.lane(Attribute::Position, 0), y = group.lane(Attribute::Position, 1),
       z = group.lane(Attribute::Position, 2);
  auto r = group.lane(Attribute::Color, 0), g = group.lane(Attribute::Color, 1),
       b = group.lane(Attribute::Color, 2), a = group.lane(Attribute::Color, 3);
  auto radius = group.lane(Attribute::Size);
  for (std::size_t i = 0; i < group.size(); ++i)
    out.push_back({x[i], y[i], z[i], r[i], g[i], b[i], a[i], radius[i]});
}

int main() {
  flurry::Context ctx({.dt = 1.0 / 60});  // a fixed step, whatever the frame rate

  flurry::Group& sparks = ctx.createGroup("sparks", 4'000);
  flurry::Emitter torch;
  torch.rate = 1000;
  torch.types[0].velocity = flurry::Domain::sphere({0, 2, 0}, 1.0f);
  torch.types[0].color = flurry::Domain::point({1, 0.6f, 0.2f});
  torch.types[0].lifetime = 1.0f;
  sparks.addEmitter(torch);
  sparks.setActions({flurry::Gravity{}, flurry::Move{}, flurry::KillOld{}});

  flurry::Group& smoke = ctx.createGroup("smoke", 2'000);
  flurry::Emitter vent;
  vent.position = {3, 0, 0};
  vent.rate = 200;
  vent.types[0].velocity = flurry::Domain::cone({0, 0, 0}, {0, 1, 0}, 0.3f);
  vent.types[0].size = 0.2f;
  smoke.addEmitter(vent);
  smoke.setActions({flurry::Turbulence{}, flurry::Move{}, flurry::KillOld{}});

  // The renderer reads colour and size: ask both groups to store them.
  for (flurry::Group* g : ctx.groups())
    g->require({flurry::Attribute::Color, flurry::Attribute::Size});

  std::vector<Vertex> vertices;
  vertices.reserve(sparks.capacity() + smoke.capacity());  // no allocation in the loop

  const double frameTimes[] = {0.016, 0.021, 0.009, 0.034};  // what the game's clock measured
  double clock = 0, behind = 0;
  for (int frame = 0; frame < 240; ++frame) {
    double elapsed = std::min(frameTimes[frame % 4], 0.25);  // after a stall, don't catch up
    clock += elapsed;
    behind += elapsed;
    while (behind >= ctx.timeStep()) {  // as many fixed steps as the frame took
      ctx.step();
      behind -= ctx.timeStep();
    }
    vertices.clear();
    gather(sparks, vertices);
    gather(smoke, vertices);
    // draw(vertices) ...
  }
  std::printf("clock %.3f s, simulated %.3f s in %llu steps; %zu vertices\n", clock, ctx.time(),
              (unsigned long long)ctx.stepIndex(), vertices.size());
  bool ok = std::abs(clock - ctx.time()) < ctx.timeStep() &&
            vertices.size() == sparks.size() + smoke.size() && sparks.size() > 0 &&
            smoke.size() > 0;
  return ok ? 0 : 1;
}
