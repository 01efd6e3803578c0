#include <cstdio>
#include <flurry/flurry.hpp>

int main() {
  flurry::Context ctx;
  flurry::Group& g = ctx.createGroup("sparks", 1000);
  flurry::Emitter e;
  e.rate = 300;
  g.addEmitter(e);
  g.setActions({flurry::Gravity{}, flurry::Move{}});
  ctx.run(30);
  std::printf("consumer: %zu particles\n", g.size());
  return g.size() == 300 ? 0 : 1;
}
