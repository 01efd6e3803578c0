// docs/snippets/instance.cpp: built and run by tests/docs
#include <flurry/effect.hpp>
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  flurry::Effect effect = flurry::parseEffect(R"({
    "groups": [{"name": "flames", "capacity": 2000,
                "emitters": [{"rate": 400, "shape": [0, 0, 0],
                              "types": [{"velocity": {"type": "cone", "base": [0, 1, 0],
                                                      "outerRadius": 0.3},
                                         "lifetime": 1}]}],
                "actions": [{"type": "Move"}, {"type": "KillOld"}]}]})");
  flurry::Context ctx(effect.contextOptions());

  flurry::EffectInstance torch = effect.instantiate(ctx, "torch7");
  torch.prewarm(2.0);  // already burning
  torch.setTransform({{4, 0, -2}, glm::angleAxis(0.5f, glm::vec3(0, 1, 0)), 1.0f});
  ctx.step();

  // World space: the flames born before the move stay at the origin, this step's are born
  // at the torch's new place, 4 m along x.
  const flurry::Group& flames = ctx.group("flames@torch7");
  const auto x = flames.lane(flurry::Attribute::Position, 0);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < flames.size(); ++i) moved += x[i] > 3.0f;
  std::printf("%zu flames, %zu born at the new place\n", flames.size(), moved);
  return flames.size() > 300 && moved > 5 && moved < 30 ? 0 : 1;
}
