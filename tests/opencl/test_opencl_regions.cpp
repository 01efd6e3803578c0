// Parity on the device: mesh and union domains as the regions, obstacles and sampled
// domains of actions (Sink, SinkVelocity, Block, Avoid, Jet, Random*).
// Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp), and
// first makes sure, on the CPU, that the action under test changes the particles (a test of
// an action that does nothing could not fail).
#include <cmath>
#include <cstdio>
#include <vector>

#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;

namespace {

// ---- Shapes -----------------------------------------------------------------------------

// A closed axis-aligned box as a mesh of 12 triangles, counter-clockwise seen from outside:
// its faces and edges lie along the axes, which the CPU's skewed containment ray must miss.
Domain boxMesh(Vec3 lo, Vec3 hi) {
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k)
    v.push_back(Vec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z));
  return Domain::mesh(v, {{0, 2, 1},
                          {1, 2, 3},  // z = lo
                          {4, 5, 6},
                          {5, 7, 6},  // z = hi
                          {0, 1, 4},
                          {1, 5, 4},  // y = lo
                          {2, 6, 3},
                          {3, 6, 7},  // y = hi
                          {0, 4, 2},
                          {2, 4, 6},  // x = lo
                          {1, 3, 5},
                          {3, 7, 5}});  // x = hi
}

// A closed octahedron, counter-clockwise seen from outside.
Domain octahedron(Vec3 c, float r) {
  std::vector<Vec3> v = {c + Vec3(r, 0, 0),  c + Vec3(-r, 0, 0), c + Vec3(0, r, 0),
                         c + Vec3(0, -r, 0), c + Vec3(0, 0, r),  c + Vec3(0, 0, -r)};
  return Domain::mesh(
      v, {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

// A tetrahedron with oblique faces, each turned to face away from the opposite vertex.
Domain tetrahedron(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  const std::vector<Vec3> v = {a, b, c, d};
  std::vector<glm::uvec3> t;
  for (unsigned k = 0; k < 4; ++k) {
    glm::uvec3 f((k + 1) % 4, (k + 2) % 4, (k + 3) % 4);
    const Vec3 n = glm::cross(v[f.y] - v[f.x], v[f.z] - v[f.x]);
    if (glm::dot(n, v[k] - v[f.x]) > 0.0f) std::swap(f.y, f.z);
    t.push_back(f);
  }
  return Domain::mesh(v, t);
}

// A union of a mesh and a solid.
Domain meshUnion(Vec3 at) {
  return Domain::unite({boxMesh(at + Vec3(-0.9f, 0.0f, -0.6f), at + Vec3(0.2f, 0.6f, 0.7f)),
                        Domain::sphere(at + Vec3(0.8f, 0.3f, 0.1f), 0.5f)});
}

// A union with a union in it (a mesh and a cylinder), its leaves of four kinds.
Domain nestedUnion(Vec3 at) {
  return Domain::unite({Domain::sphere(at + Vec3(1.0f, 0.2f, 0.0f), 0.45f),
                        Domain::unite({octahedron(at + Vec3(-0.6f, 0.5f, 0.1f), 0.6f),
                                       Domain::cylinder(at + Vec3(0.0f, -0.3f, -0.8f),
                                                        at + Vec3(0.3f, 0.0f, 0.8f), 0.3f)}),
                        tetrahedron(at + Vec3(-0.4f, 0.9f, -0.8f), at + Vec3(0.9f, 0.8f, -0.6f),
                                    at + Vec3(0.1f, 1.0f, 0.9f), at + Vec3(0.2f, 1.6f, 0.0f))});
}

// ---- Checks -----------------------------------------------------------------------------

Build build(const ActionList& actions, const Emitter& e, AttributeSet require) {
  return [=](Context& ctx) -> Group& {
    Group& g = ctx.createGroup("regions", 20000);
    g.addEmitter(e);
    g.setActions(actions);
    g.require(require);
    return g;
  };
}

// Parity of `actions`, whose actions[tested] must change the particles (on the CPU, against
// the same list without it). Prints the largest |cpu - opencl| of the run.
void check(const ActionList& actions, std::size_t tested, Emitter e = spray(),
           AttributeSet require = {}) {
  FLURRY_REQUIRE_OPENCL();
  EXPECT_TRUE(differs(
      runEffect(Backend::Cpu, build(actions, e, require), kSteps),
      runEffect(Backend::Cpu, build(withoutAction(actions, tested), e, require), kSteps), 10))
      << "actions[" << tested << "] (" << actionName(actions.actions()[tested])
      << ") does not change the particles: the test proves nothing";
  if (::testing::Test::HasFailure()) return;
  checkParityReporting(build(actions, e, require));
}

// The regions the Sink, Block and Avoid tests use, in the spray's path (about y = 1..2.3).
std::vector<Domain> regions() {
  return {boxMesh(Vec3(-0.8f, 1.5f, -0.8f), Vec3(0.6f, 2.2f, 0.9f)),
          octahedron(Vec3(0.5f, 1.7f, 0.2f), 0.7f),
          tetrahedron(Vec3(-1.5f, 1.2f, -1.0f), Vec3(1.5f, 1.4f, -0.8f), Vec3(0.0f, 1.3f, 1.6f),
                      Vec3(0.2f, 2.6f, 0.1f)),
          meshUnion(Vec3(0.0f, 1.5f, 0.0f)), nestedUnion(Vec3(0.0f, 1.3f, 0.0f))};
}

const Bounce kFloor{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.6f, 0.1f, 0.0f};

// Spinning, colourful particles: RandomRotVelocity has a lane to write.
Emitter spinning() {
  Emitter e = spray();
  e.types[0].rotVelocity = Domain::box(Vec3(-2.0f), Vec3(2.0f));
  return e;
}

}  // namespace

// ---- Sink ---------------------------------------------------------------------------------

TEST(OpenCLRegions, SinkInside) {
  for (const Domain& r : regions()) {
    SCOPED_TRACE(r.name());
    check({Gravity{kDown}, Sink{r, 0.0f, Sink::Mode::Inside}, Move{}, KillOld{}}, 1);
  }
}

// Outside a region around the emitter; with passThrough (its own draw per particle).
TEST(OpenCLRegions, SinkOutside) {
  const Domain around[] = {
      boxMesh(Vec3(-1.4f, 0.6f, -1.3f), Vec3(1.5f, 2.4f, 1.2f)),
      Domain::unite({octahedron(Vec3(0.0f, 1.2f, 0.0f), 1.6f),
                     Domain::unite({Domain::box(Vec3(-2.0f, 0.0f, -0.4f), Vec3(2.0f, 1.0f, 0.4f)),
                                    Domain::sphere(Vec3(0.0f, 2.4f, 0.0f), 0.6f)})}),
  };
  for (const Domain& r : around) {
    SCOPED_TRACE(r.name());
    check({Gravity{kDown}, Sink{r, 0.0f, Sink::Mode::Outside}, Move{}, KillOld{}}, 1);
    check({Gravity{kDown}, Sink{r, 0.3f, Sink::Mode::Outside}, Move{}, KillOld{}}, 1);
  }
}

TEST(OpenCLRegions, SinkEnterLeave) {
  for (const Domain& r : regions()) {
    SCOPED_TRACE(r.name());
    check({Gravity{kDown}, Sink{r, 0.0f, Sink::Mode::Enter}, Move{}, KillOld{}}, 1);
    check({Gravity{kDown}, Sink{r, 0.2f, Sink::Mode::Leave}, Move{}, KillOld{}}, 1);
  }
}

// Hit needs a plane piece: validation refuses a mesh or a union on both backends alike.
TEST(OpenCLRegions, SinkHitRefused) {
  FLURRY_REQUIRE_OPENCL();
  for (const Domain& r : {regions()[0], regions()[3]})
    for (Backend b : {Backend::Cpu, Backend::OpenCL}) {
      ContextOptions o;
      o.backend = b;
      Context ctx(o);
      Group& g = ctx.createGroup("hit", 100);
      EXPECT_THROW(g.setActions({Sink{r, 0.0f, Sink::Mode::Hit}, Move{}}), InvalidArgument);
    }
}

TEST(OpenCLRegions, SinkVelocity) {
  // Falling fast (velocities about (0, -4, 0)), and a union of velocities.
  check({Gravity{kDown}, SinkVelocity{octahedron(Vec3(0.0f, -4.0f, 0.0f), 2.0f), true}, Move{},
         KillOld{}},
        1);
  check({Gravity{kDown},
         SinkVelocity{Domain::unite({boxMesh(Vec3(-3.0f, -1.0f, -3.0f), Vec3(3.0f, 6.0f, 0.0f)),
                                     Domain::unite({Domain::sphere(Vec3(0.0f, -3.0f, 1.0f), 1.5f),
                                                    octahedron(Vec3(1.0f, 2.0f, 1.5f), 1.2f)})}),
                      false},
         Move{}, KillOld{}},
        1);
}

// ---- Block --------------------------------------------------------------------------------

TEST(OpenCLRegions, Block) {
  const auto r = regions();
  // The first blocker (which starts from "visible") and a later one.
  check({Gravity{kDown}, Block{r[0]}, Move{}, Block{r[4]}, KillOld{}}, 1, spray(),
        {Attribute::Visible});
  check({Gravity{kDown}, Block{r[2]}, Move{}, Block{r[3]}, KillOld{}}, 3, spray(),
        {Attribute::Visible});
}

// ---- Avoid --------------------------------------------------------------------------------

TEST(OpenCLRegions, Avoid) {
  for (const Domain& o : regions()) {
    SCOPED_TRACE(o.name());
    check({Gravity{kDown}, Avoid{o, 2.0f, 1e-2f, 0.3f}, kFloor, Move{}, KillOld{}}, 1);
  }
}

// ---- Sampled domains: Jet and the random actions -------------------------------------------

TEST(OpenCLRegions, Jet) {
  check(
      {Gravity{kDown}, Jet{Vec3(0.0f, 2.0f, 0.0f), 1.5f, octahedron(Vec3(1.0f, 8.0f, 0.0f), 4.0f)},
       Move{}, KillOld{}},
      1);
  check({Gravity{kDown}, Jet{Vec3(0.0f, 2.0f, 0.0f), 1.5f, nestedUnion(Vec3(0.0f, 6.0f, 0.0f))},
         Move{}, KillOld{}},
        1);
}

TEST(OpenCLRegions, RandomAccel) {
  check(
      {RandomAccel{boxMesh(Vec3(-4.0f, -2.0f, -3.0f), Vec3(5.0f, 3.0f, 4.0f))}, Move{}, KillOld{}},
      0);
  check({Gravity{kDown}, RandomAccel{meshUnion(Vec3(0.0f, 2.0f, 0.0f))}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLRegions, RandomDisplace) {
  check({Gravity{kDown},
         RandomDisplace{tetrahedron(Vec3(-1.0f), Vec3(2.0f, -1.0f, 0.0f), Vec3(0.0f, 1.5f, -1.0f),
                                    Vec3(0.0f, 0.0f, 2.0f))},
         Move{}, KillOld{}},
        1);
  check({Gravity{kDown}, RandomDisplace{nestedUnion(Vec3(0.0f))}, Move{}, KillOld{}}, 1);
}

TEST(OpenCLRegions, RandomVelocity) {
  check({RandomVelocity{octahedron(Vec3(0.0f, 1.0f, 0.0f), 2.5f)}, Move{}, KillOld{}}, 0);
  check({RandomVelocity{nestedUnion(Vec3(0.0f, 0.5f, 0.0f))}, Move{}, KillOld{}}, 0);
}

TEST(OpenCLRegions, RandomRotVelocity) {
  check({Gravity{kDown}, RandomRotVelocity{boxMesh(Vec3(-3.0f), Vec3(2.0f, 4.0f, 3.0f))}, Move{},
         KillOld{}},
        1, spinning(), {Attribute::RotVelocity});
  check({Gravity{kDown}, RandomRotVelocity{meshUnion(Vec3(1.0f, -2.0f, 0.0f))}, Move{}, KillOld{}},
        1, spinning(), {Attribute::RotVelocity});
}

// Jet and RandomAccel as forces an integrator evaluates (their accel code), over sub-steps,
// together with a mesh region the same step packs after them.
TEST(OpenCLRegions, SampledUnderIntegrators) {
  for (Integrator in : {Integrator::RK4, Integrator::VelocityVerlet}) {
    ActionList l{Gravity{kDown},
                 Jet{Vec3(0.0f, 2.0f, 0.0f), 1.5f, nestedUnion(Vec3(0.0f, 5.0f, 0.0f))},
                 RandomAccel{octahedron(Vec3(0.0f), 3.0f)},
                 Move{},
                 Sink{regions()[3], 0.0f, Sink::Mode::Enter},
                 KillOld{}};
    l.setIntegrator(in);
    l.setSubsteps(Substeps{1.0 / 75.0});
    check(l, 1);
    check(l, 2);
  }
}
