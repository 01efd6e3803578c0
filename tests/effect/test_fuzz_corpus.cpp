// Runs every file of the fuzzing corpus and of the fuzzer's findings through the loader, as
// the fuzz target does: each must load or be refused with an EffectError, never crash, hang
// or throw anything else. Regressions of whatever the fuzzer found live in tests/fuzz/crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "step_checks.hpp"

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

// What loads is built with small groups and stepped: whatever the file asks for (extreme
// rates, speeds, step lengths, nested prime emitters), a step may refuse it with an Error
// but never crashes or leaves a particle that is not finite, past its group's capacity, or
// outside the box its group reports.
bool stepIfItLoads(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  flurry::Effect fx;
  try {
    fx = flurry::parseEffect(ss.str(), file.filename().string());
  } catch (const flurry::EffectError&) {
    return false;  // (the test above checks the refusal)
  }
  flurry::ContextOptions o = fx.contextOptions();
  o.threads = 2;
  flurry::Context ctx(o);
  std::vector<flurry::Group*> groups;
  try {
    groups = fx.build(ctx, 64);
  } catch (const flurry::Error&) {
    return false;  // refused by the core, named (the effect tests check the messages)
  }
  for (flurry::Group* g : groups) (void)g->bounds();  // kept by the passes from now on
  for (int step = 0; step < 20; ++step) {
    try {
      ctx.step();
    } catch (const flurry::Error&) {
      return true;
    }
    if (!flurry::test::stepLeftGroupsSound(groups, step)) return true;
  }
  return true;
}

}  // namespace

TEST(FuzzCorpus, EveryFileThatLoadsSteps) {
  std::size_t stepped = 0;
  for (const fs::path& f : filesUnder(fs::path(FLURRY_FUZZ_DIR) / "corpus")) {
    SCOPED_TRACE(f.string());
    stepped += stepIfItLoads(f) ? 1 : 0;
  }
  EXPECT_GT(stepped, 10u);  // (most of the corpus is refused)
}

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
