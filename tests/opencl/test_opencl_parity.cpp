// Parity: every action, every emitter shape and every built-in sample, 200 steps on the CPU
// and the OpenCL backend from the same seed; the same particles (matched by id: a device
// compacts in another order), the same counts, the same attributes.
//
#include <bit>
#include <map>
#include <optional>

#include "../leaf_shapes.hpp"
#include "builtin.hpp"
#include "effect/descriptors.hpp"
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

TEST(OpenCLParity, GravityMoveKillOld) {
  checkParity(withActions({Gravity{kDown}, Move{}, KillOld{}}));
}

TEST(OpenCLParity, Damping) {
  checkParity(withActions({Gravity{kDown}, Damping{Vec3(0.5f, 0.1f, 2.0f)}, Move{}, KillOld{}}));
}

TEST(OpenCLParity, BouncePlane) {
  checkParity(withActions(
      {Gravity{kDown}, Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.6f, 0.2f, 0.05f},
       Move{}, KillOld{}}));
}

TEST(OpenCLParity, BounceRectangle) {
  checkParity(withActions({Gravity{kDown},
                           Bounce{Domain::rectangle(Vec3(-1.0f, 0.0f, -1.0f),
                                                    Vec3(2.0f, 0.0f, 0.0f), Vec3(0.5f, 0.3f, 2.0f)),
                                  0.8f, 0.1f, 0.0f},
                           Move{}, KillOld{}}));
}

TEST(OpenCLParity, BounceDisc) {
  checkParity(
      withActions({Gravity{kDown},
                   Bounce{Domain::disc(Vec3(0.0f, 0.2f, 0.0f), Vec3(0.1f, 1.0f, 0.0f), 1.5f, 0.3f),
                          0.7f, 0.0f, 0.0f},
                   Move{}, KillOld{}}));
}

TEST(OpenCLParity, BounceTriangle) {
  checkParity(withActions({Gravity{kDown},
                           Bounce{Domain::triangle(Vec3(-2.0f, 0.0f, -2.0f),
                                                   Vec3(2.0f, 0.5f, -2.0f), Vec3(0.0f, 0.0f, 2.0f)),
                                  0.5f, 0.3f, 0.1f},
                           Move{}, KillOld{}}));
}

TEST(OpenCLParity, BounceSphere) {
  checkParity(withActions({Gravity{kDown},
                           Bounce{Domain::sphere(Vec3(0.3f, 3.0f, 0.0f), 0.8f), 0.9f, 0.1f, 0.0f},
                           Move{}, KillOld{}}));
}

TEST(OpenCLParity, SinkInsideEveryRegion) {
  const Domain regions[] = {
      Domain::box(Vec3(-1.0f, 2.0f, -1.0f), Vec3(1.0f, 3.0f, 1.0f)),
      Domain::sphere(Vec3(0.0f, 2.5f, 0.0f), 1.0f, 0.3f),
      Domain::cylinder(Vec3(0.0f, 1.5f, 0.0f), Vec3(0.0f, 3.0f, 0.5f), 0.8f),
      Domain::cone(Vec3(0.0f, 4.0f, 0.0f), Vec3(0.0f, 2.0f, 0.0f), 1.0f),
      Domain::blob(Vec3(0.5f, 2.0f, 0.0f), 0.7f),
      Domain::plane(Vec3(0.0f, 3.0f, 0.0f), Vec3(0.0f, 1.0f, 0.2f)),
      Domain::disc(Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 1.0f),  // no inside
  };
  for (const Domain& r : regions) {
    SCOPED_TRACE(r.name());
    checkParity(withActions({Gravity{kDown}, Sink{r, 0.0f}, Move{}, KillOld{}}));
  }
}

TEST(OpenCLParity, SinkOutsideWithPassThrough) {
  checkParity(
      withActions({Gravity{kDown},
                   Sink{Domain::sphere(Vec3(0.0f, 1.5f, 0.0f), 2.0f), 0.3f, Sink::Mode::Outside},
                   Sink{Domain::box(Vec3(-2.0f, 1.0f, -2.0f), Vec3(2.0f, 2.0f, 2.0f)), 0.7f},
                   Move{}, KillOld{}}));
}

TEST(OpenCLParity, MoveStoresPreviousPosition) {
  checkParity([](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("prev", 20000);
    g.addEmitter(spray());
    g.setActions({Gravity{kDown}, Move{}, KillOld{}});
    g.require({Attribute::PrevPosition});
    return g;
  });
}

// Every domain as an emitter shape and as a velocity, with every attribute stored and every
// fuzzy value drawn (uniform and normal).
TEST(OpenCLParity, EmissionFromEveryDomain) {
  const std::vector<Domain> shapes = leafShapes();
  for (const Domain& shape : shapes) {
    SCOPED_TRACE(shape.name());
    checkParity(
        [&](Context& ctx) -> Group& {
          Group& g = ctx.createGroup("emit", 5000);
          Emitter e;
          e.shape = shape;
          e.rate = 300;
          e.velocity = Vec3(0.5f, 0.0f, 0.0f);  // a moving emitter
          ParticleType t;
          t.velocity = shape;
          t.color = shape;
          t.up = shape;
          t.rotVelocity = shape;
          t.alpha = Fuzzy(0.5f, 0.2f);
          t.size = Fuzzy(0.05f, 0.02f, Fuzzy::Distribution::Normal);
          t.mass = Fuzzy(1.0f, 0.5f);
          t.lifetime = Fuzzy(1.0f, 0.3f, Fuzzy::Distribution::Normal);
          t.charge = Fuzzy(0.0f, 1.0f);
          e.types = {t};
          g.addEmitter(e);
          g.setActions({Move{}, KillOld{}});
          g.require({Attribute::Color, Attribute::Size, Attribute::Mass, Attribute::Charge,
                     Attribute::Up, Attribute::RotVelocity, Attribute::PrevPosition,
                     Attribute::Visible, Attribute::UserData});
          return g;
        },
        60);
  }
}

// Box-Muller is float arithmetic alone on both backends (kernels/domain.h fl_logf,
// fl_sincos_2pi), so normal draws have the same bits: a blob's velocities and normal fuzzy
// sizes and lifetimes of newborns that nothing moves, compared bit for bit by id.
TEST(OpenCLParity, NormalDrawsAreBitwiseTheSame) {
  const Build build = [](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("normal", 5000);
    Emitter e;
    e.shape = Domain::point(Vec3(0.0f));
    e.rate = 3000;
    ParticleType t;
    t.velocity = Domain::blob(Vec3(0.5f, 2.0f, -1.0f), 0.7f);
    t.size = Fuzzy(0.05f, 0.02f, Fuzzy::Distribution::Normal);
    t.lifetime = Fuzzy(10.0f, 0.3f, Fuzzy::Distribution::Normal);
    e.types = {t};
    g.addEmitter(e);
    g.setActions({KillOld{}});
    g.require({Attribute::Size});
    return g;
  };
  FLURRY_REQUIRE_OPENCL();
  const RunResult cpu = runEffect(Backend::Cpu, build, 5);
  const RunResult cl = runEffect(Backend::OpenCL, build, 5);
  ASSERT_GT(cpu.size, 400u);
  ASSERT_EQ(cpu.size, cl.size);
  const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
  for (const auto& [id, p] : cpu.byId) {
    const auto it = cl.byId.find(id);
    ASSERT_NE(it, cl.byId.end()) << id;
    const Particle& q = it->second;
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(bits(p.velocity[c]), bits(q.velocity[c])) << "velocity of " << id;
    ASSERT_EQ(bits(p.size), bits(q.size)) << "size of " << id;
    ASSERT_EQ(bits(p.lifetime), bits(q.lifetime)) << "lifetime of " << id;
  }
}

// Several particle types (a type is drawn first), bursts, a keyframed path, and a group that
// fills up (births dropped at capacity on both backends alike).
TEST(OpenCLParity, TypesBurstsPathsAndCapacity) {
  checkParity([](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("mixed", 3000);
    Emitter e;
    e.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 0.5f);
    e.rate = 700.5;
    e.start = 0.1;
    e.stop = 5.0;
    e.path = {{0.0, Vec3(0.0f)}, {2.0, Vec3(3.0f, 1.0f, 0.0f)}, {4.0, Vec3(0.0f, 2.0f, 3.0f)}};
    e.bursts = {{0.5, 400, 1.0, 3}};
    ParticleType a, b, c;
    a.weight = 1.0f;
    a.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 6.0f, 0.0f), 2.0f);
    a.lifetime = Fuzzy(3.0f, 1.0f);
    b.weight = 2.5f;
    b.velocity = Domain::box(Vec3(-1.0f, 2.0f, -1.0f), Vec3(1.0f, 4.0f, 1.0f));
    b.lifetime = Fuzzy(2.0f, 0.5f, Fuzzy::Distribution::Normal);
    b.size = Fuzzy(0.1f, 0.05f);
    c.weight = 0.5f;
    c.velocity = Domain::blob(Vec3(0.0f, 3.0f, 0.0f), 1.0f);
    c.lifetime = 6.0f;
    e.types = {a, b, c};
    g.addEmitter(e);
    Emitter second = spray(Vec3(2.0f, 0.0f, 0.0f), 90);
    g.addEmitter(second);
    g.setActions({Gravity{kDown},
                  Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f, 0.1f, 0.0f},
                  Sink{Domain::sphere(Vec3(1.0f, 2.0f, 1.0f), 0.7f), 0.25f}, Move{}, KillOld{}});
    g.require({Attribute::Size, Attribute::Color});
    return g;
  });
}

TEST(OpenCLParity, EveryBuiltinSample) {
  FLURRY_REQUIRE_OPENCL();
  std::string notOnDevice;
  int compared = 0;
  for (const auto& s : samples::builtinSamples()) {
    SCOPED_TRACE(s.name);
    auto build = [&](Context& ctx) -> Group& {
      s.build(ctx, 50000);
      return *ctx.groups().front();
    };
    RunResult cl;
    try {
      cl = runEffect(Backend::OpenCL, build, kSteps);
    } catch (const Error& e) {
      // A sample using what the device does not run yet is named, not silently passed.
      if (std::string(e.what()).find("does not run on the device yet") == std::string::npos) throw;
      notOnDevice += "\n  " + s.name + ": " + e.what();
      continue;
    }
    expectSame(runEffect(Backend::Cpu, build, kSteps), cl);
    ++compared;
  }
  std::printf("[ parity   ] %d built-in samples compared; largest |cpu - opencl| seen: %g\n",
              compared, maxDiff);
  if (!notOnDevice.empty())
    std::printf("[ parity   ] NOT COMPARED (features not on the device yet):%s\n",
                notOnDevice.c_str());
  EXPECT_GT(compared, 0);
}

namespace {

// One action of each kind in a scene whose emission is bitwise on both backends (boxes and
// uniform draws only: no libm there), with sensible parameters where the defaults do nothing.
template <class A>
A bitwiseCase() {
  A a{};
  const Domain box = Domain::box(Vec3(-1.0f, 0.5f, -1.0f), Vec3(1.0f, 2.0f, 1.0f));
  // (Nothing falls in these scenes: the surfaces stand in the particles' way up.)
  if constexpr (std::is_same_v<A, Bounce>)
    a.surface = Domain::plane(Vec3(0, 2.5f, 0), Vec3(0, 1, 0));
  if constexpr (std::is_same_v<A, ElectricField>) a.field = Vec3(0.0f, 2.0f, 1.0f);
  if constexpr (std::is_same_v<A, TargetColor>) {
    a.color = Vec3(1.0f, 0.2f, 0.0f);
    a.rate = 2.0f;
  }
  if constexpr (std::is_same_v<A, SpeedClamp>) a.maxSpeed = 2.0f;
  if constexpr (std::is_same_v<A, Sink>) a.region = Domain::sphere(Vec3(0.0f, 1.5f, 0.0f), 0.6f);
  if constexpr (std::is_same_v<A, SinkVelocity>) a.velocity = Domain::sphere(Vec3(0.0f), 1.5f);
  if constexpr (std::is_same_v<A, Block>) a.region = Domain::sphere(Vec3(0.0f, 2.0f, 0.0f), 0.5f);
  if constexpr (std::is_same_v<A, Avoid>) a.obstacle = Domain::sphere(Vec3(0, 3, 0), 0.5f);
  if constexpr (std::is_same_v<A, Jet>) {
    a.center = Vec3(0.0f, 2.0f, 0.0f);
    a.acceleration = box;
  }
  if constexpr (std::is_same_v<A, RandomAccel>) a.acceleration = box;
  if constexpr (std::is_same_v<A, RandomDisplace>) a.displacement = box;
  if constexpr (std::is_same_v<A, RandomVelocity>) a.velocity = box;
  if constexpr (std::is_same_v<A, RandomRotVelocity>) a.rotVelocity = box;
  if constexpr (std::is_same_v<A, SampledField>) {
    auto f = std::make_shared<VectorField>();
    f->dims = {2, 2, 2};
    f->origin = Vec3(-3.0f);
    f->voxelSize = 6.0f;
    for (int k = 0; k < 8; ++k) f->data.push_back(Vec3(float(k % 2), float(k / 4), 0.5f));
    a.field = f;
  }
  return a;
}

// Whether two runs hold the same particles to the bit, and the largest difference.
std::pair<bool, float> bitwiseCompare(const RunResult& x, const RunResult& y) {
  bool same = x.size == y.size;
  float most = 0.0f;
  auto cmp = [&](float a, float b) {
    if (std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b)) return;
    same = false;
    most = std::max(most, std::abs(a - b));
  };
  for (const auto& [id, p] : x.byId) {
    const auto it = y.byId.find(id);
    if (it == y.byId.end()) return {false, kInfinity};
    const Particle& q = it->second;
    for (int c = 0; c < 3; ++c) {
      cmp(p.position[c], q.position[c]);
      cmp(p.velocity[c], q.velocity[c]);
      cmp(p.up[c], q.up[c]);
      cmp(p.rotVelocity[c], q.rotVelocity[c]);
      cmp(p.positionB[c], q.positionB[c]);
      cmp(p.velocityB[c], q.velocityB[c]);
    }
    for (int c = 0; c < 4; ++c) cmp(p.color[c], q.color[c]);
    cmp(p.size, q.size);
    cmp(p.age, q.age);
    cmp(p.userData, q.userData);
    if (p.visible != q.visible) same = false;
  }
  return {same, most};
}

}  // namespace

// Which actions give the CPU's particles to the bit on the device, each alone before Move and
// KillOld over 40 steps (docs/opencl.md, "Bitwise parity", keeps the table this prints). Both
// sides run one source (kernels/*.h) in float with no contraction into FMAs and correctly
// rounded division and square root: what is left to differ is where a libm function (log,
// sin, cos, atan2) stands in the path, the device's builtin and the CPU's libm rounding
// their last bit apart; no action has one now (exp and pow are the kernels' own,
// kernels/math.h fl_expf and fl_powf: a vortex's swirl, a falloff's fade of any power; sin
// and cos too, kernels/forces.h fl_sincos_real: a magnetic field's turn, the up vector's).
// An action that may differ would be listed with that function, and must still be within the
// parity tolerance; every other must be bitwise.
TEST(OpenCLParity, WhichActionsAreBitwise) {
  FLURRY_REQUIRE_OPENCL();
  // Each action not bitwise, and the libm function on its path: none.
  const std::map<std::string, std::string> expectedNot = {};
  int bitwise = 0, differ = 0;
  std::string table;
  std::optional<RunResult> alone;  // the CPU's run without the action
  auto check = [&](const std::string& name, const ActionList& list) {
    auto build = [&](Context& ctx) -> Group& {
      Group& g = ctx.createGroup("g", 3000);
      Emitter e;
      e.shape = Domain::box(Vec3(-0.5f, 0.5f, -0.5f), Vec3(0.5f, 1.5f, 0.5f));
      e.rate = 900;
      ParticleType t;
      t.velocity = Domain::box(Vec3(-1.0f, 1.0f, -1.0f), Vec3(1.0f, 4.0f, 1.0f));
      t.lifetime = Fuzzy(1.0f, 0.4f);
      t.charge = Fuzzy(1.0f, 0.5f);
      t.rotVelocity = Domain::box(Vec3(-1.0f), Vec3(1.0f));
      e.types = {t};
      g.addEmitter(e);
      g.setActions(list);
      return g;
    };
    const RunResult cpu = runEffect(Backend::Cpu, build, 40);
    // A case that changes nothing would be bitwise for nothing: each action must act.
    if (alone) {
      EXPECT_FALSE(bitwiseCompare(*alone, cpu).first) << name << " changed nothing";
    } else {
      alone = cpu;
    }
    const auto [same, most] = bitwiseCompare(cpu, runEffect(Backend::OpenCL, build, 40));
    const auto it = expectedNot.find(name);
    char line[160];
    std::snprintf(line, sizeof line, "| %s | %s | %.3g | %s |\n", name.c_str(),
                  same ? "bitwise" : "differs", double(most),
                  it == expectedNot.end() ? "" : it->second.c_str());
    table += line;
    (same ? bitwise : differ) += 1;
    if (it == expectedNot.end()) {
      EXPECT_TRUE(same) << name << " differs by up to " << most;
    } else {
      EXPECT_LE(most, 1e-3f) << name;
    }
  };
  check("Move, KillOld", ActionList{Move{}, KillOld{}});
  {
    Gravity faded;  // a falloff of a power other than 1: fl_powf on both sides
    faded.acceleration = Vec3(0.0f, 6.0f, 2.0f);
    faded.falloff.center = Vec3(0.0f, 1.0f, 0.0f);
    faded.falloff.radius = 3.0f;
    faded.falloff.power = 2.5f;
    check("Gravity, falloff power 2.5", ActionList{faded, Move{}, KillOld{}});
    // A drawn jet in reach of every particle (the CPU draws a block's in batches) and of few
    // (one by one).
    for (const float radius : {100.0f, 0.4f}) {
      Jet jet = bitwiseCase<Jet>();
      jet.radius = radius;
      check(radius > 1.0f ? "Jet, every particle in reach" : "Jet, few in reach",
            ActionList{jet, Move{}, KillOld{}});
    }
  }
  // Boxes and a sphere, which the CPU tests a chunk at a time and bounces only the particles
  // that may reach (the device: every particle through the kernel).
  {
    Bounce room{Domain::box(Vec3(-1.2f, 0.3f, -1.1f), Vec3(1.1f, 2.2f, 1.3f)), 0.7f, 0.2f, 0.1f};
    room.inside = true;
    check("Bounce, box inside", ActionList{room, Move{}, KillOld{}});
    const Bounce crate{Domain::box(Vec3(-0.4f, 1.6f, -0.5f), Vec3(0.5f, 2.0f, 0.4f)), 0.6f};
    check("Bounce, box outside", ActionList{crate, Move{}, KillOld{}});
    Bounce ball{Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 1.6f), 0.9f, 0.1f};
    ball.inside = true;
    check("Bounce, sphere inside", ActionList{ball, Move{}, KillOld{}});
    // The crossings of a rectangle and a triangle (their nearest points branch-free on the
    // CPU, in vectors).
    const Domain plate =
        Domain::rectangle(Vec3(-0.8f, 1.8f, -0.7f), Vec3(1.5f, 0.2f, 0.0f), Vec3(0.3f, 0.1f, 1.4f));
    const Domain sail =
        Domain::triangle(Vec3(-1.0f, 1.7f, -1.0f), Vec3(1.0f, 1.9f, -0.6f), Vec3(0.1f, 2.1f, 1.2f));
    check("Sink, hit a rectangle",
          ActionList{Sink{plate, 0.0f, Sink::Mode::Hit}, Move{}, KillOld{}});
    check("Avoid, a triangle", ActionList{Avoid{sail, 4.0f, 1e-3f, 0.4f}, Move{}, KillOld{}});
  }
  // The neighbours' pulls under the integrators that sum them at each stage (the CPU scans
  // two vectors' worth of particles at once, each in the device's order).
  for (const Integrator in : {Integrator::RK4, Integrator::VelocityVerlet}) {
    ActionList pulled{bitwiseCase<Gravitate>(), Move{}, KillOld{}};
    pulled.setIntegrator(in);
    check(std::string("Gravitate, ") + integratorName(in), pulled);
    ActionList led{bitwiseCase<Follow>(), Move{}, KillOld{}};
    led.setIntegrator(in);
    check(std::string("Follow, ") + integratorName(in), led);
  }
  desc::forEachAction([&](auto tag) {
    using A = typename decltype(tag)::type;
    if constexpr (!std::is_same_v<A, Move> && !std::is_same_v<A, KillOld>)
      check(desc::Describe<A>::name, ActionList{bitwiseCase<A>(), Move{}, KillOld{}});
  });
  std::printf(
      "| action | CPU and device | largest difference | libm on its path |\n"
      "| --- | --- | --- | --- |\n%s",
      table.c_str());
  std::printf("[ parity   ] %d bitwise, %d differ\n", bitwise, differ);
}
