// docs/snippets/effect.cpp: built and run by tests/docs
#include <flurry/effect.hpp>
#include <flurry/flurry.hpp>

#include <cstdio>

int main() {
  flurry::Effect fx = flurry::loadEffect("campfire.json");  // throws flurry::EffectError
  for (const flurry::EffectWarning& w : fx.warnings)
    std::printf("warning: %s\n", w.message().c_str());

  flurry::Context ctx(fx.contextOptions());  // the effect's seed and dt
  std::vector<flurry::Group*> groups = fx.build(ctx);
  ctx.run(fx.frames);

  for (const flurry::Group* g : groups)
    std::printf("%s: %zu particles\n", g->name().c_str(), g->size());
  const flurry::Group& flames = ctx.group("flames");
  bool ok = fx.warnings.empty() && groups.size() == 2 && flames.size() > 0 &&
            flames.attributes().has(flurry::Attribute::Color) && ctx.group("smoke").size() > 0;
  return ok ? 0 : 1;
}
