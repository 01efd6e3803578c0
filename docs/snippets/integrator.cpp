// docs/snippets/integrator.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cmath>
#include <cstdio>

// Position error after 2 s of gravity and drag at 4 steps a second.
static double projectileError(flurry::Integrator integrator) {
  flurry::Context ctx({.dt = 0.25});
  flurry::Group& g = ctx.createGroup("shot", 1);
  flurry::ActionList list{flurry::Gravity{{0, -9.81f, 0}}, flurry::Damping{{0.5f, 0.5f, 0.5f}},
                          flurry::Move{}};
  list.setIntegrator(integrator);
  g.setActions(list);
  g.add({.velocity = {3, 10, 0}});
  ctx.run(8);

  // The closed form: v(t) = g/k + (v0 - g/k)·e^(-kt), integrated.
  const double k = 0.5, t = 2.0, e = std::exp(-k * t);
  const double x = 3 * (1 - e) / k;
  const double y = -9.81 / k * t + (10 + 9.81 / k) * (1 - e) / k;
  flurry::Vec3 p = g.particle(0).position;
  return std::hypot(p.x - x, p.y - y);
}

int main() {
  double exact = projectileError(flurry::Integrator::Exact);
  double euler = projectileError(flurry::Integrator::SemiImplicitEuler);
  double rk4 = projectileError(flurry::Integrator::RK4);
  std::printf("error after 2 s at dt = 0.25 s: Exact %.1e, RK4 %.1e, default %.1e\n", exact, rk4,
              euler);

  // Exact is a closed form for Gravity, Damping and ElectricField only.
  try {
    flurry::ActionList swirl{flurry::Vortex{}, flurry::Move{}};
    swirl.setIntegrator(flurry::Integrator::Exact);
    return 1;
  } catch (const flurry::InvalidArgument& e) {
    std::printf("refused: %s (parameter \"%s\")\n", e.what(), e.parameter().c_str());
  }
  return exact < 1e-4 && rk4 < euler ? 0 : 1;
}
