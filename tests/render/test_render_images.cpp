// Image tests: fixed scenes rendered offscreen (a private Xvfb and Mesa's llvmpipe when there
// is no display), compared with references and checked for what they mean.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <glm/glm.hpp>

#include "flurry/flurry.hpp"
#include "flurry/render.hpp"
#include "flurry/render_viewer.hpp"
#include "render/platform.hpp"
#include "render_test_util.hpp"

using namespace flurry;
using flurry::test::compareWithReference;
using flurry::test::same;

namespace {

constexpr int kSize = 256;

OffscreenOptions small() {
  return {kSize, kSize, 4};
}

Camera front(float distance, float fovY) {
  Camera c;
  c.target = Vec3(0.0f);
  c.distance = distance;
  c.yaw = 0.0f;  // eye on +z: world x is screen right, world y screen up
  c.pitch = 0.0f;
  c.fovY = fovY;
  return c;
}

// Pixels per world unit at the target's depth for a front() camera.
float pixelsPerUnit(const Camera& c) {
  return float(kSize) * 0.5f / (c.distance * std::tan(glm::radians(c.fovY) * 0.5f));
}

Group& particles(Context& ctx, AttributeSet extra = {}) {
  Group& g = ctx.createGroup("g", 1024);
  g.require(Renderer::attributes() | extra);
  return g;
}

void add(Group& g, Vec3 p, float radius, Vec4 color, bool visible = true) {
  Particle q;
  q.position = p;
  q.size = radius;
  q.color = color;
  q.visible = visible;
  ASSERT_TRUE(g.add(q));
}

// Restores an environment variable at the end of a test.
struct EnvGuard {
  const char* name;
  std::string old;
  bool had;
  explicit EnvGuard(const char* n) : name(n), had(std::getenv(n) != nullptr) {
    if (had) old = std::getenv(n);
  }
  ~EnvGuard() {
    if (had)
      setenv(name, old.c_str(), 1);
    else
      unsetenv(name);
  }
};

}  // namespace

// One sphere-like particle under one directional light. Its color has no blue, so the blue
// channel is the specular highlight alone.
TEST(RenderImage, LitSphere) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.lighting.ambient = Vec3(0.2f);
  const Vec3 l = glm::normalize(Vec3(1.0f, 0.6f, 1.0f));
  s.lighting.lights = {Light{Light::Type::Directional, l, Vec3(1.0f)}};
  s.lighting.material = Material{Vec3(1.0f), Vec3(0.8f), Vec3(0.6f), 30.0f};
  OffscreenRenderer r(small(), s);
  Context ctx;
  Group& g = particles(ctx);
  const Vec3 color(1.0f, 0.35f, 0.0f);
  add(g, Vec3(0.0f), 1.0f, Vec4(color, 1.0f));
  const Image img = r.render(g);
  EXPECT_EQ(r.lastDrawn(), 1u);
  compareWithReference(img, "lit_sphere");

  const float rpx = pixelsPerUnit(s.camera);  // the billboard's radius in pixels
  const Vec3 eye = s.camera.eye();
  // (u, v) on the billboard at a pixel centre, and the sphere's normal there.
  auto uv = [&](int x, int y) {
    return glm::vec2((float(x) + 0.5f - kSize / 2) / rpx, (kSize / 2 - (float(y) + 0.5f)) / rpx);
  };
  auto normalAt = [&](glm::vec2 q) {
    return Vec3(q.x, q.y, std::sqrt(std::max(0.0f, 1.0f - glm::dot(q, q))));
  };

  // The centre pixel is the CPU model's value.
  {
    const Vec3 n = normalAt(uv(kSize / 2, kSize / 2));
    const Vec3 expect = glm::clamp(shade(s.lighting, color, n, n, eye), 0.0f, 1.0f);
    const std::uint8_t* p = img.pixel(kSize / 2, kSize / 2);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], expect[c] * 255.0f, 3.0) << "channel " << c;
  }

  // The lit side (+x, towards the light) is brighter than the unlit side.
  double lit = 0, unlit = 0;
  int nl = 0, nu = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const glm::vec2 q = uv(x, y);
      if (glm::length(q) > 0.75f || std::abs(q.x) < 0.2f) continue;
      const std::uint8_t* p = img.pixel(x, y);
      (q.x > 0 ? lit : unlit) += p[0] + p[1];
      ++(q.x > 0 ? nl : nu);
    }
  ASSERT_GT(nl, 1000);
  ASSERT_GT(nu, 1000);
  EXPECT_GT(lit / nl, 1.5 * (unlit / nu));

  // The highlight peaks where (M·V)^n, with M·V = 2(N·L)(N·V) − V·L, is largest.
  int px = 0, py = 0, gx = 0, gy = 0;
  float best = -1.0f;
  int bestBlue = -1;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const glm::vec2 q = uv(x, y);
      if (glm::length(q) > 0.8f) continue;  // the disc's opaque part
      const Vec3 n = normalAt(q);
      const float m = specularTerm(mirrorCosine(n, l, glm::normalize(eye - n)), 30.0f);
      if (m > best) best = m, px = x, py = y;
      if (img.pixel(x, y)[2] > bestBlue) bestBlue = img.pixel(x, y)[2], gx = x, gy = y;
    }
  EXPECT_LE(std::hypot(gx - px, gy - py), 2.0)
      << "GPU peak (" << gx << "," << gy << "), formula (" << px << "," << py << ")";
  // ... which is near the half vector: N = normalize(L + V).
  const Vec3 h = glm::normalize(l + Vec3(0, 0, 1));
  EXPECT_NEAR(px, kSize / 2 + h.x * rpx, 3.0);
  EXPECT_NEAR(py, kSize / 2 - h.y * rpx, 3.0);
  EXPECT_NEAR(bestBlue, 0.6 * 255.0 * best, 4.0);
}

// A strand thinning from red to blue, shaded with the tangent model.
TEST(RenderImage, Strand) {
  RenderSettings s;
  s.camera = front(6.0f, 30.0f);
  // L and V are both across the strand's middle, so the highlight sits there; a hair-like
  // exponent keeps it narrow.
  s.lighting.lights = {Light{Light::Type::Directional, glm::normalize(Vec3(0, 1, 1)), Vec3(1.0f)}};
  s.lighting.material.n = 80.0f;
  Strands strands;
  std::vector<Vec3> p;
  std::vector<Vec4> c;
  std::vector<float> rad;
  const Vec4 c0(1.0f, 0.1f, 0.1f, 1.0f), c1(0.1f, 0.2f, 1.0f, 1.0f);
  for (int i = 0; i <= 40; ++i) {
    const float t = float(i) / 40.0f, x = -1.0f + 2.0f * t;
    p.emplace_back(x, 0.2f * x * x, 0.0f);
    c.push_back(glm::mix(c0, c1, t));
    rad.push_back(0.12f - 0.09f * t);
  }
  strands.add(p, c, rad);
  OffscreenRenderer r(small(), s);
  const Image img = r.render(strands);
  compareWithReference(img, "strand");

  const std::uint8_t* bg = img.pixel(0, 0);
  const float ppu = pixelsPerUnit(s.camera);
  auto column = [&](float x, int& covered, double& red, double& blue) {
    const int px = int(kSize / 2 + x * ppu);
    covered = 0;
    red = blue = 0;
    for (int y = 0; y < kSize; ++y)
      if (!same(img, px, y, bg)) {
        ++covered;
        red += img.pixel(px, y)[0];
        blue += img.pixel(px, y)[2];
      }
  };
  int thick, thin;
  double r0, b0, r1, b1;
  column(-0.8f, thick, r0, b0);
  column(0.8f, thin, r1, b1);
  // Radius 0.111 vs 0.039 at the same slope: 2.85 times as wide.
  EXPECT_GT(thick, 2 * thin) << thick << " vs " << thin;
  EXPECT_LT(thick, 4 * thin) << thick << " vs " << thin;
  EXPECT_GT(thin, 3);
  EXPECT_GT(r0, 2 * b0);  // red at the start
  EXPECT_GT(b1, 2 * r1);  // blue at the end

  // The middle vertex (tangent +x) shaded by the CPU model.
  {
    const Vec3 mid(0.0f), col = Vec3(glm::mix(c0, c1, 0.5f));
    const Vec3 expect =
        glm::clamp(shadeStrand(s.lighting, col, mid, Vec3(1, 0, 0), s.camera.eye()), 0.0f, 1.0f);
    const std::uint8_t* q = img.pixel(kSize / 2, kSize / 2 - 1);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(q[k], expect[k] * 255.0f, 4.0) << "channel " << k;
  }

  // As lines: one pixel wide wherever the strand is at least that thick.
  r.settings().strandStyle = StrandStyle::Line;
  const Image lines = r.render(strands);
  flurry::writePng(lines, flurry::test::outDir() / "strand_lines.png");
  int covered = 0;
  const int px = int(kSize / 2 - 0.8f * ppu);
  for (int y = 0; y < kSize; ++y) covered += !same(lines, px, y, bg);
  EXPECT_GE(covered, 1);
  EXPECT_LE(covered, 2);
}

// A box blocker across a stream of particles and a strand: nothing is drawn inside it, the
// background there is untouched, and both sides are drawn.
TEST(RenderImage, BlockerBox) {
  RenderSettings s;
  s.camera = front(8.0f, 40.0f);
  s.blend = BlendMode::Additive;
  s.blockers = {Domain::box(Vec3(-0.5f, -1.0f, -1.0f), Vec3(0.5f, 1.0f, 1.0f))};
  Context ctx;
  Group& g = particles(ctx);
  Strands strands;
  std::vector<Vec3> sp;
  std::vector<Vec4> sc;
  std::vector<float> sr;
  for (int k = 0; k < 80; ++k) {
    const float x = -2.0f + 0.05f * float(k) + 0.025f;  // none on the box's faces
    add(g, Vec3(x, 0.0f, 0.0f), 0.04f, Vec4(1.0f, 0.8f, 0.4f, 1.0f));
    sp.emplace_back(x, 0.6f, 0.0f);
    sc.emplace_back(0.3f, 1.0f, 0.5f, 1.0f);
    sr.push_back(0.03f);
  }
  strands.add(sp, sc, sr);
  OffscreenRenderer r(small(), s);
  const Group* groups[] = {&g};
  const Image img = r.render(groups, &strands);
  EXPECT_EQ(r.lastDrawn(), 60u);  // 20 of the 80 are inside the box
  compareWithReference(img, "blocker_box");

  const std::uint8_t* bg = img.pixel(0, 0);
  const float ppu = pixelsPerUnit(s.camera);
  // The nearest drawn particle edge is at |x| = 0.525 − 0.04: leave a pixel of margin.
  const int halfGap = int(0.485f * ppu) - 1;
  for (int y = 0; y < kSize; ++y)
    for (int x = kSize / 2 - halfGap; x < kSize / 2 + halfGap; ++x)
      ASSERT_TRUE(same(img, x, y, bg)) << "particle pixel inside the blocker at " << x << "," << y;
  int left = 0, right = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      if (!same(img, x, y, bg)) (x < kSize / 2 ? left : right)++;
  EXPECT_GT(left, 300);
  EXPECT_GT(right, 300);
  EXPECT_NEAR(left, right, 0.1 * left);
}

// Particles whose Visible attribute is 0 (a blocker action's verdict) are not drawn.
TEST(RenderImage, VisibleAttributeHides) {
  RenderSettings s;
  s.camera = front(8.0f, 40.0f);
  Context ctx;
  Group& g = particles(ctx, {Attribute::Visible});
  for (int k = 0; k < 40; ++k) {
    const float x = -2.0f + 0.1f * float(k) + 0.05f;
    add(g, Vec3(x, 0.0f, 0.0f), 0.05f, Vec4(1.0f), x > 0.0f);
  }
  OffscreenRenderer r(small(), s);
  const Image img = r.render(g);
  EXPECT_EQ(r.lastDrawn(), 20u);
  const std::uint8_t* bg = img.pixel(0, 0);
  int left = 0, right = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      if (!same(img, x, y, bg)) (x < kSize / 2 ? left : right)++;
  EXPECT_EQ(left, 0);
  EXPECT_GT(right, 200);
}

// Big particles are lit; particles under litMinPixels keep their own color.
TEST(RenderImage, TinyParticlesAreUnshaded) {
  RenderSettings s;
  s.camera = front(8.0f, 40.0f);
  s.background = Vec3(0.0f);
  s.lighting.ambient = Vec3(0.0f);
  s.lighting.lights.clear();  // a lit particle is black
  OffscreenRenderer r(OffscreenOptions{kSize, kSize, 0}, s);
  const float ppu = pixelsPerUnit(s.camera);
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(-1.0f, 0.0f, 0.0f), 0.5f, Vec4(1.0f));       // 22 pixels: lit, so black
  add(g, Vec3(1.0f, 0.0f, 0.0f), 0.8f / ppu, Vec4(1.0f));  // 0.8 pixel: own color
  add(g, Vec3(1.0f, 1.0f, 0.0f), 0.3f / ppu, Vec4(1.0f));  // 0.3 pixel: dimmed by coverage
  const Image img = r.render(g);
  writePng(img, flurry::test::outDir() / "tiny_unshaded.png");
  auto at = [&](Vec3 p) {
    return img.pixel(int(kSize / 2 + p.x * ppu), int(kSize / 2 - p.y * ppu));
  };
  EXPECT_LE(at(Vec3(-1, 0, 0))[0], 2);
  int brightest = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      brightest = std::max<int>(brightest, img.pixel(int(kSize / 2 + ppu) + dx, kSize / 2 + dy)[0]);
  EXPECT_GT(brightest, 120);
  // 0.3 px: coverage π·0.3² = 0.28 of one pixel.
  int sum = 0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx)
      sum += img.pixel(int(kSize / 2 + ppu) + dx, int(kSize / 2 - ppu) + dy)[0];
  EXPECT_NEAR(sum, 0.283 * 255, 6);
}

// Each sprite kind draws its own shape; a PNG sprite is drawn upright.
TEST(RenderImage, Sprites) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.0f);
  OffscreenRenderer r(small(), s);
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(0.0f), 1.0f, Vec4(1.0f));
  // A PNG sprite: red top-left quadrant, green elsewhere.
  Image png;
  png.width = png.height = 32;
  png.rgba.resize(32 * 32 * 4);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      std::uint8_t* p = png.pixel(x, y);
      const bool red = x < 16 && y < 16;
      p[0] = red ? 255 : 0;
      p[1] = red ? 0 : 255;
      p[2] = 0;
      p[3] = 255;
    }
  const auto pngPath = flurry::test::outDir() / "sprite_quadrants.png";
  writePng(png, pngPath);
  s.spriteImage = pngPath.string();

  auto coverage = [&](Sprite kind, const char* name) {
    r.settings().sprite = kind;
    r.settings().spriteImage = pngPath.string();
    const Image img = r.render(g);
    writePng(img, flurry::test::outDir() / (std::string("sprite_") + name + ".png"));
    int n = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) n += img.pixel(x, y)[0] + img.pixel(x, y)[1] > 64;
    return std::pair{n, img};
  };
  const float rpx = pixelsPerUnit(s.camera);
  const double square = 4.0 * rpx * rpx, disc = 3.14159 * rpx * rpx;
  const auto [nDisc, iDisc] = coverage(Sprite::Disc, "disc");
  const auto [nSpark, iSpark] = coverage(Sprite::Spark, "spark");
  const auto [nFlake, iFlake] = coverage(Sprite::Snowflake, "snowflake");
  const auto [nPoint, iPoint] = coverage(Sprite::Point, "point");
  const auto [nImage, iImage] = coverage(Sprite::Image, "image");
  EXPECT_NEAR(nDisc, 0.91 * disc, 0.05 * disc);  // the soft rim fades out past 0.8 r
  EXPECT_LT(nSpark, 0.5 * disc);
  EXPECT_GT(nSpark, 0.02 * disc);
  EXPECT_LT(nFlake, 0.6 * disc);
  EXPECT_GT(nFlake, 0.1 * disc);
  // GL rasterises a wide point as a square, MSAA or not: the shader cuts it round.
  EXPECT_NEAR(nPoint, disc, 0.05 * disc);
  EXPECT_NEAR(nImage, square, 0.05 * square);
  const auto [nGlow, iGlow] = coverage(Sprite::Glow, "glow");
  const auto [nPuff, iPuff] = coverage(Sprite::Puff, "puff");
  EXPECT_LT(nGlow, 0.6 * disc);  // a gaussian: bright core, faint wide halo
  EXPECT_GT(nGlow, 0.2 * disc);
  EXPECT_GT(iGlow.pixel(kSize / 2, kSize / 2)[0], 240);
  EXPECT_LT(nPuff, 0.9 * disc);
  EXPECT_GT(nPuff, 0.3 * disc);
  const int q = int(rpx / 2);
  EXPECT_GT(iImage.pixel(kSize / 2 - q, kSize / 2 - q)[0], 200);  // top left: red
  EXPECT_GT(iImage.pixel(kSize / 2 + q, kSize / 2 - q)[1], 200);  // top right: green
  EXPECT_GT(iImage.pixel(kSize / 2 - q, kSize / 2 + q)[1], 200);  // bottom left: green
  // The snowflake has six arms, one along +x: its hub and that arm's tip are drawn, the
  // point at 30 degrees between two arms is not.
  EXPECT_GT(iFlake.pixel(kSize / 2, kSize / 2)[0], 200);
  EXPECT_GT(iFlake.pixel(int(kSize / 2 + 0.85f * rpx), kSize / 2)[0], 120);
  EXPECT_LT(
      iFlake.pixel(int(kSize / 2 + 0.85f * rpx * 0.866f), int(kSize / 2 - 0.85f * rpx * 0.5f))[0],
      40);

  r.settings().spriteImage = "/nonexistent/sprite.png";
  r.settings().sprite = Sprite::Image;
  EXPECT_THROW(r.render(g), IoError);
}

// Additive blending adds overlapping particles; alpha blending covers.
TEST(RenderImage, BlendModes) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.0f);
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(0.0f, 0.0f, 0.0f), 0.5f, Vec4(0.4f, 0.2f, 0.0f, 1.0f));
  add(g, Vec3(0.0f, 0.0f, 0.1f), 0.5f, Vec4(0.0f, 0.2f, 0.4f, 1.0f));
  OffscreenRenderer r(small(), s);
  r.settings().blend = BlendMode::Additive;
  Image img = r.render(g);
  const std::uint8_t* p = img.pixel(kSize / 2, kSize / 2);
  EXPECT_NEAR(p[0], 102, 2);
  EXPECT_NEAR(p[1], 102, 2);
  EXPECT_NEAR(p[2], 102, 2);
  r.settings().blend = BlendMode::Alpha;  // sorted: the nearer (bluer) one is drawn last
  img = r.render(g);
  p = img.pixel(kSize / 2, kSize / 2);
  EXPECT_NEAR(p[0], 0, 2);
  EXPECT_NEAR(p[1], 51, 2);
  EXPECT_NEAR(p[2], 102, 2);
}

// Velocity-stretched sprites: a fast particle covers a streak along its screen-space velocity,
// trailing behind it, as long as the path of the last `stretch` seconds (clamped to
// maxStretch widths); a particle at rest, and any particle without `stretch`, stays round.
TEST(RenderImage, StretchedSpritesStreakAlongTheVelocity) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.0f);
  s.sprite = Sprite::Glow;
  s.blend = BlendMode::Additive;
  Context ctx;
  Group& g = particles(ctx);
  auto moving = [&](Vec3 velocity) {
    g.clear();
    Particle q;
    q.size = 0.15f;
    q.color = Vec4(1.0f);
    q.velocity = velocity;
    g.add(q);
  };
  moving(Vec3(10.0f, 0.0f, 0.0f));  // +x: screen right
  OffscreenRenderer r(small(), s);
  const float ppu = pixelsPerUnit(s.camera);
  // The lit footprint's extent and centre along x and y.
  struct Footprint {
    int minX = kSize, maxX = -1, minY = kSize, maxY = -1;
    double cx = 0;
  };
  auto footprint = [&](const char* name) {
    const Image img = r.render(g);
    writePng(img, flurry::test::outDir() / (std::string("stretch_") + name + ".png"));
    Footprint f;
    int n = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        if (img.pixel(x, y)[0] > 24) {
          f.minX = std::min(f.minX, x);
          f.maxX = std::max(f.maxX, x);
          f.minY = std::min(f.minY, y);
          f.maxY = std::max(f.maxY, y);
          f.cx += x;
          ++n;
        }
    f.cx = n ? f.cx / n : -1.0;
    return f;
  };
  const Footprint round = footprint("off");
  const int w = round.maxX - round.minX, h = round.maxY - round.minY;
  ASSERT_GT(w, 4);
  EXPECT_NEAR(w, h, 2);         // no stretch: round
  r.settings().stretch = 0.1f;  // 10 units/s x 0.1 s: a streak 1 unit long
  const Footprint streak = footprint("on");
  const int sw = streak.maxX - streak.minX, sh = streak.maxY - streak.minY;
  EXPECT_NEAR(sw - w, ppu, 0.15 * ppu) << sw << " vs " << w;  // longer by the path
  EXPECT_NEAR(sh, h, 2);                                      // no wider
  EXPECT_LT(streak.cx, kSize / 2 - 0.35 * ppu);               // it trails the particle
  EXPECT_GE(streak.maxX, round.maxX - 2);                     // the head stays at the particle
  // Clamped: at most maxStretch widths long (the sprite swept over 2 of its widths more).
  r.settings().maxStretch = 3.0f;
  const Footprint clamped = footprint("clamped");
  EXPECT_NEAR(clamped.maxX - clamped.minX - w, 2.0f * 2.0f * 0.15f * ppu, 3);
  // A vertical velocity streaks vertically; a particle at rest stays round.
  r.settings().maxStretch = 8.0f;
  moving(Vec3(0.0f, -10.0f, 0.0f));
  const Footprint down = footprint("down");
  EXPECT_NEAR(down.maxX - down.minX, w, 2);
  EXPECT_NEAR((down.maxY - down.minY) - h, ppu, 0.15 * ppu);
  moving(Vec3(0.0f));
  const Footprint rest = footprint("rest");
  EXPECT_NEAR(rest.maxX - rest.minX, w, 2);
}

// Per-group looks: one group additive, another alpha-blended, in one frame; an instance
// "NAME@I" takes NAME's look.
TEST(RenderImage, GroupLooksOverrideTheSettings) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.0f);
  s.blend = BlendMode::Alpha;
  GroupLook fire;
  fire.group = "fire";
  fire.blend = BlendMode::Additive;
  s.groups = {fire};
  Context ctx;
  Group& a = ctx.createGroup("fire@2", 16);
  Group& b = ctx.createGroup("smoke", 16);
  for (Group* g : {&a, &b}) g->require(Renderer::attributes());
  const float x = 0.6f;
  add(a, Vec3(-x, 0.0f, 0.0f), 0.5f, Vec4(0.4f, 0.2f, 0.0f, 1.0f));
  add(a, Vec3(-x, 0.0f, 0.1f), 0.5f, Vec4(0.0f, 0.2f, 0.4f, 1.0f));
  add(b, Vec3(x, 0.0f, 0.0f), 0.5f, Vec4(0.4f, 0.2f, 0.0f, 1.0f));
  add(b, Vec3(x, 0.0f, 0.1f), 0.5f, Vec4(0.0f, 0.2f, 0.4f, 1.0f));
  OffscreenRenderer r(small(), s);
  const Group* groups[] = {&a, &b};
  const Image img = r.render(groups);
  writePng(img, flurry::test::outDir() / "group_looks.png");
  const int dx = int(x * pixelsPerUnit(s.camera));
  const std::uint8_t* p = img.pixel(kSize / 2 - dx, kSize / 2);  // fire: added
  EXPECT_NEAR(p[0], 102, 2);
  EXPECT_NEAR(p[1], 102, 2);
  EXPECT_NEAR(p[2], 102, 2);
  p = img.pixel(kSize / 2 + dx, kSize / 2);  // smoke: the nearer one covers
  EXPECT_NEAR(p[0], 0, 2);
  EXPECT_NEAR(p[1], 51, 2);
  EXPECT_NEAR(p[2], 102, 2);
}

// Glow and puff sprites are shaded flat: one normal towards the eye, so a lit puff of smoke is
// not a ball with a bright and a dark side (the disc, shaded as a sphere, is).
TEST(RenderImage, GlowAndPuffAreShadedFlat) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.background = Vec3(0.0f);
  s.lighting.ambient = Vec3(0.1f);
  s.lighting.lights = {Light{Light::Type::Directional, Vec3(1.0f, 0.0f, 0.3f), Vec3(1.0f)}};
  s.lighting.material = Material{Vec3(1.0f), Vec3(0.8f), Vec3(0.0f), 20.0f};
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(0.0f), 1.0f, Vec4(1.0f));
  OffscreenRenderer r(small(), s);
  const int dx = int(0.3f * pixelsPerUnit(s.camera));
  auto sides = [&](Sprite kind) {
    r.settings().sprite = kind;
    const Image img = r.render(g);
    return std::pair{int(img.pixel(kSize / 2 - dx, kSize / 2)[0]),
                     int(img.pixel(kSize / 2 + dx, kSize / 2)[0])};
  };
  const auto [discLeft, discRight] = sides(Sprite::Disc);
  EXPECT_GT(discRight, discLeft + 40);  // the sphere: lit from +x
  for (Sprite kind : {Sprite::Glow, Sprite::Puff}) {
    const auto [left, right] = sides(kind);
    EXPECT_NEAR(left, right, 12) << int(kind);
    EXPECT_GT(left, 20) << int(kind);
  }
}

// The tone map: overlapping additive particles that sum far above 1 keep their hue instead
// of clipping to white; without it they clip.
TEST(RenderImage, ToneMapKeepsAdditiveCoresFromClipping) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.0f);
  s.blend = BlendMode::Additive;
  Context ctx;
  Group& g = particles(ctx);
  for (int i = 0; i < 8; ++i)
    add(g, Vec3(0.0f, 0.0f, 0.01f * float(i)), 0.5f, Vec4(1.0f, 0.5f, 0.2f, 1.0f));
  OffscreenRenderer r(small(), s);
  const std::uint8_t* p = nullptr;
  Image img = r.render(g);
  p = img.pixel(kSize / 2, kSize / 2);
  EXPECT_EQ(p[0], 255);
  EXPECT_EQ(p[1], 255);
  EXPECT_GE(p[2], 254);  // 8 x 0.2 = 1.6: white
  for (ToneMap t : {ToneMap::Aces, ToneMap::Reinhard}) {
    r.settings().toneMap = t;
    img = r.render(g);
    p = img.pixel(kSize / 2, kSize / 2);
    EXPECT_GT(p[0], p[1] + 5) << int(t);  // still orange: red > green > blue
    EXPECT_GT(p[1], p[2] + 5) << int(t);
    EXPECT_LT(p[2], 250) << int(t);
    EXPECT_EQ(img.pixel(2, 2)[0], 0) << int(t);  // black stays black
  }
  // The curves themselves, at the centre: 8 x (1, 0.5, 0.2) = (8, 4, 1.6).
  r.settings().toneMap = ToneMap::Reinhard;
  img = r.render(g);
  p = img.pixel(kSize / 2, kSize / 2);
  EXPECT_NEAR(p[0], 255.0 * 8 / 9, 3);
  EXPECT_NEAR(p[1], 255.0 * 4 / 5, 3);
  EXPECT_NEAR(p[2], 255.0 * 1.6 / 2.6, 3);
}

// A transparent background: alpha 0 where nothing is drawn, the particle's colour (straight,
// not premultiplied) and coverage where it is; with and without a tone map.
TEST(RenderImage, TransparentBackground) {
  RenderSettings s;
  s.camera = front(30.0f, 6.0f);
  s.shading = false;
  s.background = Vec3(0.5f);  // unused when transparent
  s.transparent = true;
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(0.0f), 1.0f, Vec4(0.2f, 0.6f, 1.0f, 0.5f));
  OffscreenRenderer r(small(), s);
  for (ToneMap t : {ToneMap::None, ToneMap::Aces}) {
    r.settings().toneMap = t;
    const Image img = r.render(g);
    const std::uint8_t* corner = img.pixel(2, 2);
    EXPECT_EQ(corner[3], 0) << int(t);
    const std::uint8_t* c = img.pixel(kSize / 2, kSize / 2);
    EXPECT_NEAR(c[3], 128, 3) << int(t);
    EXPECT_GT(c[2], c[1]) << int(t);
    EXPECT_GT(c[1], c[0]) << int(t);
    if (t == ToneMap::None) {
      EXPECT_NEAR(c[0], 51, 3);  // straight: 0.2, not 0.2 x 0.5
      EXPECT_NEAR(c[1], 153, 3);
      EXPECT_NEAR(c[2], 255, 3);
    }
  }
  r.settings().transparent = false;
  r.settings().toneMap = ToneMap::None;
  const Image opaque = r.render(g);
  EXPECT_EQ(opaque.pixel(2, 2)[3], 255);
  EXPECT_NEAR(opaque.pixel(2, 2)[0], 128, 1);
}

// The scene geometry: a group's Bounce, Sink and Block surfaces drawn faintly when asked, an
// `outside` absorber (a bound) not; nothing when not asked.
TEST(RenderImage, SceneGeometry) {
  RenderSettings s;
  s.camera = front(30.0f, 10.0f);
  s.background = Vec3(0.0f);
  Context ctx;
  Group& g = particles(ctx);
  add(g, Vec3(100.0f), 0.01f, Vec4(1.0f));  // out of view: only geometry is drawn
  OffscreenRenderer r(small(), s);
  auto drawn = [&](ActionList actions, int x0, int x1) {
    g.setActions(std::move(actions));
    const Image img = r.render(g);
    int n = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = x0; x < x1; ++x) n += img.pixel(x, y)[2] > 10;
    return n;
  };
  const ActionList scene{
      Bounce{Domain::line(Vec3(-2, -1, 0), Vec3(-0.5f, -1, 0)), 0.5f},    // left
      Sink{Domain::box(Vec3(0.5f, -0.5f, -0.5f), Vec3(2, 0.5f, 0.5f))},   // right
      Sink{Domain::sphere(Vec3(0.0f), 1.0f), 0.0f, Sink::Mode::Outside},  // a bound
      Move{}};
  EXPECT_EQ(drawn(scene, 0, kSize), 0);  // off by default
  r.settings().geometry.show = true;
  EXPECT_GT(drawn(scene, 0, kSize / 2 - 20), 40);            // the deflector's segment
  EXPECT_GT(drawn(scene, kSize / 2 + 20, kSize), 400);       // the absorber's box
  EXPECT_EQ(drawn(scene, kSize / 2 - 8, kSize / 2 + 8), 0);  // no bounding sphere
  r.settings().geometry.sink = false;
  EXPECT_EQ(drawn(scene, kSize / 2 + 20, kSize), 0);
  g.setActions({Block{Domain::box(Vec3(-1.0f), Vec3(1.0f))}, Move{}});
  EXPECT_GT(drawn(g.actions(), kSize / 2 - 8, kSize / 2 + 8), 100);  // a blocker's faces
}

// With no display and no Xvfb there is no OpenGL: a clear RenderError, nothing else breaks.
TEST(RenderHeadless, NoOpenGLGivesAClearError) {
  EnvGuard display("DISPLAY"), path("PATH");
  unsetenv("DISPLAY");
  setenv("PATH", "/nonexistent", 1);
  try {
    OffscreenRenderer r(small());
    FAIL() << "expected RenderError";
  } catch (const RenderError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no usable OpenGL"), std::string::npos) << what;
    EXPECT_NE(what.find("Xvfb"), std::string::npos) << what;
  }
}

// The private X server is started on a free display and is gone after.
TEST(RenderHeadless, XServerStartsAndStops) {
  std::string why;
  auto x = detail::XServer::start(why);
  ASSERT_TRUE(x) << why;
  EXPECT_EQ(x->display()[0], ':');
  const pid_t pid = x->pid();
  EXPECT_EQ(kill(pid, 0), 0);
  x.reset();
  EXPECT_EQ(kill(pid, 0), -1);
  EXPECT_EQ(errno, ESRCH);
}

// The viewer runs a scene in a window; it needs a display and says so when there is none.
TEST(RenderViewer, RunsFramesAndNeedsADisplay) {
  EnvGuard display("DISPLAY");
  unsetenv("DISPLAY");
  auto build = [] {
    ViewerScene scene;
    scene.context = std::make_unique<Context>();
    Group& g = scene.context->createGroup("g", 100);
    Emitter e;
    e.shape = Domain::sphere(Vec3(0.0f), 0.5f);
    e.rate = 600;
    g.addEmitter(e);
    g.setActions({Move{}});
    return scene;
  };
  EXPECT_THROW(runViewer(build, {}, {}), RenderError);

  std::string why;
  auto x = detail::XServer::start(why);
  ASSERT_TRUE(x) << why;
  setenv("DISPLAY", x->display().c_str(), 1);
  int builds = 0;
  ViewerOptions o;
  o.width = 320;
  o.height = 240;
  o.maxFrames = 12;
  o.vsync = false;
  runViewer(
      [&] {
        ++builds;
        return build();
      },
      {}, o);
  EXPECT_EQ(builds, 1);
}
