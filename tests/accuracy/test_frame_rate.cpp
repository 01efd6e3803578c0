// Frame-rate independence and integrator accuracy against analytic answers.
//
// Every tolerance below is stated with its reason. "Rounding" bounds are worst cases for
// float32 arithmetic: one step's update of a quantity of size X rounds by at most
// 2^-24·X (half an ulp), so N steps accumulate at most N·2^-24·X (we allow N·2^-23·X, twice
// that, for the one or two roundings per update).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec2.hpp>

#include "accuracy_util.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

constexpr double kUlp = 1.0 / (1 << 23);  // 2^-23: float's relative spacing at 1
const double kFrameRates[] = {24.0, 60.0, 240.0};

// Steps a fresh context at 1/fps for `seconds` (a whole number of steps) and returns the
// single particle's final state.
Particle runOne(const ActionList& list, const Particle& start, double fps, double seconds,
                Integrator integ = Integrator::SemiImplicitEuler) {
  Context ctx = makeContext(1.0 / fps, 1);
  Group& g = ctx.createGroup("g", 1);
  g.setActions(withIntegrator(list, integ));
  g.add(start);
  ctx.run(std::size_t(std::lround(seconds * fps)));
  EXPECT_EQ(g.size(), 1u);
  return g.particle(0);
}

}  // namespace

// ---- Drag is an exact exponential --------------------------------------------------------

// The classic API damps with v *= 1 − k·dt: for k = 0.5, one step of 1 s gives 0.5 and ten
// steps of 0.1 s give 0.95^10 = 0.599. Flurry applies exp(−k·dt): both give e^−0.5 = 0.6065.
TEST(FrameRate, DampingIsExactNotLinearised) {
  const ActionList list{Damping{Vec3(0.5f)}};
  const Particle start = particleAt(Vec3(0.0f), Vec3(1.0f, -2.0f, 4.0f));
  Context one = makeContext(1.0, 1), ten = makeContext(0.1, 1);
  Group& a = one.createGroup("a", 1);
  Group& b = ten.createGroup("b", 1);
  a.setActions(list);
  b.setActions(list);
  a.add(start);
  b.add(start);
  one.step();
  ten.run(10);
  const Vec3 va = a.particle(0).velocity, vb = b.particle(0).velocity;
  const double want = std::exp(-0.5);
  for (int d = 0; d < 3; ++d) {
    const double v0 = start.velocity[d];
    // 10 multiplications by a rounded exp(−0.05) (≤ 1 ulp each) plus the exp itself: 12 ulps.
    EXPECT_NEAR(va[d], v0 * want, 12 * kUlp * std::abs(v0)) << "axis " << d;
    EXPECT_NEAR(vb[d], v0 * want, 12 * kUlp * std::abs(v0)) << "axis " << d;
    EXPECT_NEAR(va[d], vb[d], 24 * kUlp * std::abs(v0)) << "axis " << d;
    // The classic API's numbers are far away.
    EXPECT_GT(std::abs(vb[d] - v0 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95 * 0.95),
              0.005 * std::abs(v0));
  }
}

// Pure drag stepped at 24, 60 and 240 Hz for one second: the velocity is v0·e^−k to rounding
// with the default integrator and with Exact; Exact also gets the position exactly
// (p0 + v0(1 − e^−k)/k), the default integrator to first order.
TEST(FrameRate, DragIsTheSameAtEveryFrameRate) {
  const float k = 1.5f;
  const ActionList list{Damping{Vec3(k)}, Move{}};
  const Particle start = particleAt(Vec3(1.0f, 2.0f, 3.0f), Vec3(4.0f, -3.0f, 2.0f));
  for (Integrator integ : {Integrator::SemiImplicitEuler, Integrator::Exact}) {
    for (double fps : kFrameRates) {
      SCOPED_TRACE(std::string(integratorName(integ)) + " at " + std::to_string(fps) + " Hz");
      const Particle p = runOne(list, start, fps, 1.0, integ);
      const double N = fps, E = std::exp(-double(k));
      for (int d = 0; d < 3; ++d) {
        const double v0 = start.velocity[d], p0 = start.position[d];
        // Velocity: N roundings of a product (rounding bound), plus exp's error per step.
        EXPECT_NEAR(p.velocity[d], v0 * E, 2 * N * kUlp * std::abs(v0));
        const double pw = p0 + v0 * (1 - E) / k;
        if (integ == Integrator::Exact) {
          // Position: N additions to a value of size ≤ |p0| + |v0|/k (rounding bound).
          EXPECT_NEAR(p.position[d], pw, 2 * N * kUlp * (std::abs(p0) + std::abs(v0) / k));
        } else {
          // Semi-implicit Euler moves with the end-of-step velocity: p_N = p0 + v0·dt·Σ e^{−jk·dt}
          // = p0 + v0(1 − e^−k)·k·dt·e^{−k·dt}/(1 − e^{−k·dt})/k: a first-order error
          // of about k·dt/2 of the distance travelled; allow k·dt of it.
          const double dt = 1.0 / fps;
          EXPECT_NEAR(p.position[d], pw, k * dt * std::abs(v0 * (1 - E) / k) + 1e-5);
        }
      }
    }
  }
}

// ---- Target-seeking actions cannot overshoot ------------------------------------------------

// rate·dt up to 100/24 ≈ 4.2: the classic x += (target − x)·rate·dt would overshoot 3×.
// Flurry's x += (target − x)(1 − e^{−rate·dt}) approaches monotonically and after T is
// target + (x0 − target)e^{−rate·T} at any frame rate.
TEST(FrameRate, TargetActionsNeverOvershoot) {
  for (float rate : {4.0f, 100.0f}) {
    for (double fps : kFrameRates) {
      SCOPED_TRACE("rate " + std::to_string(rate) + " at " + std::to_string(fps) + " Hz");
      Context ctx = makeContext(1.0 / fps, 1);
      Group& g = ctx.createGroup("g", 1);
      g.setActions({TargetVelocity{Vec3(1.0f, 2.0f, -3.0f), rate},
                    TargetRotVelocity{Vec3(0.0f, 5.0f, 0.0f), rate},
                    TargetColor{Vec3(0.0f, 0.5f, 1.0f), 0.0f, rate}, TargetSize{2.0f, rate}});
      Particle start = particleAt(Vec3(0.0f), Vec3(-4.0f, 0.0f, 6.0f));
      start.rotVelocity = Vec3(0.0f, -5.0f, 0.0f);
      start.color = Vec4(1.0f, 0.0f, 0.0f, 1.0f);
      start.size = 0.1f;
      g.add(start);
      const Vec3 tv(1.0f, 2.0f, -3.0f);
      const int steps = int(std::lround(0.5 * fps));
      for (int s = 0; s < steps; ++s) {
        ctx.step();
        const Particle p = g.particle(0);
        // Never past the target: each component stays on the start's side of it (or on it).
        for (int d = 0; d < 3; ++d) {
          EXPECT_GE((p.velocity[d] - tv[d]) * (start.velocity[d] - tv[d]), 0.0f) << "v" << d;
        }
        EXPECT_GE((p.rotVelocity.y - 5.0f) * (start.rotVelocity.y - 5.0f), 0.0f);
        EXPECT_GE(p.color.r, 0.0f);
        EXPECT_LE(p.color.g, 0.5f);
        EXPECT_LE(p.color.b, 1.0f);
        EXPECT_GE(p.color.a, 0.0f);
        EXPECT_LE(p.size, 2.0f);
      }
      const Particle p = g.particle(0);
      const double E = std::exp(-double(rate) * 0.5);
      // Rounding bound: steps products of a value of size ≤ |x0 − target| (≤ 10 here).
      const double tol = 2 * steps * kUlp * 10.0;
      for (int d = 0; d < 3; ++d)
        EXPECT_NEAR(p.velocity[d], tv[d] + (start.velocity[d] - tv[d]) * E, tol);
      EXPECT_NEAR(p.size, 2.0 + (0.1 - 2.0) * E, tol);
      EXPECT_NEAR(p.color.g, 0.5 + (0.0 - 0.5) * E, tol);
    }
  }
}

// The same promise for TargetVelocity under every integrator: it is one of the forces the
// non-default integrators gather into a(p, v), and its documentation says it never
// overshoots at any step size.
TEST(FrameRate, TargetVelocityNeverOvershootsUnderAnyIntegrator) {
  for (Integrator integ : kGeneralIntegrators) {
    for (double fps : kFrameRates) {
      SCOPED_TRACE(std::string(integratorName(integ)) + " at " + std::to_string(fps) + " Hz");
      Context ctx = makeContext(1.0 / fps, 1);
      Group& g = ctx.createGroup("g", 1);
      g.setActions(withIntegrator({TargetVelocity{Vec3(1.0f, 0.0f, 0.0f), 100.0f}, Move{}}, integ));
      g.add(particleAt(Vec3(0.0f), Vec3(-4.0f, 0.0f, 0.0f)));
      for (int s = 0; s < 12; ++s) {
        ctx.step();
        ASSERT_EQ(g.size(), 1u);
        const float v = g.particle(0).velocity.x;
        // 1e-6: rounding of the target value. One report per case: stop at the first.
        const bool ok = v <= 1.0f + 1e-6f && v >= -4.0f;
        EXPECT_TRUE(ok) << "velocity " << v << " left [-4, 1] at step " << s;
        if (!ok) break;
      }
    }
  }
}

// ---- Emission does not depend on dt ---------------------------------------------------------

// A rate of 10.5/s for 2 s gives floor(10.5·2) = 21 particles at any frame rate, born at the
// same times: an emitter moving at 1 m/s along x leaves each particle (velocity 0) at
// x = its birth time, and its age at the end is 2 s minus that.
TEST(FrameRate, EmissionCountsAndBirthTimesDoNotDependOnDt) {
  std::vector<std::vector<float>> births;
  for (double fps : kFrameRates) {
    SCOPED_TRACE(std::to_string(fps) + " Hz");
    Context ctx = makeContext(1.0 / fps, 1);
    Group& g = ctx.createGroup("g", 100);
    Emitter e;
    e.rate = 10.5;
    e.velocity = Vec3(1.0f, 0.0f, 0.0f);
    e.types[0].lifetime = 100.0f;
    g.addEmitter(e);
    g.setActions({Move{}, KillOld{}});
    const int steps = int(std::lround(2.0 * fps));
    ctx.run(steps);
    ASSERT_EQ(g.size(), 21u);
    EXPECT_EQ(g.stats().emitted, 21u);
    std::vector<float> x;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle p = g.particle(i);
      x.push_back(p.position.x);
      // age + birth time = 2 s. Rounding bound: the age is a sum of up to `steps` values
      // ≤ 2 s (steps·2^-23·2) plus the birth time's own rounding.
      EXPECT_NEAR(p.age + p.position.x, 2.0, 2 * steps * kUlp * 2.0 + 1e-6) << "particle " << i;
      EXPECT_EQ(p.position.y, 0.0f);
    }
    std::sort(x.begin(), x.end());
    births.push_back(x);
  }
  for (std::size_t k = 1; k < births.size(); ++k)
    for (std::size_t i = 0; i < births[0].size(); ++i)
      // The birth time k/10.5 computed in double and placed in float: 1 ulp at 2 m.
      EXPECT_NEAR(births[k][i], births[0][i], 4.0 * kUlp) << "birth " << i;
}

// ---- Integrators against analytic answers -----------------------------------------------------

namespace {

// Projectile with linear drag: v(t) = g/k + (v0 − g/k)e^{−kt},
// p(t) = p0 + (g/k)t + (v0 − g/k)(1 − e^{−kt})/k.
struct Projectile {
  glm::dvec3 g{0.0, -9.81, 0.0};
  double k = 0.5;
  glm::dvec3 p0{0.0, 1.0, 0.0}, v0{6.0, 8.0, 2.0};
  glm::dvec3 position(double t) const {
    const glm::dvec3 vt = g / k;
    return p0 + vt * t + (v0 - vt) * ((1 - std::exp(-k * t)) / k);
  }
  glm::dvec3 velocity(double t) const {
    const glm::dvec3 vt = g / k;
    return vt + (v0 - vt) * std::exp(-k * t);
  }
  // A bound on |dv/dt| = |g − k v| over [0, T]: |v| ≤ |v0| + |g|T.
  double amax(double T) const {
    return glm::length(g) + k * (glm::length(v0) + glm::length(g) * T);
  }
};

// The integrator's stated global error for the projectile over T with step dt:
//   first order (explicit and semi-implicit Euler): ≤ amax·T·dt/2 — exactly |g|·T·dt/2
//     without drag, since each step misses ±g·dt²/2;
//   velocity Verlet: exact for constant acceleration; the drag makes a second-order error
//     ≤ k·amax·T·dt² (the leading term is k·|a|·T·dt²/12: a factor of 12 of margin);
//   RK4: ≤ k³·amax·T·dt⁴ (leading term k⁴|v|·T·dt⁴/120);
//   Exact: 0.
// plus the float rounding of N steps of a position of size P: N·2^-23·P.
double statedError(Integrator integ, const Projectile& pr, double T, double dt) {
  const double a = pr.amax(T), k = pr.k;
  switch (integ) {
    case Integrator::SemiImplicitEuler:
    case Integrator::ExplicitEuler: return a * T * dt / 2;
    case Integrator::VelocityVerlet: return k * a * T * dt * dt;
    case Integrator::RK4: return k * k * k * a * T * dt * dt * dt * dt;
    case Integrator::Exact: return 0.0;
  }
  return 0.0;
}

}  // namespace

// The projectile stepped at 24, 60 and 240 Hz for 1.5 s under each integrator is within the
// integrator's stated error of the analytic answer (so the three runs agree within it).
TEST(Integrators, ProjectileWithinStatedError) {
  const Projectile pr;
  const double T = 1.5;
  const ActionList list{Gravity{Vec3(pr.g)}, Damping{Vec3(float(pr.k))}, Move{}};
  Particle start = particleAt(Vec3(pr.p0), Vec3(pr.v0));
  for (Integrator integ : kAllIntegrators) {
    std::vector<double> errors;
    for (double fps : kFrameRates) {
      SCOPED_TRACE(std::string(integratorName(integ)) + " at " + std::to_string(fps) + " Hz");
      const Particle p = runOne(list, start, fps, T, integ);
      const double dt = 1.0 / fps, N = T * fps;
      const double size = glm::length(pr.position(T)) + glm::length(pr.v0) * dt + 1.0;
      const double err = glm::length(glm::dvec3(p.position) - pr.position(T));
      const double bound = statedError(integ, pr, T, dt) + 2 * N * kUlp * size;
      EXPECT_LE(err, bound);
      errors.push_back(err);
    }
    // First-order methods converge at first order: 10× the rate gives ~10× less error
    // (between 7× and 13×: the drag's second-order terms shift it a little).
    if (integ == Integrator::SemiImplicitEuler || integ == Integrator::ExplicitEuler) {
      EXPECT_GT(errors[0] / errors[2], 7.0) << integratorName(integ);
      EXPECT_LT(errors[0] / errors[2], 13.0) << integratorName(integ);
    }
  }
}

// Order of convergence on a circular orbit (OrbitPoint), three quarters of a period at 24
// and 48 steps: halving dt divides the position error by about 2^p (p = 1, 1, 2, 4).
// Accepted bands are ±40 % around 2^p in the ratio (higher-order terms and rounding move
// it). Not a whole period: there semi-implicit Euler's first-order error (a periodic
// distortion of the orbit) vanishes and it looks second order.
TEST(Integrators, ConvergeAtTheirOrderOnAnOrbit) {
  const float M = 1.0f, eps = 1e-3f;
  const double r = 1.0, v = std::sqrt(M * r * r / std::pow(r * r + eps, 1.5)), w = v / r;
  const double period = 2 * M_PI / w;
  const ActionList list{OrbitPoint{Vec3(0.0f), M, eps}, Move{}};
  const Particle start = particleAt(Vec3(float(r), 0.0f, 0.0f), Vec3(0.0f, float(v), 0.0f));
  const struct {
    Integrator integ;
    double order;
  } cases[] = {{Integrator::SemiImplicitEuler, 1},
               {Integrator::ExplicitEuler, 1},
               {Integrator::VelocityVerlet, 2},
               {Integrator::RK4, 4}};
  for (const auto& c : cases) {
    double err[2];
    for (int k = 0; k < 2; ++k) {
      const int steps = 24 << k;
      Context ctx = makeContext(0.75 * period / steps, 1);
      Group& g = ctx.createGroup("g", 1);
      g.setActions(withIntegrator(list, c.integ));
      g.add(start);
      ctx.run(steps);
      ASSERT_EQ(g.size(), 1u);
      err[k] = glm::length(glm::dvec3(g.particle(0).position) - glm::dvec3(0.0, -r, 0.0));
    }
    const double ratio = err[0] / err[1], want = std::pow(2.0, c.order);
    EXPECT_GT(ratio, 0.6 * want) << integratorName(c.integ) << ": errors " << err[0] << ", " << err[1];
    EXPECT_LT(ratio, 1.4 * want) << integratorName(c.integ) << ": errors " << err[0] << ", " << err[1];
  }
}

// A charge in a magnetic field (default integrator: the exact rotation of v, then the move
// with the new velocity) stays on a circle at any frame rate. The polygon's vertices lie on
// a circle of radius R·(θ/2)/sin(θ/2), θ = ω·dt, so within θ²/24 of the Larmor radius
// R = m·v⊥/(|q|·B); its centre is the guiding centre turned about the start by θ/2 (the
// first chord already uses the turned velocity): R·θ/2 away. Checked for 3 turns, with 20 %
// margin on both and float rounding (1e-5·R) on every vertex's distance.
TEST(FrameRate, ChargeCirclesAtTheLarmorRadius) {
  const float B = 2.0f, q = 1.5f, m = 0.5f;
  const double w = q * B / m, vperp = 3.0, R = m * vperp / (q * B);
  for (double fps : kFrameRates) {
    SCOPED_TRACE(std::to_string(fps) + " Hz");
    Context ctx = makeContext(1.0 / fps, 1);
    Group& g = ctx.createGroup("g", 1);
    g.setActions({MagneticField{Vec3(0.0f, 0.0f, B)}, Move{}});
    Particle p = particleAt(Vec3(0.0f), Vec3(float(vperp), 0.0f, 0.0f));
    p.charge = q;
    p.mass = m;
    g.add(p);
    const double dt = 1.0 / fps, theta = w * dt;
    const int steps = int(3 * 2 * M_PI / theta);
    std::vector<glm::dvec2> path;
    for (int s = 0; s < steps; ++s) {
      ctx.step();
      const Particle now = g.particle(0);
      path.push_back(glm::dvec2(now.position.x, now.position.y));
      // Speed is conserved to rounding (the rotation is done in double).
      EXPECT_NEAR(glm::length(now.velocity), vperp, 1e-5);
    }
    // The circle through the first three vertices.
    const glm::dvec2 a = path[0], b = path[1], c = path[2];
    const double d = 2 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    const glm::dvec2 centre(
        (glm::dot(a, a) * (b.y - c.y) + glm::dot(b, b) * (c.y - a.y) + glm::dot(c, c) * (a.y - b.y)) / d,
        (glm::dot(a, a) * (c.x - b.x) + glm::dot(b, b) * (a.x - c.x) + glm::dot(c, c) * (b.x - a.x)) / d);
    const double radius = glm::length(a - centre);
    const double polygon = R * (theta / 2) / std::sin(theta / 2);
    EXPECT_NEAR(radius, polygon, 1e-4 * R);
    EXPECT_LE(std::abs(radius - R), 1.2 * R * theta * theta / 24 + 1e-5 * R);
    // Guiding centre for w = vx + i·vy turning as e^{−iωt}: z0 − i·w0/ω = (0, −R).
    EXPECT_LE(glm::length(centre - glm::dvec2(0.0, -R)), 1.2 * R * theta / 2);
    double worst = 0;
    for (const glm::dvec2& x : path) worst = std::max(worst, std::abs(glm::length(x - centre) - radius));
    EXPECT_LE(worst, 1e-4 * R) << "the vertices stay on one circle";
  }
}

// A ball dropped from h0 onto a plane with restitution e reaches apex n at e^{2n}·h0. The
// apex is read from the step where vy turns negative as y + vy²/2g (exact on a parabola).
// With the Eulers Bounce reflects the velocity the step has (not the one at the moment of
// impact, which differs by up to g·dt), so they are first order at a bounce: each bounce
// may change the energy height by up to v_impact·dt ≤ sqrt(2g·h0)·dt. Exact, Verlet and RK4
// reflect the velocity at impact on their parabola (Integrators.BounceIsExactUnderConstant-
// Gravity holds them to float error); this bound covers them with room. In flight, Exact, Verlet and RK4 are exact under constant
// gravity; for the Eulers y + vy²/2g drifts by g·dt²/2 per step (exactly, for semi-implicit
// Euler), g·t·dt/2 by time t. Allowed: g·t·dt + n·sqrt(2g·h0)·dt at apex n (2× the flight
// term for margin).
TEST(FrameRate, BouncingBallApexHeights) {
  const double g = 9.81, e = 0.8, h0 = 1.0;
  for (Integrator integ : kAllIntegrators) {
    for (double fps : kFrameRates) {
      SCOPED_TRACE(std::string(integratorName(integ)) + " at " + std::to_string(fps) + " Hz");
      Context ctx = makeContext(1.0 / fps, 1);
      Group& grp = ctx.createGroup("g", 1);
      grp.setActions(withIntegrator(
          {Gravity{Vec3(0.0f, float(-g), 0.0f)},
           Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), float(e), 0.0f, 0.0f},
           Move{}},
          integ));
      grp.add(particleAt(Vec3(0.0f, float(h0), 0.0f)));
      const double dt = 1.0 / fps;
      float prevVy = 0.0f;
      int apex = 0;
      const int steps = int(std::lround(2.5 * fps));
      for (int s = 0; s < steps && apex < 3; ++s) {
        ctx.step();
        const Particle p = grp.particle(0);
        EXPECT_GE(p.position.y, 0.0f) << "behind the deflector at step " << s;
        if (p.position.y < 0.0f) break;
        if (prevVy > 0.0f && p.velocity.y <= 0.0f) {
          ++apex;
          const double h = p.position.y + double(p.velocity.y) * p.velocity.y / (2 * g);
          const double tol = g * ctx.time() * dt + apex * std::sqrt(2 * g * h0) * dt;
          EXPECT_NEAR(h, std::pow(e, 2 * apex) * h0, tol) << "apex " << apex;
        }
        prevVy = p.velocity.y;
      }
      EXPECT_EQ(apex, 3) << "three apexes in 2.5 s";
    }
  }
}

// ---- Sub-stepping ---------------------------------------------------------------------------

// Sub-stepping a 24 Hz step into sub-steps of at most 1/240 s gives what stepping at 240 Hz
// gives (the same arithmetic, up to the rounding of dt/10 against 1/240: 1e-5 relative over
// two orbits), and a far smaller error than plain 24 Hz steps.
TEST(Substeps, MaxStepMatchesTheFinerFrameRate) {
  const float M = 1.0f, eps = 1e-3f;
  const double v = std::sqrt(M / std::pow(1.0 + eps, 1.5));
  const Particle start = particleAt(Vec3(1.0f, 0.0f, 0.0f), Vec3(0.0f, float(v), 0.0f));
  ActionList sub{OrbitPoint{Vec3(0.0f), M, eps}, Move{}};
  sub.setSubsteps(Substeps{1.0 / 240.0, 0.0f, 64});
  const Particle coarse = runOne(sub, start, 24.0, 2.0);
  const Particle fine = runOne({OrbitPoint{Vec3(0.0f), M, eps}, Move{}}, start, 240.0, 2.0);
  const Particle plain = runOne({OrbitPoint{Vec3(0.0f), M, eps}, Move{}}, start, 24.0, 2.0);
  EXPECT_LT(glm::length(coarse.position - fine.position), 1e-5f);
  EXPECT_LT(glm::length(coarse.velocity - fine.velocity), 1e-5f);
  EXPECT_GT(glm::length(plain.position - fine.position), 10 * glm::length(coarse.position - fine.position) + 1e-4f);
}
