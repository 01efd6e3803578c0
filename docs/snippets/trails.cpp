// docs/snippets/trails.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  flurry::Context ctx({.dt = 1.0 / 60});
  flurry::Group& sparks = ctx.createGroup("sparks", 2000);
  flurry::Emitter grinder;
  grinder.rate = 400;
  grinder.types[0].velocity =
      flurry::Domain::cone(flurry::Vec3(0.0f), flurry::Vec3(6.0f, 3.0f, 0.0f), 2.0f);
  grinder.types[0].lifetime = 1.0f;
  grinder.types[0].color = flurry::Domain::point(flurry::Vec3(1.0f, 0.6f, 0.2f));
  sparks.addEmitter(grinder);
  sparks.require({flurry::Attribute::Color});
  sparks.setActions(
      {flurry::Gravity{flurry::Vec3(0, -9.81f, 0)}, flurry::Move{}, flurry::KillOld{}});
  // The last 12 positions of each spark: a ribbon 1 cm wide at the spark, a fifth of that
  // and transparent at its end.
  sparks.setTrail({.length = 12, .width = 0.01f, .taper = 0.2f, .fade = 0.0f});

  flurry::Strands ribbons;  // reused every frame: no allocation once grown
  for (int frame = 0; frame < 90; ++frame) {
    ctx.step();
    flurry::trailStrands(sparks, ribbons);
    // An engine uploads ribbons.position, .radius, .color and draws strand k from vertex
    // ribbons.start[k] to ribbons.start[k + 1] (flurry::render draws them itself).
  }
  std::printf("%zu sparks, %zu ribbons, %zu vertices\n", sparks.size(), ribbons.size(),
              ribbons.vertexCount());
  // A second-old spark has all 12 points; every live spark older than a step has a ribbon.
  return ribbons.size() + 10 > sparks.size() && ribbons.vertexCount() > 10 * ribbons.size() ? 0 : 1;
}
