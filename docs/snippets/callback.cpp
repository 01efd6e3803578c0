// docs/snippets/callback.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <algorithm>
#include <cstdio>

int main() {
  flurry::Context ctx;  // Backend::Cpu; the same list runs on Backend::OpenCL
  flurry::Group& g = ctx.createGroup("lift", 5000);
  flurry::Emitter e;
  e.rate = 1000;
  e.types[0].velocity = flurry::Domain::sphere(flurry::Vec3(0, 3, 0), 0.5f);
  g.addEmitter(e);
  // One body, C++ here and OpenCL C on a device: above 1.5 m a particle drifts east and
  // counts the seconds it spent there (naming `user` makes the group store UserData).
  const flurry::Callback lift = FLURRY_CALLBACK(
      if (py > 1.5f) {
        vx = fmin(vx + 0.5f * dt, 2.0f);
        user += dt;
      });
  g.setActions({flurry::Gravity{flurry::Vec3(0, -2, 0)}, lift, flurry::Move{}});
  ctx.run(60);
  float most = 0;
  for (std::size_t i = 0; i < g.size(); ++i) most = std::max(most, g.particle(i).userData);
  std::printf("%zu particles, the longest above 1.5 m: %.2f s\n", g.size(), most);
  return g.attributes().has(flurry::Attribute::UserData) && most > 0 ? 0 : 1;
}
