// Runs every file of the fuzzing corpus and of the fuzzer's findings through the loader, as
// the fuzz target does: each must load or be refused with an EffectError, never crash, hang
// or throw anything else. Regressions of whatever the fuzzer found live in tests/fuzz/crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "flurry/effect.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> filesUnder(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.' &&
        e.path().extension() != ".md")
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

void runThroughLoader(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  try {
    const flurry::Effect fx = flurry::parseEffect(text, file.filename().string());
    EXPECT_FALSE(fx.groups.empty());
  } catch (const flurry::EffectError& e) {
    EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos);
  }
}

}  // namespace

TEST(FuzzCorpus, EveryFileLoadsOrIsRefused) {
  const auto files = filesUnder(fs::path(FLURRY_FUZZ_DIR) / "corpus");
  EXPECT_GT(files.size(), 10u);
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    runThroughLoader(f);
  }
}

TEST(FuzzCorpus, EveryCrashFoundIsFixed) {
  for (const fs::path& f : filesUnder(fs::path(FLURRY_FUZZ_DIR) / "crashes")) {
    SCOPED_TRACE(f.string());
    runThroughLoader(f);
  }
}
