// FLURRY_CALLBACK: a user action's body written once, run as C++ on the CPU (the OpenCL side
// is in tests/opencl/test_opencl_core.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

Particle particleAt(Vec3 p, Vec3 v) {
  Particle q;
  q.position = p;
  q.velocity = v;
  return q;
}

void run(const Callback& cb, Particle& p, float dt = 0.5f, double time = 2.0) {
  cb.function(p, CallbackContext{dt, time, 4});
}

}  // namespace

TEST(Callback, TheAttributesAreTheNamesTheBodyUses) {
  EXPECT_EQ(attributesUsedBy("user += dt; if (py > 2.0f) vx += 0.5f;"),
            (AttributeSet{Attribute::UserData, Attribute::Position, Attribute::Velocity}));
  // Whole identifiers only: not inside a longer name, a number's suffix or a hex literal.
  EXPECT_EQ(attributesUsedBy("float apx = 0xa; float sizes = 1e3f; int ids = 2;"), AttributeSet{});
  EXPECT_EQ(attributesUsedBy("a = 0.5f;"), AttributeSet{Attribute::Color});
  EXPECT_EQ(
      attributesUsedBy("birthsize = size; vis = 0u; life = age + mass + charge;"),
      (AttributeSet{Attribute::BirthSize, Attribute::Size, Attribute::Visible, Attribute::Lifetime,
                    Attribute::Age, Attribute::Mass, Attribute::Charge}));
  EXPECT_EQ(attributesUsedBy("rotz = upx + prevy + pbz + vbx;"),
            (AttributeSet{Attribute::RotVelocity, Attribute::Up, Attribute::PrevPosition,
                          Attribute::PositionB, Attribute::VelocityB}));
  EXPECT_TRUE(usesIdentifier("x; return;", "return"));
  EXPECT_FALSE(usesIdentifier("returned = 1;", "return"));
}

TEST(Callback, OneBodyIsTheFunctionAndTheOpenCLText) {
  const Callback cb = FLURRY_CALLBACK(user += dt; if (py > 2.0f) vx += 0.5f;);
  EXPECT_EQ(cb.opencl, "user += dt; if (py > 2.0f) vx += 0.5f;");
  EXPECT_EQ(cb.attributes,
            (AttributeSet{Attribute::UserData, Attribute::Position, Attribute::Velocity}));
  Particle high = particleAt(Vec3(0, 3, 0), Vec3(1, 0, 0));
  run(cb, high);
  EXPECT_EQ(high.userData, 0.5f);
  EXPECT_EQ(high.velocity.x, 1.5f);
  Particle low = particleAt(Vec3(0, 1, 0), Vec3(1, 0, 0));
  run(cb, low);
  EXPECT_EQ(low.velocity.x, 1.0f);
}

TEST(Callback, BuiltinsBreakAndCommasBehaveAsOnTheDevice) {
  // Commas inside the body (arguments, declarations) survive the macro; break ends the body;
  // the OpenCL builtins have OpenCL's definitions.
  const Callback cb = FLURRY_CALLBACK(
      const float speed = sqrt(vx * vx + vy * vy + vz * vz), cap = 2.0f;
      if (speed > cap) {
        vx *= cap / speed;
        vy *= cap / speed;
        vz *= cap / speed;
      }
      size = clamp(mix(0.0f, 1.0f, 0.25f), 0.3f, 1.0f) + step(1.0f, age) + sign(-0.0f);
      user = smoothstep(0.0f, 2.0f, 1.0f) + fmax(min(r, g), max(b, 0.0f));
      if (id % 2u == 1u) break;
      a = (float)time + radians(180.0f) - M_PI_F;);
  EXPECT_TRUE(cb.attributes.contains({Attribute::Velocity, Attribute::Size, Attribute::Age,
                                      Attribute::UserData, Attribute::Color, Attribute::Id}));
  Particle p = particleAt(Vec3(0), Vec3(3, 4, 0));
  p.age = 1.5f;
  p.color = Vec4(0.2f, 0.7f, -1.0f, 0.0f);
  p.id = 2;
  run(cb, p, 0.1f, 7.0);
  EXPECT_NEAR(glm::length(p.velocity), 2.0f, 1e-6f);
  EXPECT_EQ(p.size, 0.3f + 1.0f);
  EXPECT_EQ(std::signbit(p.size), false);
  EXPECT_FLOAT_EQ(p.userData, 0.5f + 0.2f);
  EXPECT_NEAR(p.color.a, 7.0f, 1e-6f);
  Particle odd = p;
  odd.id = 3;
  odd.color.a = 0.0f;
  run(cb, odd, 0.1f, 7.0);
  EXPECT_EQ(odd.color.a, 0.0f);  // ended by break before the last statement
}

TEST(Callback, ARunsInAGroupStoringWhatItUses) {
  // A group stores UserData because the body names `user`, and every particle's user value
  // counts its steps.
  Context ctx;
  Group& g = ctx.createGroup("counted", 1000);
  Emitter e;
  e.shape = Domain::point(Vec3(0));
  e.rate = 300.0f;
  e.types[0].velocity = Domain::point(Vec3(0, 1, 0));
  g.addEmitter(e);
  const Callback count = FLURRY_CALLBACK(user += 1.0f;);
  g.setActions({count, Move{}});
  ctx.run(10);
  ASSERT_TRUE(g.attributes().has(Attribute::UserData));
  ASSERT_GT(g.size(), 0u);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Particle p = g.particle(i);
    EXPECT_GE(p.userData, 1.0f);
    EXPECT_LE(p.userData, 10.0f);
    EXPECT_EQ(p.userData, std::round(p.userData));
  }
}
