// docs/snippets/concepts.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>
#include <memory>

int main() {
  flurry::Context ctx({.seed = 3, .dt = 1.0 / 30});
  flurry::Group& sparks = ctx.createGroup("sparks", 100'000);

  // A prime emitter emits emitters: shells that fly up, shed a trail and, at death, burst
  // sparks and spawn the next level of emitters (showers of showers).
  auto stars = std::make_shared<flurry::EmitterSpec>();
  stars->velocity = flurry::Domain::sphere({0, 0, 0}, 4.0f);
  stars->lifetime = 0.5f;
  stars->emitter.rate = 60;  // each star sheds 60 sparks a second while it lives
  stars->emitter.types[0].lifetime = 1.0f;

  flurry::PrimeEmitter launcher;
  launcher.bursts = {flurry::Burst{.time = 0, .count = 2, .interval = 1.0, .repeat = 3}};
  launcher.child.velocity = flurry::Domain::cone({0, 0, 0}, {0, 12, 0}, 2.0f);
  launcher.child.lifetime = 1.0f;
  launcher.child.emitter.rate = 100;  // the shell's trail
  launcher.child.emitter.types[0].lifetime = 1.0f;
  launcher.child.deathBurst = 200;   // sparks at the shell's death
  launcher.child.deathChildren = 8;  // and eight stars
  launcher.child.next = stars;
  sparks.addPrimeEmitter(launcher);

  sparks.setActions({
      // A force field: gravity everywhere, turbulence fading out 6 units from (0, 8, 0).
      flurry::Gravity{{0, -9.81f, 0}},
      flurry::Turbulence{.amplitude = 3, .frequency = 0.5f, .falloff = {{0, 8, 0}, 6, 1}},
      // An absorber: the ground takes the sparks that hit it, but lets a quarter through...
      flurry::Sink{.region = flurry::Domain::plane({0, 0, 0}, {0, 1, 0}),
                   .passThrough = 0.25f,
                   .mode = flurry::Sink::Mode::Hit},
      // ...onto a deflector one unit lower.
      flurry::Bounce{.surface = flurry::Domain::plane({0, -1, 0}, {0, 1, 0}), .restitution = 0.3f},
      flurry::Move{},
      // A blocker: particles inside the box are hidden, still simulated.
      flurry::Block{flurry::Domain::box({-2, -1, -2}, {2, 3, 2})},
      flurry::KillOld{},
  });
  ctx.run(120);

  const flurry::Group& g = sparks;
  const flurry::GroupStats& s = g.stats();
  std::span<const float> x = g.lane(flurry::Attribute::Position, 0);
  std::span<const float> y = g.lane(flurry::Attribute::Position, 1);
  std::span<const float> z = g.lane(flurry::Attribute::Position, 2);
  std::span<const std::uint32_t> visible = g.visible();
  std::size_t belowGround = 0, hiddenWrongly = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (y[i] < -1) return 1;  // the deflector holds
    belowGround += y[i] < 0;
    bool inBox = x[i] > -2 && x[i] < 2 && y[i] > -1 && y[i] < 3 && z[i] > -2 && z[i] < 2;
    hiddenWrongly += (visible[i] == 0) != inBox;
  }
  std::printf(
      "%zu alive; absorbed %llu, %zu passed the ground; emitters spawned %llu; "
      "sparks by generation:",
      g.size(), (unsigned long long)s.absorbed, belowGround, (unsigned long long)s.emittersSpawned);
  for (std::uint64_t n : s.emittedByGeneration) std::printf(" %llu", (unsigned long long)n);
  std::printf("\n");
  bool ok =
      s.absorbed > 0 && belowGround > 0 && hiddenWrongly == 0 &&
      s.emittedByGeneration.size() == 3 && s.emittedByGeneration[1] > 0 &&
      s.emittedByGeneration[2] > 0 &&
      s.emitted == g.size() + s.killedByAge + s.absorbed + s.droppedAtCapacity + s.killedNonFinite;
  return ok ? 0 : 1;
}
