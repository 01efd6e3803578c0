// Packing live particles as vertex / instance data for a game's own renderer.
#include <gtest/gtest.h>

#include <cstring>

#include "flurry/flurry.hpp"
#include "flurry/interop.hpp"

using namespace flurry;

namespace {
template <typename T>
T read(const std::vector<std::byte>& b, std::size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}

Group& makeGroup(Context& ctx, AttributeSet extra = {}) {
  Group& g = ctx.createGroup("g", 16);
  g.require(AttributeSet{Attribute::Color, Attribute::Size} | extra);
  for (int i = 0; i < 5; ++i) {
    Particle p;
    p.position = Vec3(float(i), 2.0f * float(i), -float(i));
    p.color = Vec4(0.1f * float(i), 0.5f, 1.5f, 1.0f);
    p.size = 0.01f * float(i + 1);
    p.visible = i != 2;
    g.add(p);
  }
  return g;
}
}  // namespace

TEST(Interop, InstancesLayout) {
  const PackLayout l = PackLayout::instances();
  EXPECT_EQ(l.stride, 32u);
  EXPECT_EQ(l.attributes(), (AttributeSet{Attribute::Position, Attribute::Size, Attribute::Color}));
  Context ctx;
  Group& g = makeGroup(ctx);
  const auto bytes = packParticles(g, l);
  ASSERT_EQ(bytes.size(), 5u * 32u);
  for (int i = 0; i < 5; ++i) {
    const std::size_t at = std::size_t(i) * 32;
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 0), float(i));
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 4), 2.0f * float(i));
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 8), -float(i));
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 12), 0.01f * float(i + 1));
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 16), 0.1f * float(i));
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 24), 1.5f);
  }
}

TEST(Interop, CustomLayoutWithBytesAndIds) {
  Context ctx;
  Group& g = makeGroup(ctx);
  const PackLayout l = PackLayout::interleaved({{Attribute::Color, PackFormat::UNorm8},
                                                {Attribute::Position, PackFormat::Float32},
                                                {Attribute::Id, PackFormat::UInt32}});
  EXPECT_EQ(l.fields[1].offset, 4u);
  EXPECT_EQ(l.fields[2].offset, 16u);
  EXPECT_EQ(l.stride, 20u);
  const auto bytes = packParticles(g, l);
  ASSERT_EQ(bytes.size(), 5u * 20u);
  const auto ids = g.ids();
  for (int i = 0; i < 5; ++i) {
    const std::size_t at = std::size_t(i) * 20;
    EXPECT_EQ(std::uint8_t(bytes[at + 0]), std::uint8_t(std::lround(0.1f * float(i) * 255.0f)));
    EXPECT_EQ(std::uint8_t(bytes[at + 1]), 128);  // 0.5 rounds to 128 of 255
    EXPECT_EQ(std::uint8_t(bytes[at + 2]), 255);  // 1.5 clamps
    EXPECT_FLOAT_EQ(read<float>(bytes, at + 8), 2.0f * float(i));
    EXPECT_EQ(read<std::uint32_t>(bytes, at + 16), ids[std::size_t(i)]);
  }
}

TEST(Interop, HiddenBlockedAndSorted) {
  Context ctx;
  Group& g = makeGroup(ctx, {Attribute::Visible});
  PackOptions o;
  // Visible == 0 (particle 2) is left out, and so is what a blocker holds (particle 3).
  const Domain blockers[] = {Domain::sphere(Vec3(3, 6, -3), 0.5f)};
  o.blockers = blockers;
  const PackLayout l = PackLayout::interleaved({{Attribute::Position, PackFormat::Float32}});
  auto bytes = packParticles(g, l, o);
  ASSERT_EQ(bytes.size(), 3u * 12u);
  EXPECT_FLOAT_EQ(read<float>(bytes, 0), 0.0f);
  EXPECT_FLOAT_EQ(read<float>(bytes, 12), 1.0f);
  EXPECT_FLOAT_EQ(read<float>(bytes, 24), 4.0f);
  // Back to front from an eye beyond particle 0: the farthest (4) first.
  o.sortFromEye = Vec3(-1.0f, -2.0f, 1.0f);
  bytes = packParticles(g, l, o);
  ASSERT_EQ(bytes.size(), 3u * 12u);
  EXPECT_FLOAT_EQ(read<float>(bytes, 0), 4.0f);
  EXPECT_FLOAT_EQ(read<float>(bytes, 12), 1.0f);
  EXPECT_FLOAT_EQ(read<float>(bytes, 24), 0.0f);
  // skipHidden = false keeps particle 2.
  o = {};
  o.skipHidden = false;
  EXPECT_EQ(packParticles(g, l, o).size(), 5u * 12u);
}

TEST(Interop, UnstoredAttributesReadAsDefaults) {
  Context ctx;
  Group& g = ctx.createGroup("bare", 4);
  g.add(Particle{});
  ASSERT_FALSE(g.attributes().has(Attribute::Color));
  const auto bytes = packParticles(g, PackLayout::instances());
  ASSERT_EQ(bytes.size(), 32u);
  EXPECT_FLOAT_EQ(read<float>(bytes, 12), Particle{}.size);
  for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(read<float>(bytes, 16 + 4 * std::size_t(c)), 1.0f);
}

TEST(Interop, BadLayoutsNameTheField) {
  Context ctx;
  Group& g = makeGroup(ctx);
  PackLayout l = PackLayout::instances();
  l.fields[2].offset = 20;  // rgba would end at byte 36, past the stride of 32
  try {
    packParticles(g, l);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(e.parameter(), "layout.fields[2].offset");
  }
  l = PackLayout::interleaved({{Attribute::Size, PackFormat::UInt32}});
  EXPECT_THROW(packParticles(g, l), InvalidArgument);
  std::vector<std::byte> small(10);
  try {
    packParticles(g, PackLayout::instances(), small);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(e.parameter(), "out");
  }
}
