// Run time against error: reference scenarios with known answers, swept over integrator ×
// time step. For every point it measures the run time per particle-step (median of
// repeated, timed runs) and the error against an analytic answer, or against a
// double-precision RK4 reference at a tiny step where there is none (the vortex).
//
//   build/release/bench/bench_accuracy --csv docs/accuracy/time-vs-error.csv
//   python3 scripts/plot_accuracy.py docs/accuracy/time-vs-error.csv docs/accuracy/
//
// Options: --csv FILE (else stdout), --summary FILE (the "10× at equal run time" table),
// --particles N (default 1024), --repeats R (default 5), --scenario NAME (repeatable),
// --quick (fewer steps and repeats: a smoke run).
//
// Every timed run is single-threaded (one particle-step costs the same on one core as on
// many, and a 2-core shared machine is quieter that way); a timed sample is at least
// ~5 ms of stepping (short simulations are run several times), and the figure is the
// median of the samples. The error comes from one more, untimed run (it is deterministic).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

const Integrator kIntegrators[] = {Integrator::ExplicitEuler, Integrator::SemiImplicitEuler,
                                   Integrator::VelocityVerlet, Integrator::RK4,
                                   Integrator::Exact};

// ---- Scenarios ------------------------------------------------------------------------------

// What one error run measured: the primary error (what the plot shows) and a secondary one
// (energy drift, radius error, ...), both dimensionless or in the units stated by the
// scenario; `lost` counts particles that did not survive (killed as non-finite).
struct Errors {
  double error = 0.0;
  double secondary = 0.0;
  std::size_t lost = 0;
};

struct Scenario {
  std::string name;
  std::string errorName;      ///< what `error` is
  std::string secondaryName;  ///< what `secondary` is
  double duration;            ///< simulated seconds
  std::vector<int> steps;     ///< the sweep: dt = duration / steps
  std::function<ActionList()> actions;
  /// The i-th of n initial particles (deterministic).
  std::function<Particle(std::size_t i, std::size_t n)> particle;
  /// Called after every step of the error run (may be empty).
  std::function<void(const Group&, double t)> observe;
  /// The errors after the run, from the final particles (by initial index) and the
  /// initial ones.
  std::function<Errors(const std::vector<std::optional<Particle>>& final,
                       const std::vector<Particle>& initial)>
      errors;
  std::function<void()> reset;  ///< clears the observer's state before an error run
};

double len(glm::dvec3 v) { return std::sqrt(glm::dot(v, v)); }
glm::dvec3 dv(Vec3 v) { return glm::dvec3(v); }

// Deterministic low-discrepancy numbers in [0, 1): the i-th point of a rank-1 lattice.
double frac(double x) { return x - std::floor(x); }
double u1(std::size_t i) { return frac(0.5 + double(i) * 0.6180339887498949); }
double u2(std::size_t i) { return frac(0.5 + double(i) * 0.7548776662466927); }
double u3(std::size_t i) { return frac(0.5 + double(i) * 0.5698402909980532); }

// Projectile with gravity and linear drag: dv/dt = g − k v, exact:
//   v(t) = g/k + (v0 − g/k) e^{−kt},  p(t) = p0 + (g/k) t + (v0 − g/k)(1 − e^{−kt})/k.
Scenario projectile() {
  static const glm::dvec3 g(0.0, -9.81, 0.0);
  static const double k = 0.5;
  Scenario s;
  s.name = "projectile";
  s.errorName = "max position error / range";
  s.secondaryName = "max velocity error / |v0|";
  s.duration = 2.0;
  s.steps = {8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
  s.actions = [] {
    return ActionList{Gravity{Vec3(g)}, Damping{Vec3(float(k))}, Move{}};
  };
  s.particle = [](std::size_t i, std::size_t) {
    const double speed = 5.0 + 15.0 * u1(i), elev = (15.0 + 60.0 * u2(i)) * kPi / 180.0,
                 az = 2.0 * kPi * u3(i);
    Particle p;
    p.position = Vec3(float(u1(i + 7)), 0.0f, float(u2(i + 7)));
    p.velocity = Vec3(float(speed * std::cos(elev) * std::cos(az)), float(speed * std::sin(elev)),
                      float(speed * std::cos(elev) * std::sin(az)));
    return p;
  };
  const double T = s.duration;
  s.errors = [T](const std::vector<std::optional<Particle>>& fin,
                 const std::vector<Particle>& init) {
    Errors e;
    const double E = std::exp(-k * T);
    for (std::size_t i = 0; i < init.size(); ++i) {
      if (!fin[i]) {
        ++e.lost;
        continue;
      }
      const glm::dvec3 p0 = dv(init[i].position), v0 = dv(init[i].velocity);
      const glm::dvec3 vt = g / k, v = vt + (v0 - vt) * E;
      const glm::dvec3 p = p0 + vt * T + (v0 - vt) * ((1.0 - E) / k);
      const double range = len(p - p0);
      e.error = std::max(e.error, len(dv(fin[i]->position) - p) / range);
      e.secondary = std::max(e.secondary, len(dv(fin[i]->velocity) - v) / len(v0));
    }
    return e;
  };
  return s;
}

// A circular orbit about OrbitPoint's softened pull a = M d/(|d|² + ε)^{3/2}: the circular
// speed is v² = M r²/(r² + ε)^{3/2}, the angular speed v/r, the energy
// v²/2 − M/sqrt(r² + ε). 1.37 periods of the r = 1 orbit: not a whole number, where
// semi-implicit Euler's (periodic) first-order error would vanish and flatter it.
Scenario orbit() {
  static const double M = 1.0, eps = 1e-3;
  Scenario s;
  s.name = "orbit";
  s.errorName = "max position error / r";
  s.secondaryName = "max |energy drift| / |E|";
  const double v1 = std::sqrt(M / std::pow(1.0 + eps, 1.5));
  s.duration = 1.37 * 2.0 * kPi / v1;
  s.steps = {16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192};
  s.actions = [] { return ActionList{OrbitPoint{Vec3(0.0f), float(M), float(eps)}, Move{}}; };
  s.particle = [](std::size_t i, std::size_t) {
    const double r = 0.8 + 0.45 * u1(i), phase = 2.0 * kPi * u2(i);
    const double v = std::sqrt(M * r * r / std::pow(r * r + eps, 1.5));
    Particle p;
    p.position = Vec3(float(r * std::cos(phase)), float(r * std::sin(phase)), 0.0f);
    p.velocity = Vec3(float(-v * std::sin(phase)), float(v * std::cos(phase)), 0.0f);
    return p;
  };
  const double T = s.duration;
  s.errors = [T](const std::vector<std::optional<Particle>>& fin,
                 const std::vector<Particle>& init) {
    Errors e;
    auto energy = [](glm::dvec3 p, glm::dvec3 v) {
      return 0.5 * glm::dot(v, v) - M / std::sqrt(glm::dot(p, p) + eps);
    };
    for (std::size_t i = 0; i < init.size(); ++i) {
      if (!fin[i]) {
        ++e.lost;
        continue;
      }
      // The analytic orbit from the float initial state (rounded onto a circle): radius and
      // phase from the position, speed from the radius.
      const glm::dvec3 p0 = dv(init[i].position);
      const double r = len(p0), phase = std::atan2(p0.y, p0.x);
      const double v = std::sqrt(M * r * r / std::pow(r * r + eps, 1.5)), w = v / r;
      const glm::dvec3 p(r * std::cos(phase + w * T), r * std::sin(phase + w * T), 0.0);
      e.error = std::max(e.error, len(dv(fin[i]->position) - p) / r);
      const double E0 = energy(p0, dv(init[i].velocity));
      const double E1 = energy(dv(fin[i]->position), dv(fin[i]->velocity));
      e.secondary = std::max(e.secondary, std::abs(E1 - E0) / std::abs(E0));
    }
    return e;
  };
  return s;
}

// A charge in a uniform magnetic field B ẑ: dv/dt = (q/m) v × B turns v about ẑ at
// ω = (q/m)|B| (clockwise for q > 0); the orbit is a helix of Larmor radius m v⊥/(|q| B).
// With w = vx + i vy: w(t) = w0 e^{−iωt}, (x + iy)(t) = (x + iy)0 + i w0 (e^{−iωt} − 1)/ω.
// 1.37 gyration periods (after whole turns the default integrator's chords close exactly
// and its first-order error would not show).
Scenario magnetic() {
  static const double B = 2.0, q = 1.0, m = 1.0, w = q * B / m;
  Scenario s;
  s.name = "magnetic";
  s.errorName = "max position error / Larmor radius";
  s.secondaryName = "max |guiding-centre distance - Larmor radius| / Larmor radius";
  s.duration = 1.37 * 2.0 * kPi / w;
  s.steps = {8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
  s.actions = [] { return ActionList{MagneticField{Vec3(0.0f, 0.0f, float(B))}, Move{}}; };
  s.particle = [](std::size_t i, std::size_t) {
    const double vperp = 1.0 + u1(i), dir = 2.0 * kPi * u2(i), vpar = 0.5 * (u3(i) - 0.5);
    Particle p;
    p.position = Vec3(float(u3(i + 3) - 0.5), float(u1(i + 3) - 0.5), 0.0f);
    p.velocity = Vec3(float(vperp * std::cos(dir)), float(vperp * std::sin(dir)), float(vpar));
    p.charge = float(q);
    p.mass = float(m);
    return p;
  };
  const double T = s.duration;
  s.errors = [T](const std::vector<std::optional<Particle>>& fin,
                 const std::vector<Particle>& init) {
    Errors e;
    using C = std::complex<double>;
    const C I(0.0, 1.0);
    for (std::size_t i = 0; i < init.size(); ++i) {
      if (!fin[i]) {
        ++e.lost;
        continue;
      }
      const glm::dvec3 p0 = dv(init[i].position), v0 = dv(init[i].velocity);
      const C w0(v0.x, v0.y), z0(p0.x, p0.y);
      const C z = z0 + I * w0 * (std::exp(-I * (w * T)) - 1.0) / w;
      const glm::dvec3 p(z.real(), z.imag(), p0.z + v0.z * T);
      const double R = m * std::abs(w0) / (std::abs(q) * B);
      e.error = std::max(e.error, len(dv(fin[i]->position) - p) / R);
      // The guiding centre: z0 − i w0/ω (where the orbit circles).
      const C c = z0 - I * w0 / w;
      const C zf(fin[i]->position.x, fin[i]->position.y);
      e.secondary = std::max(e.secondary, std::abs(std::abs(zf - c) - R) / R);
    }
    return e;
  };
  return s;
}

// A ball dropped from h0 onto the plane y = 0 with restitution e: apex n is at
// h_n = e^{2n} h0. The apex is read at the step where vy turns from up to down as
// y + vy²/(2g) (exact on a parabola), for the first three bounces. A step that bounces
// (vy ends above the free fall's vy − g·dt) may also hold an apex: the previous flight's if
// it began rising (read from the step's start), the new flight's if it ends falling.
Scenario bouncingBall() {
  static const double g = 9.81, e = 0.8;
  static const int kApexes = 3;
  struct State {
    std::vector<float> prevVy, prevY;
    double prevT = 0.0;
    std::vector<int> apexCount;
    std::vector<double> worst;
  };
  auto st = std::make_shared<State>();
  Scenario s;
  s.name = "bounce";
  s.errorName = "max apex height error / h0 (first 3 bounces)";
  s.secondaryName = "apexes missed";
  s.duration = 3.0;
  s.steps = {16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192};
  s.actions = [] {
    return ActionList{Gravity{Vec3(0.0f, float(-g), 0.0f)},
                      Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), float(e), 0.0f,
                             0.0f},
                      Move{}};
  };
  s.particle = [](std::size_t i, std::size_t) {
    Particle p;
    p.position = Vec3(float(u2(i) - 0.5), float(0.5 + u1(i)), float(u3(i) - 0.5));
    p.velocity = Vec3(float(u3(i + 1) - 0.5), 0.0f, float(u2(i + 1) - 0.5));
    return p;
  };
  s.reset = [st] {
    st->prevVy.clear();
    st->prevY.clear();
    st->prevT = 0.0;
    st->apexCount.clear();
    st->worst.clear();
  };
  // Needs the initial heights: the observer sees ids and heights; ids are 0..n-1 in the
  // order added (checked by the driver), so the initial height is recomputed from the id.
  auto h0 = [](std::size_t i) { return 0.5 + u1(i); };
  s.observe = [st, h0](const Group& grp, double t) {
    const double dt = t - st->prevT;
    st->prevT = t;
    const auto ids = grp.ids();
    const auto y = grp.lane(Attribute::Position, 1);
    const auto vy = grp.lane(Attribute::Velocity, 1);
    for (std::size_t j = 0; j < grp.size(); ++j) {
      const std::size_t i = ids[j];
      if (i >= st->prevVy.size()) {
        st->prevVy.resize(i + 1, 0.0f);
        st->prevY.resize(i + 1, float(h0(i)));
        st->apexCount.resize(i + 1, 0);
        st->worst.resize(i + 1, 0.0);
      }
      auto apexAt = [&](double py, double pvy) {
        if (st->apexCount[i] >= kApexes) return;
        const int n = ++st->apexCount[i];
        const double apex = py + pvy * pvy / (2.0 * g);
        const double want = std::pow(e, 2 * n) * h0(i);
        st->worst[i] = std::max(st->worst[i], std::abs(apex - want) / h0(i));
      };
      const double v0 = st->prevVy[i], v1 = vy[j];
      const bool bounced = v1 > v0 - 0.5 * g * dt;
      if (bounced && v0 > 0.0) apexAt(st->prevY[i], v0);
      if ((v0 > 0.0 || bounced) && v1 <= 0.0) apexAt(y[j], v1);
      st->prevVy[i] = vy[j];
      st->prevY[i] = y[j];
    }
  };
  s.errors = [st](const std::vector<std::optional<Particle>>& fin,
                  const std::vector<Particle>& init) {
    Errors r;
    for (std::size_t i = 0; i < init.size(); ++i) {
      if (!fin[i]) {
        ++r.lost;
        continue;
      }
      const int seen = i < st->apexCount.size() ? st->apexCount[i] : 0;
      r.secondary += double(kApexes - seen);
      if (seen < kApexes) r.error = std::max(r.error, 1.0);  // a missed apex: error 100 %
      if (i < st->worst.size()) r.error = std::max(r.error, st->worst[i]);
    }
    return r;
  };
  return s;
}

// The Vortex action: dv/dt = k (u(p) − v), dp/dt = v with u the documented Rankine field
// (solid-body inside coreRadius, aroundSpeed (coreRadius/r)^tightness outside, inSpeed
// towards the axis, upSpeed along it). No closed form: the reference is RK4 in double at
// dt = 1e-4 (its error, checked against dt = 2e-4, is below float rounding).
Scenario vortex() {
  static const Vortex V = [] {
    Vortex v;
    v.center = Vec3(0.0f);
    v.axis = Vec3(0.0f, 1.0f, 0.0f);
    v.aroundSpeed = 2.0f;
    v.coreRadius = 0.5f;
    v.tightness = 1.0f;
    v.inSpeed = 0.2f;
    v.upSpeed = 0.5f;
    v.responsiveness = 5.0f;
    return v;
  }();
  struct Ref {
    std::vector<glm::dvec3> p;  // by initial index
  };
  auto ref = std::make_shared<Ref>();
  Scenario s;
  s.name = "vortex";
  s.errorName = "max position error / initial radius";
  s.secondaryName = "reference self-check: |RK4(1e-4) - RK4(2e-4)| max";
  s.duration = 2.0;
  s.steps = {8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
  s.actions = [] { return ActionList{V, Move{}}; };
  s.particle = [](std::size_t i, std::size_t) {
    const double r = 1.0 + 0.5 * u1(i), phase = 2.0 * kPi * u2(i);
    Particle p;
    p.position = Vec3(float(r * std::cos(phase)), float(u3(i) - 0.5), float(r * std::sin(phase)));
    p.velocity = Vec3(0.0f);
    return p;
  };
  const double T = s.duration;
  // The documented field, in double.
  auto field = [](glm::dvec3 p) {
    const glm::dvec3 axis(0.0, 1.0, 0.0), w = p - dv(V.center);
    const glm::dvec3 radial = w - axis * glm::dot(w, axis);
    const double r = len(radial);
    const glm::dvec3 rhat = r > 0.0 ? radial / r : glm::dvec3(0.0);
    const double a = V.aroundSpeed, c = V.coreRadius;
    const double around = r < c ? a * r / c : a * std::pow(c / r, double(V.tightness));
    return glm::cross(axis, rhat) * around - rhat * double(V.inSpeed) + axis * double(V.upSpeed);
  };
  auto reference = [field, T](glm::dvec3 p, glm::dvec3 v, double h) {
    const double k = V.responsiveness;
    const int n = int(std::lround(T / h));
    auto acc = [&](glm::dvec3 q, glm::dvec3 u) { return (field(q) - u) * k; };
    for (int i = 0; i < n; ++i) {
      const glm::dvec3 k1p = v, k1v = acc(p, v);
      const glm::dvec3 k2p = v + k1v * (h / 2), k2v = acc(p + k1p * (h / 2), v + k1v * (h / 2));
      const glm::dvec3 k3p = v + k2v * (h / 2), k3v = acc(p + k2p * (h / 2), v + k2v * (h / 2));
      const glm::dvec3 k4p = v + k3v * h, k4v = acc(p + k3p * h, v + k3v * h);
      p += (k1p + k2p * 2.0 + k3p * 2.0 + k4p) * (h / 6);
      v += (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (h / 6);
    }
    return p;
  };
  s.errors = [ref, reference](const std::vector<std::optional<Particle>>& fin,
                              const std::vector<Particle>& init) {
    Errors e;
    if (ref->p.size() != init.size()) {  // computed once, for the first error run
      ref->p.resize(init.size());
      for (std::size_t i = 0; i < init.size(); ++i)
        ref->p[i] = reference(dv(init[i].position), dv(init[i].velocity), 1e-4);
    }
    // Self-check on a few particles: the reference against itself at twice the step.
    for (std::size_t i = 0; i < std::min<std::size_t>(init.size(), 8); ++i)
      e.secondary = std::max(
          e.secondary,
          len(reference(dv(init[i].position), dv(init[i].velocity), 2e-4) - ref->p[i]));
    for (std::size_t i = 0; i < init.size(); ++i) {
      if (!fin[i]) {
        ++e.lost;
        continue;
      }
      const glm::dvec3 p0 = dv(init[i].position);
      const double r0 = std::sqrt(p0.x * p0.x + p0.z * p0.z);
      e.error = std::max(e.error, len(dv(fin[i]->position) - ref->p[i]) / r0);
    }
    return e;
  };
  return s;
}

// ---- The driver -----------------------------------------------------------------------------

struct Options {
  std::string csv, summary;
  std::size_t particles = 1024;
  int repeats = 5;
  bool quick = false;
  std::vector<std::string> only;
};

// One simulation: a fresh context, the particles added, `steps` steps. Returns the seconds
// the steps took.
double simulate(const Scenario& s, Integrator integ, int steps, std::size_t n,
                std::vector<std::optional<Particle>>* fin, std::vector<Particle>* init,
                bool observe) {
  ContextOptions o;
  o.dt = s.duration / steps;
  o.threads = 1;
  Context ctx(o);
  Group& g = ctx.createGroup(s.name, n);
  ActionList list = s.actions();
  list.setIntegrator(integ);
  g.setActions(std::move(list));
  std::vector<Particle> start(n);
  for (std::size_t i = 0; i < n; ++i) {
    start[i] = s.particle(i, n);
    g.add(start[i]);
  }
  // ids are assigned in the order added: id - firstId is the initial index.
  std::uint32_t firstId = g.ids().empty() ? 0 : g.ids()[0];
  if (observe && firstId != 0) {
    std::fprintf(stderr, "bench_accuracy: ids do not start at 0 (%u)\n", firstId);
    std::exit(1);
  }
  const auto t0 = Clock::now();
  if (observe && s.observe) {
    for (int k = 0; k < steps; ++k) {
      ctx.step();
      s.observe(g, ctx.time());
    }
  } else {
    ctx.run(std::size_t(steps));
  }
  const double sec = std::chrono::duration<double>(Clock::now() - t0).count();
  if (fin) {
    fin->assign(n, std::nullopt);
    for (std::size_t j = 0; j < g.size(); ++j) {
      const std::uint32_t id = g.ids()[j] - firstId;
      if (id < n) (*fin)[id] = g.particle(j);
    }
  }
  if (init) *init = std::move(start);
  return sec;
}

struct Row {
  std::string scenario, integrator;
  double dt;
  int steps;
  std::size_t particles;
  double nsPerParticleStep, nsPerParticle;  // the second: to simulate the whole duration
  Errors err;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Euler's error at run time t, interpolated log-log between its points (nullopt outside).
std::optional<double> interpolate(const std::vector<const Row*>& curve, double t) {
  for (std::size_t k = 1; k < curve.size(); ++k) {
    double t0 = curve[k - 1]->nsPerParticle, t1 = curve[k]->nsPerParticle;
    double e0 = curve[k - 1]->err.error, e1 = curve[k]->err.error;
    if (t0 > t1) {
      std::swap(t0, t1);
      std::swap(e0, e1);
    }
    if (t < t0 || t > t1 || !(e0 > 0) || !(e1 > 0)) continue;
    if (t1 == t0) return e0;
    const double w = std::log(t / t0) / std::log(t1 / t0);
    return std::exp(std::log(e0) + w * (std::log(e1) - std::log(e0)));
  }
  return std::nullopt;
}

int parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--csv") o.csv = next();
    else if (a == "--summary") o.summary = next();
    else if (a == "--particles") o.particles = std::size_t(std::stoul(next()));
    else if (a == "--repeats") o.repeats = std::stoi(next());
    else if (a == "--scenario") o.only.push_back(next());
    else if (a == "--quick") o.quick = true;
    else {
      std::fprintf(stderr,
                   "usage: bench_accuracy [--csv FILE] [--summary FILE] [--particles N] "
                   "[--repeats R] [--scenario NAME]... [--quick]\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (const int rc = parse(argc, argv, opt); rc >= 0) return rc;
  if (opt.quick) {
    opt.repeats = std::min(opt.repeats, 3);
    opt.particles = std::min<std::size_t>(opt.particles, 256);
  }
  std::vector<Scenario> scenarios = {projectile(), orbit(), magnetic(), bouncingBall(), vortex()};
  std::vector<Row> rows;
  for (Scenario& s : scenarios) {
    if (!opt.only.empty() && std::find(opt.only.begin(), opt.only.end(), s.name) == opt.only.end())
      continue;
    if (opt.quick) {
      std::vector<int> fewer;
      for (std::size_t k = 0; k < s.steps.size(); k += 3) fewer.push_back(s.steps[k]);
      s.steps = fewer;
    }
    for (Integrator integ : kIntegrators) {
      try {
        ActionList probe = s.actions();
        probe.setIntegrator(integ);
      } catch (const InvalidArgument&) {
        continue;  // Exact for forces without a closed form
      }
      for (int steps : s.steps) {
        const std::size_t n = opt.particles;
        // Warm up (and size a sample to at least ~5 ms of stepping).
        const double once = simulate(s, integ, steps, n, nullptr, nullptr, false);
        const int inner = std::max(1, int(std::ceil(5e-3 / std::max(once, 1e-9))));
        std::vector<double> samples;
        for (int r = 0; r < opt.repeats; ++r) {
          double sec = 0.0;
          for (int k = 0; k < inner; ++k) sec += simulate(s, integ, steps, n, nullptr, nullptr, false);
          samples.push_back(sec / inner);
        }
        std::vector<std::optional<Particle>> fin;
        std::vector<Particle> init;
        if (s.reset) s.reset();
        simulate(s, integ, steps, n, &fin, &init, true);
        Row row;
        row.scenario = s.name;
        row.integrator = integratorName(integ);
        row.steps = steps;
        row.dt = s.duration / steps;
        row.particles = n;
        const double sec = median(samples);
        row.nsPerParticleStep = sec * 1e9 / (double(n) * steps);
        row.nsPerParticle = sec * 1e9 / double(n);
        row.err = s.errors(fin, init);
        std::fprintf(stderr, "%-10s %-17s dt=%-10.4g %8.2f ns/particle-step  error %.3e  (%s %.3e)%s\n",
                     s.name.c_str(), row.integrator.c_str(), row.dt, row.nsPerParticleStep,
                     row.err.error, s.secondaryName.c_str(), row.err.secondary,
                     row.err.lost ? (" lost " + std::to_string(row.err.lost)).c_str() : "");
        rows.push_back(row);
      }
    }
  }

  // The CSV.
  FILE* out = opt.csv.empty() ? stdout : std::fopen(opt.csv.c_str(), "w");
  if (!out) {
    std::perror(opt.csv.c_str());
    return 1;
  }
  std::fprintf(out,
               "scenario,integrator,dt,steps,particles,ns_per_particle_step,ns_per_particle,"
               "error,secondary,lost,error_metric,secondary_metric\n");
  std::map<std::string, const Scenario*> byName;
  for (const Scenario& s : scenarios) byName[s.name] = &s;
  for (const Row& r : rows) {
    const Scenario& s = *byName[r.scenario];
    std::fprintf(out, "%s,%s,%.9g,%d,%zu,%.4g,%.6g,%.6e,%.6e,%zu,\"%s\",\"%s\"\n",
                 r.scenario.c_str(), r.integrator.c_str(), r.dt, r.steps, r.particles,
                 r.nsPerParticleStep, r.nsPerParticle, r.err.error, r.err.secondary, r.err.lost,
                 s.errorName.c_str(), s.secondaryName.c_str());
  }
  if (out != stdout) std::fclose(out);

  // The summary: for each scenario and integrator, the largest factor by which it beats
  // explicit Euler's error at equal run time (Euler's curve interpolated log-log; only
  // where the run times overlap).
  FILE* sum = opt.summary.empty() ? nullptr : std::fopen(opt.summary.c_str(), "w");
  if (sum) std::fprintf(sum, "scenario,integrator,best_ratio,ns_per_particle,error,euler_error\n");
  std::fprintf(stderr, "\n%-10s %-17s %14s %16s %12s %12s\n", "scenario", "integrator",
               "Euler/this", "at ns/particle", "error", "Euler's");
  for (const Scenario& s : scenarios) {
    std::vector<const Row*> euler;
    for (const Row& r : rows)
      if (r.scenario == s.name && r.integrator == std::string("ExplicitEuler")) euler.push_back(&r);
    if (euler.empty()) continue;
    for (Integrator integ : kIntegrators) {
      if (integ == Integrator::ExplicitEuler) continue;
      double best = 0, at = 0, err = 0, eErr = 0;
      for (const Row& r : rows) {
        if (r.scenario != s.name || r.integrator != std::string(integratorName(integ))) continue;
        const auto e = interpolate(euler, r.nsPerParticle);
        if (!e || !(r.err.error > 0)) continue;
        if (*e / r.err.error > best) {
          best = *e / r.err.error;
          at = r.nsPerParticle;
          err = r.err.error;
          eErr = *e;
        }
      }
      if (best == 0) continue;
      std::fprintf(stderr, "%-10s %-17s %14.3g %16.4g %12.3e %12.3e\n", s.name.c_str(),
                   integratorName(integ), best, at, err, eErr);
      if (sum)
        std::fprintf(sum, "%s,%s,%.4g,%.6g,%.6e,%.6e\n", s.name.c_str(), integratorName(integ),
                     best, at, err, eErr);
    }
  }
  if (sum) std::fclose(sum);
  return 0;
}
