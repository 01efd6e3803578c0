// The random scene the culling tests of both backends share (tests/test_actions.cpp,
// tests/opencl/test_opencl_surfaces.cpp).
#pragma once

#include <cstdint>
#include <random>

#include "flurry/flurry.hpp"

namespace flurry::test {

// A scene of many finite deflectors, absorbers, blockers and falloff forces spread over
// [-50, 50]³, and particles among them, 2 % of them fast enough to cross several pieces in
// one step; `rounds` sets of five deflectors.
inline ActionList cullingScene(std::uint32_t seed, int rounds = 6) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), size(1.0f, 8.0f), unit(-1.0f, 1.0f);
  auto point = [&] { return Vec3(pos(rng), pos(rng), pos(rng)); };
  auto dir = [&] {
    Vec3 d(unit(rng), unit(rng), unit(rng));
    return glm::length(d) > 0.1f ? glm::normalize(d) : Vec3(0.0f, 1.0f, 0.0f);
  };
  ActionList list;
  Gravity g;
  g.falloff = {point(), size(rng) * 2.0f, 1.0f};
  list.add(g);
  Gravity wind{Vec3(3.0f, 0.0f, -2.0f), {point(), size(rng) * 2.0f, 2.0f}};
  list.add(wind);
  Damping d;
  d.rate = Vec3(0.5f);
  d.falloff = {point(), size(rng) * 2.0f, 1.0f};
  list.add(d);
  list.add(Block{Domain::box(point(), point())});
  for (int k = 0; k < rounds; ++k) {
    const Vec3 c = point();
    const float s = size(rng);
    list.add(Bounce{Domain::rectangle(c, dir() * s, dir() * s), 0.8f, 0.1f, 0.0f});
    list.add(Bounce{Domain::disc(point(), dir(), s, 0.2f * s), 0.5f, 0.0f, 0.0f});
    list.add(
        Bounce{Domain::triangle(point(), point() * 0.1f + c, c + dir() * s), 1.0f, 0.2f, 0.1f});
    list.add(Bounce{Domain::sphere(point(), s), 0.9f, 0.1f, 0.0f, k % 2 == 0});
    const Vec3 b = point();
    list.add(Bounce{Domain::box(b, b + Vec3(s)), 0.7f, 0.0f, 0.0f});
  }
  // A stack of close parallel discs: fast particles cross several in one step.
  const Vec3 stack = point();
  for (int k = 0; k < 4; ++k)
    list.add(Bounce{
        Domain::disc(stack + Vec3(0.7f * float(k), 0.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f), 10.0f),
        0.9f, 0.0f, 0.0f});
  list.add(Block{Domain::sphere(point(), size(rng))});
  Sink inside{Domain::sphere(point(), size(rng)), 0.0f, Sink::Mode::Inside};
  Sink enter{Domain::box(point(), point()), 0.3f, Sink::Mode::Enter};
  Sink leave{Domain::cylinder(point(), point(), size(rng)), 0.0f, Sink::Mode::Leave};
  Sink hit{Domain::disc(point(), dir(), size(rng)), 0.0f, Sink::Mode::Hit};
  list.add(inside);
  list.add(enter);
  list.add(leave);
  list.add(hit);
  list.add(Move{});
  return list;
}

/// `count` slow particles in a small patch and one fast one (id 1000) that reaches, in one
/// step of 0.1 s, a disc at x = 50 far from the others; a sphere no particle can reach.
inline void farDeflectorScene(Group& g, int count) {
  g.setActions({Bounce{Domain::disc(Vec3(50.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f), 2.0f)},
                Bounce{Domain::sphere(Vec3(0.0f, -500.0f, 0.0f), 1.0f)}, Move{}});
  for (int i = 0; i < count; ++i) {
    Particle p;
    p.position = Vec3(float(i % 16) * 0.01f, float(i / 16) * 0.01f - 0.5f, 0.0f);
    p.velocity = i == 1000 ? Vec3(600.0f, 0.0f, 0.0f) : Vec3(0.0f, 0.0f, 0.1f);
    p.position.y = i == 1000 ? 0.0f : p.position.y;
    g.add(p);
  }
}

/// After a step of farDeflectorScene: whether the fast particle was bounced by the far disc
/// (reflected, in front of it).
inline bool fastParticleBounced(const Group& g) {
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    if (p.id == 1000) return p.velocity.x < 0.0f && p.position.x < 50.0f;
  }
  return false;
}

}  // namespace flurry::test
