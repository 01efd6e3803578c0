// Scenes two benchmarks measure (bench_fountain on the CPU backend, bench_opencl on both):
// built once here so that both measure the same thing.
#pragma once

#include <string>

#include "flurry/flurry.hpp"

namespace flurry::bench {

/// n particles over 32 cells in a row (x from 0 to 128), bouncing under gravity on the floor
/// (y = 0) below them; the group is in cell order, as a level's particles are near their
/// emitters. The floor is `deflectors` rectangles side by side (a divisor of 32): with 32,
/// each cell's own, which only that cell's particles can reach; with 2, two halves, each
/// under 16 cells. Every particle bounces the same in both; spatial culling should make the
/// 32-piece list cost about what the 2-piece one costs (issue #17). Without culling every
/// particle tests every piece.
inline Group& deflectorCells(Context& ctx, std::size_t n, int deflectors) {
  constexpr int kCells = 32;
  Group& g = ctx.createGroup("cells", n);
  ActionList list;
  list.add(Gravity{});
  const float width = 4.0f * float(kCells) / float(deflectors);
  for (int j = 0; j < deflectors; ++j)
    list.add(Bounce{Domain::rectangle(Vec3(width * float(j), 0.0f, 0.0f), Vec3(width, 0.0f, 0.0f),
                                      Vec3(0.0f, 0.0f, 4.0f)),
                    1.0f, 0.0f, 0.0f});
  list.add(Move{});
  g.setActions(list);
  Random rng(7, 0, 0, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const float cell = float(i * kCells / n);
    Particle p;
    p.position = Vec3(4.0f * cell + 0.2f + 3.6f * rng.uniform(), 0.1f + 3.0f * rng.uniform(),
                      0.2f + 3.6f * rng.uniform());
    p.velocity = Vec3(0.0f, 4.0f * rng.uniform() - 2.0f, 0.0f);
    g.add(p);
  }
  return g;
}

/// A fountain-like group of about 1000 live particles at steady state: rate × lifetime =
/// 500/s × 2 s, gravity, a plane bounce, KillOld, Move (about 17 born and dying per step).
constexpr std::size_t kSmallLive = 1000;

inline Group& smallFountain(Context& ctx, const std::string& name) {
  Group& g = ctx.createGroup(name, kSmallLive + kSmallLive / 2);
  Emitter e;
  e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.1f);
  ParticleType t;
  t.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 8.0f, 0.0f), 1.5f);
  t.lifetime = Fuzzy::percent(2.0f, 10.0f);
  e.types = {t};
  e.rate = double(kSmallLive) / 2.0;
  g.addEmitter(e);
  g.setActions({Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f}, Move{},
                KillOld{}});
  return g;
}

/// `groups` small fountains of which `alive` keep emitting; the others played and are gone
/// after 3 s (a level's effects that have played). Run 90 steps at dt 1/30 before timing.
inline void levelOfEffects(Context& ctx, std::size_t groups, std::size_t alive) {
  for (std::size_t k = 0; k < groups; ++k) {
    Group& g = smallFountain(ctx, "group" + std::to_string(k));
    if (k % (groups / alive) != 0) g.emitters()[0].stop = 0.5;  // played, gone by 3 s
  }
}

}  // namespace flurry::bench
