// Image checks shared by the render tests: reference comparison with a tolerant metric, and
// small pixel queries.
#pragma once

#include <dlfcn.h>
#include <gtest/gtest.h>

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

/// Compares with tests/render/ref/<name>.png: at most 0.5 % of the pixels may differ by more
/// than 24 levels in a channel, and the mean difference must stay under 1 level. A driver
/// update moves edges by a pixel or rounds differently; a broken shader changes far more.
/// FLURRY_UPDATE_REFS=1 writes the reference instead. The image is always saved next to
/// the test binary's output (out/<name>.png) to look at.
inline void compareWithReference(const Image& img, const std::string& name) {
  writePng(img, outDir() / (name + ".png"));
  const std::filesystem::path ref = std::filesystem::path(FLURRY_RENDER_REF_DIR) / (name + ".png");
  if (const char* u = std::getenv("FLURRY_UPDATE_REFS"); u && *u && *u != '0') {
    writePng(img, ref);
    std::printf("wrote reference %s\n", ref.c_str());
    return;
  }
  ASSERT_TRUE(std::filesystem::exists(ref))
      << ref << " is missing; render it with FLURRY_UPDATE_REFS=1 and check it by eye";
  const Image r = readPng(ref);
  ASSERT_EQ(r.width, img.width);
  ASSERT_EQ(r.height, img.height);
  std::size_t bad = 0;
  double sum = 0;
  Image diff = img;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(int(img.pixel(x, y)[c]) - int(r.pixel(x, y)[c]));
        worst = std::max(worst, d);
        sum += d;
      }
      if (worst > 24) ++bad;
      std::uint8_t* q = diff.pixel(x, y);
      q[0] = q[1] = q[2] = std::uint8_t(std::min(255, worst * 8));
      q[3] = 255;
    }
  const double total = double(img.width) * img.height;
  const double mean = sum / (3.0 * total);
  if (bad > 0.005 * total || mean >= 1.0) writePng(diff, outDir() / (name + ".diff.png"));
  EXPECT_LE(double(bad), 0.005 * total) << name << ": " << bad << " pixels differ by > 24";
  EXPECT_LT(mean, 1.0) << name << ": mean difference " << mean;
}

}  // namespace flurry::test
