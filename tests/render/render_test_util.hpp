// Image checks shared by the render tests: reference comparison with a tolerant metric, and
// small pixel queries.
#pragma once

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "flurry/render.hpp"

namespace flurry::test {

// Mesa's DRI driver is dlclose()d when GLFW closes its display; what it keeps in globals
// then looks to LeakSanitizer like leaks from an unknown module (112 bytes a context), which
// no suppression can name. Kept loaded, its globals stay visible and nothing is reported.
class KeepDriverLoaded : public ::testing::Environment {
 public:
  void SetUp() override {
#ifdef FLURRY_TEST_DRI_DRIVER
    dlopen(FLURRY_TEST_DRI_DRIVER, RTLD_NOW | RTLD_NODELETE);
#endif
  }
};
// Registered once per test program that includes this header.
inline const auto* const kKeepDriver = ::testing::AddGlobalTestEnvironment(new KeepDriverLoaded);

inline std::filesystem::path outDir() {
  std::filesystem::path d = FLURRY_RENDER_OUT_DIR;
  std::filesystem::create_directories(d);
  return d;
}

/// Whether pixel (x, y) has exactly the color `bg`.
inline bool same(const Image& img, int x, int y, const std::uint8_t* bg) {
  const std::uint8_t* p = img.pixel(x, y);
  return p[0] == bg[0] && p[1] == bg[1] && p[2] == bg[2];
}

/// `img` shrunk by `factor` in each direction, each pixel the mean of its factor x factor block
/// (a block cut by the right or bottom edge averages the pixels it has).
inline Image downsample(const Image& img, int factor) {
  if (factor <= 1) return img;
  Image out;
  out.width = (img.width + factor - 1) / factor;
  out.height = (img.height + factor - 1) / factor;
  out.rgba.resize(std::size_t(out.width) * out.height * 4);
  for (int by = 0; by < out.height; ++by)
    for (int bx = 0; bx < out.width; ++bx) {
      int sum[4] = {}, n = 0;
      for (int y = by * factor; y < std::min(img.height, (by + 1) * factor); ++y)
        for (int x = bx * factor; x < std::min(img.width, (bx + 1) * factor); ++x, ++n)
          for (int c = 0; c < 4; ++c) sum[c] += img.pixel(x, y)[c];
      for (int c = 0; c < 4; ++c) out.pixel(bx, by)[c] = std::uint8_t((sum[c] + n / 2) / n);
    }
  return out;
}

/// How far an image may be from its reference. The defaults are the synthetic scenes'
/// (test_render_images.cpp): pixel for pixel, where a driver update moves edges by a pixel or
/// rounds differently and a broken shader changes far more.
struct Tolerance {
  int blur = 1;                // compare the means of blur x blur blocks (downsample()), not pixels
  int levels = 24;             // a (block) pixel is off when a channel differs by more than this
  double offFraction = 0.005;  // at most this fraction of the (block) pixels off
  double meanLevels = 1.0;     // the mean absolute difference of each channel stays under this
};

/// Compares with tests/render/ref/<name>.png (name may hold a folder: "samples/fountain"):
/// both are shrunk by `tol.blur` (downsample()), then at most `tol.offFraction` of the pixels
/// may differ by more than `tol.levels` in a channel, and each channel's mean absolute
/// difference must stay under `tol.meanLevels`. FLURRY_UPDATE_REFS=1 writes the reference
/// instead. The image is always saved next to the test binary's output (out/<name>.png) to
/// look at, and out/<name>.diff.png (the worst channel's difference x 8, per block) when it
/// fails.
inline void compareWithReference(const Image& img, const std::string& name,
                                 const Tolerance& tol = {}) {
  const std::filesystem::path out = outDir() / (name + ".png");
  std::filesystem::create_directories(out.parent_path());
  writePng(img, out);
  const std::filesystem::path ref = std::filesystem::path(FLURRY_RENDER_REF_DIR) / (name + ".png");
  if (const char* u = std::getenv("FLURRY_UPDATE_REFS"); u && *u && *u != '0') {
    std::filesystem::create_directories(ref.parent_path());
    writePng(img, ref);
    std::printf("wrote reference %s\n", ref.c_str());
    return;
  }
  ASSERT_TRUE(std::filesystem::exists(ref))
      << ref << " is missing; render it with FLURRY_UPDATE_REFS=1 and check it by eye";
  const Image full = readPng(ref);
  ASSERT_EQ(full.width, img.width);
  ASSERT_EQ(full.height, img.height);
  const Image a = downsample(img, tol.blur), r = downsample(full, tol.blur);
  std::size_t bad = 0;
  double sum[3] = {};
  Image diff = img;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(int(a.pixel(x, y)[c]) - int(r.pixel(x, y)[c]));
        worst = std::max(worst, d);
        sum[c] += d;
      }
      if (worst > tol.levels) ++bad;
      for (int py = y * tol.blur; py < std::min(img.height, (y + 1) * tol.blur); ++py)
        for (int px = x * tol.blur; px < std::min(img.width, (x + 1) * tol.blur); ++px) {
          std::uint8_t* q = diff.pixel(px, py);
          q[0] = q[1] = q[2] = std::uint8_t(std::min(255, worst * 8));
          q[3] = 255;
        }
    }
  const double total = double(a.width) * a.height;
  const double mean = std::max({sum[0], sum[1], sum[2]}) / total;
  std::printf("%s: %zu of %.0f %s off by > %d, mean difference (r, g, b) %.3f %.3f %.3f\n",
              name.c_str(), bad, total, tol.blur > 1 ? "blocks" : "pixels", tol.levels,
              sum[0] / total, sum[1] / total, sum[2] / total);
  if (bad > tol.offFraction * total || mean >= tol.meanLevels)
    writePng(diff, outDir() / (name + ".diff.png"));
  EXPECT_LE(double(bad), tol.offFraction * total)
      << name << ": " << bad << " of " << total << (tol.blur > 1 ? " blocks" : " pixels")
      << " differ by > " << tol.levels;
  EXPECT_LT(mean, tol.meanLevels) << name << ": mean difference " << mean << " in a channel";
}

}  // namespace flurry::test
