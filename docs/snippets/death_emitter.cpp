// docs/snippets/death_emitter.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  flurry::Context ctx;
  flurry::Group& rain = ctx.createGroup("rain", 4000);
  flurry::Emitter cloud;
  cloud.shape = flurry::Domain::box(flurry::Vec3(-2, 4, -2), flurry::Vec3(2, 5, 2));
  cloud.rate = 600;
  cloud.types[0].velocity = flurry::Domain::point(flurry::Vec3(0, -7, 0));
  rain.addEmitter(cloud);
  rain.setActions({flurry::Sink{flurry::Domain::plane(flurry::Vec3(0), flurry::Vec3(0, 1, 0)), 0.0f,
                                flurry::Sink::Mode::Hit},  // the ground: actions[0]
                   flurry::Move{}, flurry::KillOld{}});

  flurry::Group& splashes = ctx.createGroup("splashes", 8000);
  splashes.setActions(
      {flurry::Gravity{flurry::Vec3(0, -9.81f, 0)}, flurry::Move{}, flurry::KillOld{}});
  flurry::DeathEmitter splash;
  splash.source = "rain";
  splash.count = flurry::Fuzzy(3.0f, 1.0f);  // 2 to 4 droplets a drop
  splash.inheritVelocity = -0.1f;            // a little back up
  splash.cause = 0;                          // only the drops the ground took
  splash.types[0].velocity =
      flurry::Domain::cone(flurry::Vec3(0.0f), flurry::Vec3(0.0f, 1.5f, 0.0f), 0.8f);
  splash.types[0].lifetime = 0.4f;
  splashes.addDeathEmitter(splash);

  ctx.run(60);
  const auto& s = splashes.stats();
  const std::uint64_t hits = rain.stats().killedByAction[0];
  std::printf("%llu drops hit the ground, %llu splash droplets born, %zu in the air\n",
              (unsigned long long)hits, (unsigned long long)s.emitted, splashes.size());
  // 3 on average a drop: within a tenth.
  return hits > 100 && s.emitted > 2.7 * double(hits) && s.emitted < 3.3 * double(hits) ? 0 : 1;
}
