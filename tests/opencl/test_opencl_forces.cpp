// Parity on the device: Forces, random and target actions, curves over life (kernels/forces.cl).
// Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp), and
// first makes sure, on the CPU, that the action under test changes the particles (a test of
// an action that does nothing could not fail).
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

// Whether two runs differ beyond the parity tolerance in some particle.
Build build(ActionList actions, Emitter e, AttributeSet require) {
  return [=](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("forces", 20000);
    g.addEmitter(e);
    g.setActions(actions);
    g.require(require);
    return g;
  };
}

// Parity of `actions`, each of whose actions `tested` must change the particles (on the CPU,
// against the same list without it). Prints the largest |cpu - opencl| of the run.
void check(const ActionList& actions, std::vector<std::size_t> tested, Emitter e = spray(),
           AttributeSet require = {}) {
  FLURRY_REQUIRE_OPENCL();
  const RunResult all = runEffect(Backend::Cpu, build(actions, e, require), kSteps);
  for (std::size_t t : tested)
    EXPECT_TRUE(differs(
        all, runEffect(Backend::Cpu, build(withoutAction(actions, t), e, require), kSteps), 10))
        << "actions[" << t << "] (" << actionName(actions.actions()[t])
        << ") does not change the particles: the test proves nothing";
  if (::testing::Test::HasFailure()) return;
  checkParityReporting(build(actions, e, require));
}

void check(const ActionList& actions, std::size_t tested, Emitter e = spray(),
           AttributeSet require = {}) {
  check(actions, std::vector<std::size_t>{tested}, e, require);
}

// Charged particles of different masses (some massless: they feel no field).
Emitter charged() {
  Emitter e = spray();
  e.types[0].charge = Fuzzy(0.0f, 2.0f);
  e.types[0].mass = Fuzzy(0.6f, 0.5f);
  return e;
}

// Particles with angular velocity, color and size drawn at birth.
Emitter decorated() {
  Emitter e = spray();
  e.types[0].rotVelocity = Domain::sphere(Vec3(0.0f), 4.0f);
  e.types[0].color = Domain::box(Vec3(0.0f), Vec3(1.0f));
  e.types[0].alpha = Fuzzy(0.5f, 0.4f);
  e.types[0].size = Fuzzy(0.2f, 0.1f);
  return e;
}

const AttributeSet kDecorated{Attribute::RotVelocity, Attribute::Color, Attribute::Size};

std::shared_ptr<const VectorField> grid() {
  auto f = std::make_shared<VectorField>();
  f->origin = Vec3(-2.0f, -0.5f, -2.5f);
  f->voxelSize = 0.9f;
  f->dims = glm::ivec3(4, 3, 5);
  for (int k = 0; k < 4 * 3 * 5; ++k)
    f->data.push_back(
        Vec3(std::sin(0.7f * k) * 3.0f, std::cos(1.3f * k) * 2.0f + 1.0f, float(k % 7) - 3.0f));
  return f;
}

const Falloff kFalloff{Vec3(0.3f, 2.5f, 0.0f), 3.0f, 1.0f};
const Falloff kFalloffPow{Vec3(-0.2f, 3.0f, 0.4f), 3.5f, 2.5f};

}  // namespace

// ---- Gravity and Damping with a falloff --------------------------------------------------

TEST(OpenCLForces, GravityFalloff) {
  check({Gravity{Vec3(3.0f, -9.81f, 1.0f), kFalloff}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLForces, GravityFalloffPower) {
  check({Gravity{kDown}, Gravity{Vec3(0.0f, 20.0f, 4.0f), kFalloffPow}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLForces, DampingFalloff) {
  check({Gravity{kDown}, Damping{Vec3(0.5f, 2.0f, 4.0f), kFalloffPow}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLForces, RotDamping) {
  check({RotDamping{Vec3(0.3f, 1.0f, 2.5f)}, Gravity{kDown}, Move{}, KillOld{}}, 0, decorated(),
        kDecorated);
}

// ---- Attractors and fields -----------------------------------------------------------------

TEST(OpenCLForces, OrbitPoint) {
  check({OrbitPoint{Vec3(0.5f, 3.0f, 0.0f), 25.0f, 0.1f, 4.0f}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLForces, OrbitLine) {
  check({OrbitLine{Vec3(0.5f, 0.0f, 0.0f), Vec3(0.2f, 1.0f, 0.1f), 12.0f, 0.05f, 3.0f}, Move{},
         KillOld{}},
        0);
}

TEST(OpenCLForces, Vortex) {
  check({Vortex{Vec3(0.0f), Vec3(0.1f, 1.0f, 0.0f), 4.0f, 0.5f, 0.8f, 1.0f, 0.5f, 3.0f, 4.0f},
         Gravity{Vec3(0.0f, -2.0f, 0.0f)}, Move{}, KillOld{}},
        0);
}

TEST(OpenCLForces, JetRandom) {
  check({Gravity{kDown},
         Jet{Vec3(0.0f, 3.0f, 0.0f), 1.5f, Domain::sphere(Vec3(2.0f, 6.0f, 0.0f), 5.0f)}, Move{},
         KillOld{}},
        1);
}

TEST(OpenCLForces, JetConstant) {
  check({Gravity{kDown}, Jet{Vec3(0.3f, 2.0f, 0.0f), 1.0f, Domain::point(Vec3(4.0f, 12.0f, -2.0f))},
         Move{}, KillOld{}},
        1);
}

// Late in the run, so that the particles it pushes are still alive at the end.
TEST(OpenCLForces, Explosion) {
  check({Explosion{Vec3(0.0f, 2.0f, 0.3f), 3.0f, 30.0f, 0.5f, 1e-3f, 5.6f}, Gravity{kDown}, Move{},
         KillOld{}},
        0);
}

// ---- Random actions: uniform draws (sphere, box, cone) and Box-Muller (blob) -------------

TEST(OpenCLForces, RandomAccel) {
  check({RandomAccel{Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 6.0f)}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLForces, RandomAccelBlobFalloff) {
  check({Gravity{kDown}, RandomAccel{Domain::blob(Vec3(1.0f, 0.0f, 0.0f), 8.0f), kFalloffPow},
         Move{}, KillOld{}},
        1);
}

TEST(OpenCLForces, RandomDisplace) {
  check({Gravity{kDown},
         RandomDisplace{Domain::box(Vec3(-1.0f, -0.5f, -2.0f), Vec3(2.0f, 1.0f, 1.0f))}, Move{},
         KillOld{}},
        1);
}

TEST(OpenCLForces, RandomVelocity) {
  check({RandomVelocity{Domain::cone(Vec3(0.0f), Vec3(0.5f, 3.0f, 0.0f), 1.5f)}, Move{}, KillOld{}},
        0);
}

TEST(OpenCLForces, RandomRotVelocity) {
  check({Gravity{kDown},
         RandomRotVelocity{Domain::cylinder(Vec3(0.0f), Vec3(0.0f, 2.0f, 1.0f), 3.0f)}, Move{},
         KillOld{}},
        1, decorated(), kDecorated);
}

// ---- Turbulence (curl noise) ---------------------------------------------------------------

TEST(OpenCLForces, Turbulence) {
  check({Turbulence{4.0f, 0.8f, 3, Vec3(0.5f, 0.0f, 0.2f)}, Gravity{kDown}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLForces, TurbulenceFalloff) {
  check({Turbulence{6.0f, 1.7f, 1, Vec3(0.0f, 1.0f, 0.0f), kFalloffPow}, Gravity{kDown}, Move{},
         KillOld{}},
        0);
}

// ---- Charged particles ---------------------------------------------------------------------

TEST(OpenCLForces, ElectricField) {
  check({ElectricField{Vec3(3.0f, 0.0f, -1.0f)}, Gravity{kDown}, Move{}, KillOld{}}, 0, charged());
}

TEST(OpenCLForces, ElectricFieldFalloff) {
  check({ElectricField{Vec3(5.0f, 2.0f, 0.0f), kFalloffPow}, Gravity{kDown}, Move{}, KillOld{}}, 0,
        charged());
}

TEST(OpenCLForces, MagneticField) {
  check(
      {MagneticField{Vec3(0.5f, 2.5f, 1.0f)}, Gravity{Vec3(0.0f, -2.0f, 0.0f)}, Move{}, KillOld{}},
      0, charged());
}

TEST(OpenCLForces, MagneticFieldFalloff) {
  check({MagneticField{Vec3(0.0f, 0.0f, 6.0f), kFalloff}, Gravity{Vec3(0.0f, -2.0f, 0.0f)}, Move{},
         KillOld{}},
        0, charged());
}

// ---- A sampled grid --------------------------------------------------------------------------

TEST(OpenCLForces, SampledFieldAcceleration) {
  SampledField f;
  f.field = grid();
  f.strength = 1.5f;
  check({f, Gravity{Vec3(0.0f, -3.0f, 0.0f)}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLForces, SampledFieldVelocityFalloff) {
  SampledField f;
  f.field = grid();
  f.mode = SampledField::Mode::Velocity;
  f.responsiveness = 2.0f;
  f.falloff = kFalloffPow;
  check({Gravity{kDown}, f, Move{}, KillOld{}}, 1);
}

// ---- Targets, clamps, curves -----------------------------------------------------------------

TEST(OpenCLForces, TargetVelocity) {
  check({Gravity{kDown}, TargetVelocity{Vec3(1.0f, 2.0f, -0.5f), 1.5f}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLForces, TargetRotVelocity) {
  check({TargetRotVelocity{Vec3(0.0f, 5.0f, 1.0f), 0.7f}, Gravity{kDown}, Move{}, KillOld{}}, 0,
        decorated(), kDecorated);
}

TEST(OpenCLForces, TargetColor) {
  check({TargetColor{Vec3(0.2f, 0.9f, 0.4f), 0.1f, 1.2f}, Gravity{kDown}, Move{}, KillOld{}}, 0,
        decorated(), kDecorated);
}

TEST(OpenCLForces, TargetSize) {
  check({TargetSize{1.5f, 0.6f}, Gravity{kDown}, Move{}, KillOld{}}, 0, decorated(), kDecorated);
}

TEST(OpenCLForces, SpeedClamp) {
  check({Gravity{kDown}, SpeedClamp{2.0f, 4.0f}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLForces, ColorOverLife) {
  // A repeated key time (a zero span) and keys not starting at 0 or ending at 1.
  ColorOverLife c;
  c.keys = {{0.1f, Vec4(1.0f, 0.5f, 0.0f, 1.0f)},
            {0.4f, Vec4(0.2f, 0.9f, 0.3f, 0.8f)},
            {0.4f, Vec4(0.0f, 0.0f, 1.0f, 0.6f)},
            {0.85f, Vec4(0.7f, 0.1f, 0.4f, 0.0f)}};
  check({Gravity{kDown}, Move{}, c, KillOld{}}, 2, decorated(), kDecorated);  // Multiply
  c.mode = ColorOverLife::Mode::Replace;
  check({Gravity{kDown}, Move{}, c, KillOld{}}, 2, decorated(), kDecorated);
}

TEST(OpenCLForces, SizeOverLife) {
  SizeOverLife s;
  s.keys = {{0.0f, 0.1f}, {0.3f, 0.8f}, {1.0f, 0.05f}};
  check({Gravity{kDown}, Move{}, s, KillOld{}}, 2, decorated(), kDecorated);  // Multiply
  s.mode = SizeOverLife::Mode::Replace;
  check({Gravity{kDown}, Move{}, s, KillOld{}}, 2, decorated(), kDecorated);
}

// Multiply with curves before Move, and with the colour and size lanes only the curves ask
// for (the newborns' birth values written by the device's emission).
TEST(OpenCLForces, OverLifeMultiplyTwoTypes) {
  Emitter e = decorated();
  e.types.push_back(e.types[0]);
  e.types[1].color = Domain::point(Vec3(0.2f, 0.5f, 1.0f));
  e.types[1].size = 0.5f;
  ColorOverLife c;
  c.keys = {{0.0f, Vec4(1.5f, 1.5f, 1.5f, 1.0f)},
            {0.6f, Vec4(1.0f)},
            {1.0f, Vec4(0.3f, 0.2f, 0.2f, 0.0f)}};
  SizeOverLife s;
  s.keys = {{0.0f, 0.5f}, {1.0f, 2.0f}};
  check({Gravity{kDown}, c, s, Move{}, KillOld{}}, {1, 2}, e);
}

// ---- Under the other integrators (the forces' accelerations at the stages' states) ---------

namespace {

// Every force of the family before one Move, under `integrator`.
ActionList allForces(Integrator integrator) {
  SampledField f;
  f.field = grid();
  f.mode = SampledField::Mode::Velocity;
  f.falloff = kFalloff;
  ActionList l{Gravity{kDown, kFalloffPow}, Damping{Vec3(0.3f, 0.1f, 0.6f), kFalloff},
               // A soft core (epsilon 0.5): explicit Euler near a hard one turns the device's
               // one-ulp differences in exp/sqrt into a drift past the tolerance over 200 steps.
               OrbitPoint{Vec3(0.5f, 3.0f, 0.0f), 10.0f, 0.5f, 4.0f},
               OrbitLine{Vec3(0.5f, 0.0f, 0.0f), Vec3(0.2f, 1.0f, 0.1f), 4.0f, 0.05f, 3.0f},
               Vortex{Vec3(0.0f), Vec3(0.1f, 1.0f, 0.0f), 3.0f, 0.5f, 0.8f, 1.0f, 0.5f, 2.0f, 4.0f},
               Jet{Vec3(0.0f, 3.0f, 0.0f), 1.5f, Domain::sphere(Vec3(0.0f, 3.0f, 0.0f), 4.0f)},
               Explosion{Vec3(0.0f, 2.0f, 0.3f), 3.0f, 20.0f, 0.5f, 1e-3f, 5.6f},
               RandomAccel{Domain::sphere(Vec3(0.0f), 3.0f), kFalloff},
               Turbulence{3.0f, 0.8f, 2, Vec3(0.5f, 0.0f, 0.2f), kFalloffPow},
               ElectricField{Vec3(2.0f, 0.0f, -1.0f), kFalloff},
               MagneticField{Vec3(0.5f, 2.5f, 1.0f), kFalloffPow}, f,
               TargetVelocity{Vec3(0.0f, 1.0f, 0.0f), 0.2f}, Move{}, KillOld{}};
  l.setIntegrator(integrator);
  return l;
}

}  // namespace

TEST(OpenCLForces, IntegratorExplicitEuler) {
  check(allForces(Integrator::ExplicitEuler), 8, charged());
}

TEST(OpenCLForces, IntegratorVelocityVerlet) {
  check(allForces(Integrator::VelocityVerlet), 4, charged());
}

TEST(OpenCLForces, IntegratorRK4) {
  check(allForces(Integrator::RK4), 10, charged());
}

TEST(OpenCLForces, IntegratorExact) {
  ActionList l{Gravity{Vec3(1.0f, -9.81f, 0.0f)}, Damping{Vec3(0.4f, 1.5f, 0.0f)},
               ElectricField{Vec3(0.0f, 3.0f, 2.0f)}, Move{}, KillOld{}};
  l.setIntegrator(Integrator::Exact);
  check(l, {0, 1, 2}, charged());
}

// Sub-steps: the products with dt and the packed exponentials are the sub-step's.
TEST(OpenCLForces, Substeps) {
  ActionList l{Damping{Vec3(1.0f, 0.5f, 2.0f)},
               Vortex{Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 4.0f, 0.5f, 1.0f, 1.0f, 0.0f, 3.0f},
               TargetVelocity{Vec3(0.0f, 3.0f, 0.0f), 2.0f},
               Gravity{kDown},
               Move{},
               KillOld{}};
  Substeps s;
  s.maxStep = 1.0 / 100.0;
  l.setSubsteps(s);
  check(l, 1);
}
