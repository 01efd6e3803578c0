#include "builtin.hpp"

namespace flurry::samples {

Group& buildFountain(Context& ctx, std::size_t capacity, double rate, float lifetime) {
  Group& g = ctx.createGroup("fountain", capacity);
  Emitter e;
  e.name = "nozzle";
  e.shape = Domain::disc(Vec3(0.0f, 0.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.1f);
  e.rate = rate;
  ParticleType water;
  water.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 8.0f, 0.0f), 1.5f);
  water.lifetime = Fuzzy::percent(lifetime, 10.0f);
  water.color = Domain::box(Vec3(0.6f, 0.7f, 0.9f), Vec3(0.7f, 0.8f, 1.0f));
  water.size = Fuzzy(0.03f, 0.01f);
  e.types = {water};
  g.addEmitter(e);
  g.setActions({Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f},
                Move{}, KillOld{}});
  return g;
}

const std::vector<Sample>& builtinSamples() {
  static const std::vector<Sample> samples = {
      {"fountain", "a water fountain: disc emitter, gravity, a bouncy ground, death by age",
       [](Context& ctx, std::size_t capacity) { buildFountain(ctx, capacity, 2000.0, 3.0f); }},
  };
  return samples;
}

const Sample* findSample(const std::string& name) {
  for (const auto& s : builtinSamples())
    if (s.name == name) return &s;
  return nullptr;
}

}  // namespace flurry::samples
