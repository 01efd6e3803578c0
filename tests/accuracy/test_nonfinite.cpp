// NaN and Inf are never propagated silently: fed in as a parameter or an imported field
// they are refused with an InvalidArgument naming the field; appearing inside a step (a
// callback, an added particle, an overflowing force) the particle is killed and counted in
// GroupStats::killedNonFinite.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

#include "accuracy_util.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Runs `f`, expecting an InvalidArgument whose parameter() contains `field`.
template <class F>
::testing::AssertionResult refuses(F f, const std::string& field) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    if (e.parameter().find(field) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "refused, but names '" << e.parameter()
                                         << "' instead of '" << field << "': " << e.what();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "threw something else: " << e.what();
  }
  return ::testing::AssertionFailure() << "accepted a non-finite " << field;
}

}  // namespace

TEST(NonFinite, ActionParametersAreRefused) {
  for (float bad : {kNaN, kInf, -kInf}) {
    EXPECT_TRUE(
        refuses([&] { ActionList{}.add(Gravity{Vec3(0.0f, bad, 0.0f)}); }, "Gravity.acceleration"));
    EXPECT_TRUE(refuses([&] { ActionList{}.add(Damping{Vec3(bad)}); }, "Damping.rate"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.add(OrbitPoint{Vec3(bad), 1.0f});
        },
        "OrbitPoint.center"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.add(OrbitPoint{Vec3(0.0f), bad});
        },
        "OrbitPoint.magnitude"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.add(OrbitPoint{Vec3(0.0f), 1.0f, bad});
        },
        "OrbitPoint.epsilon"));
    Vortex v;
    v.aroundSpeed = bad;
    EXPECT_TRUE(refuses([&] { ActionList{}.add(v); }, "Vortex.aroundSpeed"));
    EXPECT_TRUE(refuses([&] { ActionList{}.add(MagneticField{Vec3(0.0f, 0.0f, bad)}); },
                        "MagneticField.field"));
    EXPECT_TRUE(refuses([&] { ActionList{}.add(ElectricField{Vec3(bad, 0.0f, 0.0f)}); },
                        "ElectricField.field"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.add(TargetVelocity{Vec3(bad), 1.0f});
        },
        "TargetVelocity.velocity"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.add(Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), bad});
        },
        "Bounce.restitution"));
    EXPECT_TRUE(refuses([&] { ActionList{}.add(Turbulence{bad}); }, "Turbulence.amplitude"));
  }
}

TEST(NonFinite, StepSizesSubstepsAndEmittersAreRefused) {
  for (double bad : {double(kNaN), double(kInf), 0.0, -1.0, 10.5}) {
    Context ctx = makeContext(1.0 / 60);
    EXPECT_TRUE(refuses([&] { ctx.setTimeStep(bad); }, "dt")) << bad;
    EXPECT_TRUE(refuses([&] { makeContext(bad); }, "dt")) << bad;
  }
  EXPECT_NO_THROW(makeContext(10.0));  // the maximum is allowed
  for (double bad : {double(kNaN), double(kInf), -1.0}) {
    EXPECT_TRUE(refuses([&] { ActionList{}.setSubsteps(Substeps{bad, 0.0f, 8}); }, "substeps"));
    EXPECT_TRUE(refuses(
        [&] {
          ActionList{}.setSubsteps(Substeps{0.0, float(bad), 8});
        },
        "substeps"));
  }
  Context ctx = makeContext(1.0 / 60);
  Group& g = ctx.createGroup("g", 10);
  Emitter e;
  e.rate = kNaN;
  EXPECT_TRUE(refuses([&] { g.addEmitter(e); }, "rate"));
  e.rate = 1.0;
  e.position = Vec3(kInf, 0.0f, 0.0f);
  EXPECT_TRUE(refuses([&] { g.addEmitter(e); }, "position"));
}

// An imported vector field (dense or read from OpenVDB) holding a NaN is refused by name.
TEST(NonFinite, ImportedFieldsAreRefused) {
  auto field = std::make_shared<VectorField>();
  field->dims = glm::ivec3(2);
  field->data.assign(8, Vec3(1.0f));
  field->data[5] = Vec3(0.0f, kNaN, 0.0f);
  SampledField s;
  s.field = field;
  EXPECT_TRUE(refuses([&] { ActionList{}.add(s); }, "SampledField.field"));
  field->data[5] = Vec3(kInf);
  EXPECT_TRUE(refuses([&] { ActionList{}.add(s); }, "SampledField.field"));
}

// A NaN position (an earlier action's, before the step's guard) samples a field inside the
// grid: a NaN cast to int would index far outside it.
TEST(NonFinite, AFieldSampledAtNaNStaysInsideTheGrid) {
  VectorField field;
  field.dims = glm::ivec3(3, 2, 2);
  field.data.assign(12, Vec3(1.0f, 2.0f, 3.0f));
  for (Vec3 p :
       {Vec3(kNaN, 0.5f, 0.5f), Vec3(0.5f, kNaN, 0.5f), Vec3(0.5f, 0.5f, kNaN), Vec3(kNaN)}) {
    const Vec3 s = field.sample(p);
    EXPECT_EQ(s, Vec3(1.0f, 2.0f, 3.0f));
  }
}

// A callback that writes NaN or Inf into a position or a velocity: exactly those particles
// die in that step and are counted; nothing non-finite is left; the others are untouched.
TEST(NonFinite, ACallbackWritingNaNKillsAndCountsTheParticle) {
  for (Integrator integ : kGeneralIntegrators) {
    SCOPED_TRACE(integratorName(integ));
    Context ctx = makeContext(1.0 / 60);
    Group& g = ctx.createGroup("g", 100);
    Callback cb;
    cb.function = [](Particle& p, const CallbackContext& c) {
      if (c.step != 3) return;
      switch (p.id % 10) {
        case 1:
          p.position.x = kNaN;
          break;
        case 2:
          p.velocity.y = kInf;
          break;
        case 3:
          p.velocity.z = -kInf;
          break;
        case 4:
          p.position.z = kInf;
          break;
        default:
          break;
      }
    };
    g.setActions(withIntegrator({Gravity{Vec3(0.0f, -9.81f, 0.0f)}, cb, Move{}}, integ));
    for (int i = 0; i < 100; ++i)
      g.add(particleAt(Vec3(float(i), 0.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f)));
    ctx.run(3);
    EXPECT_EQ(g.size(), 100u);
    EXPECT_EQ(g.stats().killedNonFinite, 0u);
    ctx.step();  // the callback poisons 40 particles in this step
    EXPECT_EQ(g.size(), 60u);
    EXPECT_EQ(g.stats().killedNonFinite, 40u);
    ASSERT_TRUE(sane(g));
    for (std::uint32_t id : g.ids()) EXPECT_TRUE(id % 10 == 0 || id % 10 >= 5) << id;
    ctx.run(5);
    EXPECT_EQ(g.stats().killedNonFinite, 40u);
    ASSERT_TRUE(sane(g));
  }
}

// A particle added with a NaN or Inf state is either refused or killed and counted in its
// first step; never kept.
TEST(NonFinite, AddedNonFiniteParticlesDoNotSurviveAStep) {
  Context ctx = makeContext(1.0 / 60);
  Group& g = ctx.createGroup("g", 10);
  g.setActions({Gravity{}, Move{}});
  g.add(particleAt(Vec3(0.0f), Vec3(0.0f)));
  bool refused = false;
  try {
    g.add(particleAt(Vec3(kNaN, 0.0f, 0.0f)));
    g.add(particleAt(Vec3(0.0f), Vec3(0.0f, kInf, 0.0f)));
  } catch (const InvalidArgument&) {
    refused = true;
  }
  ctx.step();
  ASSERT_TRUE(sane(g)) << (refused ? "refused" : "accepted, then stepped");
  EXPECT_EQ(g.size(), 1u);
}

// A force that overflows float (a huge OrbitPoint with tiny softening very near its centre)
// makes an infinite velocity inside the step: the particle is killed and counted.
TEST(NonFinite, AnOverflowingForceKillsAndCounts) {
  for (Integrator integ : kGeneralIntegrators) {
    SCOPED_TRACE(integratorName(integ));
    Context ctx = makeContext(1.0 / 60);
    Group& g = ctx.createGroup("g", 4);
    g.setActions(withIntegrator({OrbitPoint{Vec3(0.0f), 1e30f, 1e-30f}, Move{}}, integ));
    g.add(particleAt(Vec3(1e-10f, 0.0f, 0.0f)));  // pull ≈ 1e30/1e-30: overflows
    g.add(particleAt(Vec3(1e3f, 0.0f, 0.0f)));
    ctx.run(3);
    ASSERT_TRUE(sane(g));
    EXPECT_GE(g.stats().killedNonFinite, 1u);
  }
}
