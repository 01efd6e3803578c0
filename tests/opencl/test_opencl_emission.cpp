// Parity on the device: Emission on the device: every domain, spacing, normal speed, prime
// emitters. Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp).
#include <cmath>

#include "../leaf_shapes.hpp"
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

// A closed octahedron, counter-clockwise seen from outside (as samples/effects/shockwave).
Domain octahedron(Vec3 c = Vec3(0.0f), float r = 1.0f) {
  std::vector<Vec3> v = {c + Vec3(r, 0, 0),  c + Vec3(-r, 0, 0), c + Vec3(0, r, 0),
                         c + Vec3(0, -r, 0), c + Vec3(0, 0, r),  c + Vec3(0, 0, -r)};
  return Domain::mesh(
      v, {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

// A lat-long sphere of 2·rings·(segments - 1) triangles: a mesh whose triangle search takes
// several steps (unequal areas).
Domain latLongSphere(int rings, int segments) {
  std::vector<Vec3> v;
  std::vector<glm::uvec3> t;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const float th = 3.14159265f * float(r) / float(rings),
                  ph = 6.2831853f * float(s) / float(segments);
      v.emplace_back(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const auto a = unsigned(r * segments + s), b = unsigned(r * segments + (s + 1) % segments);
      if (r > 0) t.emplace_back(a, b, a + unsigned(segments));
      if (r + 1 < rings) t.emplace_back(b, b + unsigned(segments), a + unsigned(segments));
    }
  return Domain::mesh(v, t);
}

// A union of unequal parts, one of them a union itself with a mesh in it: sampling picks a
// part by measure at each level, and a newborn's normal is that of the leaf it picked.
Domain nestedUnion() {
  return Domain::unite(
      {Domain::box(Vec3(-1.0f), Vec3(0.0f, 0.5f, 1.0f)), Domain::sphere(Vec3(2.0f, 0, 0), 0.7f),
       Domain::unite({octahedron(Vec3(0, 2.0f, 0), 0.8f),
                      Domain::cylinder(Vec3(0, -2.0f, 0), Vec3(1.0f, -2.0f, 0.5f), 0.4f)})});
}

// Every attribute an emitter writes, so that every draw is made and compared.
const AttributeSet kAll{Attribute::Color,        Attribute::Size,    Attribute::Mass,
                        Attribute::Charge,       Attribute::Up,      Attribute::RotVelocity,
                        Attribute::PrevPosition, Attribute::Visible, Attribute::UserData};

ParticleType drawingType(const Domain& d) {
  ParticleType t;
  t.velocity = d;
  t.color = d;
  t.up = d;
  t.rotVelocity = d;
  t.alpha = Fuzzy(0.5f, 0.2f);
  t.size = Fuzzy(0.05f, 0.02f, Fuzzy::Distribution::Normal);
  t.mass = Fuzzy(1.0f, 0.5f);
  t.lifetime = Fuzzy(1.5f, 0.3f);
  t.charge = Fuzzy(0.0f, 1.0f);
  return t;
}

// checkParity's comparison plus the live emitters' counts, which only prime emitters move.
void expectSameWithEmitterStats(const RunResult& cpu, const RunResult& cl) {
  EXPECT_EQ(cpu.stats.emittersSpawned, cl.stats.emittersSpawned);
  EXPECT_EQ(cpu.stats.emittedByGeneration, cl.stats.emittedByGeneration);
  expectSame(cpu, cl);
  ::testing::Test::RecordProperty("max_abs_difference", std::to_string(maxDiff));
}

}  // namespace

// Emission by distance: along a keyframed path, along a straight line at a speed that
// leaves several births per step (sub-step birth times and places), slower than one per
// step, with a stop time, with rate and bursts beside it, and with several types.
TEST(OpenCLEmission, Spacing) {
  checkParity([](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("spacing", 20000);
    Emitter path;
    path.path = {{0.0, Vec3(0.0f)}, {1.5, Vec3(4.0f, 2.0f, 0.0f)}, {4.0, Vec3(-2.0f, 1.0f, 3.0f)}};
    path.spacing = 0.05f;
    path.shape = Domain::sphere(Vec3(0.0f), 0.1f);
    path.types = {drawingType(Domain::sphere(Vec3(0.0f), 0.5f))};
    g.addEmitter(path);
    Emitter line;
    line.position = Vec3(0.0f, 1.0f, 0.0f);
    line.velocity = Vec3(3.0f, 0.5f, -1.0f);
    line.spacing = 0.07f;
    line.rate = 40;
    line.bursts = {{0.5, 50, 1.0, 3}};
    line.start = 0.2;
    line.stop = 5.0;
    ParticleType a = drawingType(Domain::box(Vec3(-1.0f), Vec3(1.0f))),
                 b = drawingType(Domain::point(Vec3(0, 2, 0)));
    b.weight = 3.0f;
    line.types = {a, b};
    g.addEmitter(line);
    Emitter slow;  // 0.02 units per step: a birth every few steps
    slow.velocity = Vec3(0.0f, 0.0f, 0.6f);
    slow.spacing = 0.13f;
    g.addEmitter(slow);
    g.setActions({Gravity{kDown}, Move{}, KillOld{}});
    g.require(kAll);
    return g;
  });
}

// Emitter::pathLoop: the device wraps each birth time to the path's first key as the CPU
// does, for births by rate and by distance (200 steps of 1/30 s: the 1.2 s loop five times).
TEST(OpenCLEmission, LoopingPath) {
  checkParity([](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("loop", 20000);
    Emitter e;
    e.path = {{0.1, Vec3(0.0f)},
              {0.5, Vec3(2.0f, 0.0f, 0.0f)},
              {0.9, Vec3(1.0f, 2.0f, 1.0f)},
              {1.3, Vec3(0.0f)}};
    e.pathLoop = true;
    e.rate = 90;
    e.spacing = 0.05f;
    e.shape = Domain::sphere(Vec3(0.0f), 0.1f);
    e.types = {drawingType(Domain::sphere(Vec3(0.0f), 0.5f))};
    g.addEmitter(e);
    g.setActions({Gravity{kDown}, Move{}, KillOld{}});
    g.require(kAll);
    return g;
  });
}

// A path of many keys (a circle in 240 keys over 8 s, looping): each newborn's key is found by
// a binary search on the device and by a walk from the last one on the CPU; both must find
// the same key for every birth, by rate and by distance.
TEST(OpenCLEmission, LongPath) {
  checkParity([](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("orbit", 20000);
    Emitter e;
    for (int k = 0; k <= 240; ++k) {
      const float a = 6.2831853f * float(k) / 240.0f;
      e.path.push_back({0.2 + 8.0 * double(k) / 240.0,
                        Vec3(3.0f * std::cos(a), 0.01f * float(k), 3.0f * std::sin(a))});
    }
    e.pathLoop = true;
    e.rate = 300;
    e.spacing = 0.1f;
    e.shape = Domain::point(Vec3(0.0f));
    e.types = {drawingType(Domain::sphere(Vec3(0.0f), 0.5f))};
    g.addEmitter(e);
    g.setActions({Gravity{kDown}, Move{}, KillOld{}});
    g.require(kAll);
    return g;
  });
}

// Emitter::normalSpeed on every shape: the normal where each particle is born (faces, the
// nearest face of a box, the face of a mesh it was born on, the axial frames of cylinders and
// cones, the leaf of a union it was born on), uniform and normal speeds, one type and several.
TEST(OpenCLEmission, NormalSpeedOnEveryShape) {
  std::vector<Domain> shapes = leafShapes();
  const Domain more[] = {
      Domain::plane(Vec3(0.0f, 0.5f, 0.0f), Vec3(0.3f, 1.0f, 0.0f)),
      Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 1.0f),
      Domain::cylinder(Vec3(0.0f), Vec3(0.0f, 2.0f, 1.0f), 0.5f),
      Domain::cylinder(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), 0.5f, 0.5f),
      Domain::cone(Vec3(0.0f), Vec3(0.0f, 3.0f, 0.0f), 1.0f),
      octahedron(),
      latLongSphere(6, 9),
      // A two-sided square: each side's newborns along their own side's normal, where the
      // nearest face (the first of equals) would send nearly all of them up.
      Domain::mesh({{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},
                   {{0, 3, 2}, {0, 2, 1}, {0, 2, 3}, {0, 1, 2}}),
      nestedUnion(),
  };
  shapes.insert(shapes.end(), std::begin(more), std::end(more));
  checkParity(
      [&](Context& ctx) -> Group& {
        Group& g = ctx.createGroup("normal", 30000);
        int k = 0;
        for (const Domain& shape : shapes) {
          Emitter e;
          e.shape = shape;
          e.rate = 150;
          e.position = Vec3(0.3f * float(k), 0.0f, 0.0f);
          e.normalSpeed = k % 3 == 2   ? Fuzzy(2.0f, 0.5f, Fuzzy::Distribution::Normal)
                          : k % 3 == 1 ? Fuzzy(1.5f)
                                       : Fuzzy(1.0f, 0.4f);
          ParticleType t;
          t.velocity = Domain::point(Vec3(0.0f, 0.5f, 0.0f));
          t.lifetime = Fuzzy(1.5f, 0.3f);
          e.types = {t};
          if (k % 4 == 1) {  // several types: the CPU gathers each type's newborns
            ParticleType u = t;
            u.velocity = Domain::sphere(Vec3(0.0f), 0.3f);
            u.weight = 0.5f;
            e.types.push_back(u);
          }
          g.addEmitter(e);
          ++k;
        }
        // Only what the normal changes is stored: every emitter and type is compiled into
        // the program, and the device compiler's time grows with them.
        g.setActions({Gravity{kDown}, Move{}, KillOld{}});
        return g;
      },
      60);
}

// Meshes and unions (nested, with a mesh part, and of points alone, which have no measure)
// as emitter shapes and as the domains of velocity, colour, up and spin.
TEST(OpenCLEmission, MeshAndUnionDomains) {
  const Domain points =
      Domain::unite({Domain::point(Vec3(1.0f, 0.0f, 0.0f)), Domain::point(Vec3(0.0f, 2.0f, 0.0f)),
                     Domain::point(Vec3(0.0f, 0.0f, 3.0f))});
  checkParity(
      [&](Context& ctx) -> Group& {
        Group& g = ctx.createGroup("mesh", 30000);
        Emitter mesh;
        mesh.shape = octahedron(Vec3(0.0f, 2.0f, 0.0f), 1.5f);
        mesh.rate = 400;
        mesh.velocity = Vec3(0.2f, 0.0f, 0.0f);
        mesh.types = {drawingType(nestedUnion())};
        g.addEmitter(mesh);
        Emitter un;
        un.shape = nestedUnion();
        un.rate = 350;
        ParticleType a = drawingType(octahedron()), b = drawingType(points);
        b.weight = 2.0f;
        un.types = {a, b};
        un.bursts = {{1.0, 500, 0.0, 1}};
        g.addEmitter(un);
        Emitter p;
        p.shape = points;
        p.rate = 100;
        p.types = {drawingType(points)};
        g.addEmitter(p);
        g.setActions({Gravity{kDown}, Move{}, KillOld{}});
        g.require(kAll);
        return g;
      },
      90);
}

// Prime emitters, three levels deep as in samples/effects/fireworks: a moving prime with a
// shape spawns emitters by rate and bursts; they fly under gravity and drag, emit by
// distance, and at death burst particles and spawn children that inherit their velocity,
// emit by rate with several types and burst again at death. A static emitter emits beside
// them (its newborns come first in every step). The counts per generation and of spawned
// emitters must agree too.
TEST(OpenCLEmission, PrimeEmitters) {
  FLURRY_REQUIRE_OPENCL();
  const Build build = [](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("fireworks", 40000);
    g.addEmitter(spray(Vec3(0.0f), 200));
    auto sparks = std::make_shared<EmitterSpec>();
    sparks->velocity = Domain::sphere(Vec3(0.0f), 7.0f, 6.0f);
    sparks->inheritVelocity = 0.5f;
    sparks->lifetime = Fuzzy(0.9f, 0.3f);
    sparks->acceleration = Vec3(0.0f, -4.0f, 0.0f);
    sparks->drag = 1.0f;
    sparks->deathBurst = 6;
    sparks->emitter.rate = 60;
    ParticleType warm = drawingType(Domain::sphere(Vec3(0.0f), 0.5f));
    warm.weight = 2.0f;
    warm.color = Domain::box(Vec3(0.9f, 0.3f, 0.1f), Vec3(1.0f, 0.6f, 0.2f));
    ParticleType cold = drawingType(Domain::sphere(Vec3(0.0f), 0.5f));
    cold.color = Domain::box(Vec3(0.2f, 0.5f, 0.9f), Vec3(0.5f, 0.8f, 1.0f));
    sparks->emitter.types = {warm, cold};
    PrimeEmitter mortar;
    mortar.shape = Domain::disc(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 4.0f);
    mortar.rate = 1.2;
    mortar.bursts = {{0.0, 2}, {2.5, 3}};
    mortar.velocity = Vec3(0.5f, 0.0f, 0.0f);
    mortar.child.velocity = Domain::cone(Vec3(0.0f), Vec3(0.0f, 18.0f, 0.0f), 3.0f);
    mortar.child.lifetime = Fuzzy(1.4f, 0.2f);
    mortar.child.drag = 0.1f;
    mortar.child.deathChildren = 12;
    mortar.child.deathBurst = 20;
    mortar.child.emitter.spacing = 0.15f;
    mortar.child.emitter.shape = Domain::sphere(Vec3(0.0f), 0.05f);
    mortar.child.emitter.types = {drawingType(Domain::sphere(Vec3(0.0f), 0.3f))};
    mortar.child.next = sparks;
    g.addPrimeEmitter(mortar);
    PrimeEmitter rockets;  // no drag, a path, bursts timed from each rocket's birth
    rockets.path = {{0.0, Vec3(-3.0f, 0.0f, 0.0f)}, {6.0, Vec3(3.0f, 0.0f, 2.0f)}};
    rockets.rate = 2.0;
    rockets.start = 0.5;
    rockets.stop = 5.0;
    rockets.child.velocity = Domain::box(Vec3(-1.0f, 8.0f, -1.0f), Vec3(1.0f, 10.0f, 1.0f));
    rockets.child.lifetime = 1.0f;
    rockets.child.emitter.rate = 90;
    rockets.child.emitter.bursts = {{0.2, 30, 0.3, 2}};
    rockets.child.emitter.normalSpeed = Fuzzy(1.0f, 0.5f);
    rockets.child.emitter.shape = octahedron(Vec3(0.0f), 0.2f);
    g.addPrimeEmitter(rockets);
    g.setActions({Gravity{Vec3(0.0f, -3.0f, 0.0f)}, Damping{Vec3(1.5f)}, Move{}, KillOld{}});
    g.require(kAll);
    return g;
  };
  const RunResult cpu = runEffect(Backend::Cpu, build, kSteps);
  const RunResult cl = runEffect(Backend::OpenCL, build, kSteps);
  EXPECT_GT(cpu.stats.emittersSpawned, 100u);  // the levels all spawned
  ASSERT_GE(cpu.stats.emittedByGeneration.size(), 3u);
  EXPECT_GT(cpu.stats.emittedByGeneration[2], 0u);
  expectSameWithEmitterStats(cpu, cl);
}

// Live emitters' births past the capacity are dropped on both backends alike, after the
// static emitters' (the CPU's order of runs).
TEST(OpenCLEmission, PrimeEmittersAtCapacity) {
  FLURRY_REQUIRE_OPENCL();
  const Build build = [](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("full", 1500);
    g.addEmitter(spray(Vec3(0.0f), 300));
    PrimeEmitter p;
    p.rate = 3.0;
    p.child.lifetime = Fuzzy(1.0f, 0.5f);
    p.child.deathBurst = 100;
    p.child.emitter.rate = 200;
    p.child.emitter.types = {drawingType(Domain::sphere(Vec3(0.0f), 1.0f))};
    g.addPrimeEmitter(p);
    g.setActions({Gravity{kDown}, Move{}, KillOld{}});
    return g;
  };
  const RunResult cpu = runEffect(Backend::Cpu, build, 120);
  const RunResult cl = runEffect(Backend::OpenCL, build, 120);
  EXPECT_GT(cpu.stats.droppedAtCapacity, 0u);
  expectSameWithEmitterStats(cpu, cl);
}

// A newborn's rest pose (PositionB) is where it was born and its second velocity zero, as
// for the particles of a lane added later (GroupImpl::ensureStorage), not what the slot's
// last particle left there. The CPU backend leaves these lanes unwritten at birth, so this
// checks the device alone.
TEST(OpenCLEmission, NewbornsRestPoseIsTheirBirthPlace) {
  FLURRY_REQUIRE_OPENCL();
  const Build build = [](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("rest", 5000);
    Emitter e = spray(Vec3(0.0f, 1.0f, 0.0f), 300);
    e.types[0].lifetime = Fuzzy(0.3f, 0.1f);
    e.types[0].velocity = Domain::point(Vec3(0.0f));  // Move keeps them where they were born
    g.addEmitter(e);
    g.setActions({Move{}, KillOld{}});  // slots are reused: newborns fill the holes of the dead
    g.require({Attribute::PositionB, Attribute::VelocityB});
    return g;
  };
  const RunResult cl = runEffect(Backend::OpenCL, build, 40);
  ASSERT_GT(cl.stats.killedByAge, 0u);
  ASSERT_GT(cl.size, 0u);
  // Both backends write the same rest pose (sdk/src/emission.cpp store / emitBatch).
  const RunResult cpu = runEffect(Backend::Cpu, build, 40);
  expectSame(cpu, cl);
  for (const RunResult* r : {&cpu, &cl})
    for (const auto& [id, p] : r->byId) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(p.positionB[c], p.position[c]) << "particle " << id;
        ASSERT_EQ(p.velocityB[c], 0.0f) << "particle " << id;
      }
    }
}

// Newborns run the action list for the part of their birth step they still have to live
// (issue #11). Both checks share one program: the same list and emitter kinds, other numbers.
namespace {

// A nozzle (a point, one velocity: nothing drawn) over a floor plane at y = floorY, under
// gravity, integrated exactly.
Group& nozzleOverFloor(Context& ctx, Vec3 at, Vec3 velocity, double rate, float floorY) {
  Group& g = ctx.createGroup("nozzle", 4000);
  Emitter e;
  e.shape = Domain::point(Vec3(0.0f));
  e.position = at;
  e.rate = rate;
  e.start = 0.001;  // no birth on a step boundary of either dt below
  ParticleType t;
  t.velocity = Domain::point(velocity);
  e.types = {t};
  g.addEmitter(e);
  ActionList list({Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                   Bounce{Domain::plane(Vec3(0.0f, floorY, 0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.5f},
                   Move{}});
  list.setIntegrator(Integrator::Exact);
  g.setActions(list);
  return g;
}

ContextOptions onOpenCL(double dt) {
  ContextOptions o;
  o.dt = dt;
  o.backend = Backend::OpenCL;
  return o;
}

}  // namespace

// A newborn born just above a deflector and flying at it is bounced in its birth step: it
// never ends the step behind the floor (it used to be placed at birth place + v·age).
TEST(OpenCLEmission, NewbornsNearADeflectorStayInFront) {
  FLURRY_REQUIRE_OPENCL();
  Context ctx(onOpenCL(1.0 / 30.0));
  Group& g = nozzleOverFloor(ctx, Vec3(0.0f, 0.01f, 0.0f), Vec3(1.0f, -4.0f, 0.0f), 300, 0.0f);
  for (int s = 0; s < 30; ++s) {
    ctx.step();
    ASSERT_GT(g.size(), 0u);
    for (std::size_t i = 0; i < g.size(); ++i)
      ASSERT_GE(g.particle(i).position.y, 0.0f) << "particle " << i << " after step " << s + 1;
  }
}

// A fountain under gravity, integrated exactly, with nothing drawn: its mean height over the
// particles at the same times does not depend on the step length (newborns included).
TEST(OpenCLEmission, FountainMeanHeightDoesNotDependOnDt) {
  FLURRY_REQUIRE_OPENCL();
  Context coarse(onOpenCL(1.0 / 24.0)), fine(onOpenCL(1.0 / 240.0));
  const Vec3 at(0.0f, 0.5f, 0.0f), v(0.5f, 5.0f, 0.0f);
  Group& a = nozzleOverFloor(coarse, at, v, 100, -100.0f);
  Group& b = nozzleOverFloor(fine, at, v, 100, -100.0f);
  auto meanHeight = [](Group& g) {
    double sum = 0;
    for (std::size_t i = 0; i < g.size(); ++i) sum += g.particle(i).position.y;
    return sum / double(g.size());
  };
  double worst = 0;
  for (int s = 0; s < 24; ++s) {
    coarse.step();
    fine.run(10);
    ASSERT_EQ(a.size(), b.size()) << "after " << s + 1 << " coarse steps";
    ASSERT_GT(a.size(), 0u);
    const double ma = meanHeight(a), mb = meanHeight(b);
    worst = std::max(worst, std::abs(ma - mb));
    EXPECT_NEAR(ma, mb, 1e-5) << "after " << s + 1 << " coarse steps";
  }
  ::testing::Test::RecordProperty("max_abs_difference", std::to_string(worst));
}
