// The log callback: the library reports through it and never prints by itself.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "flurry/flurry.hpp"
#include "log.hpp"

using namespace flurry;

namespace {

/// Restores the callback a test replaced (tests share the process-wide one).
struct KeepCallback {
  LogCallback saved = setLogCallback({});
  ~KeepCallback() { setLogCallback(saved); }
};

}  // namespace

TEST(Log, SilentByDefault) {
  KeepCallback keep;
  EXPECT_FALSE(detail::logging());
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  detail::log(LogLevel::Error, "not shown");
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(Log, TheCallbackReceivesLevelAndMessage) {
  KeepCallback keep;
  std::vector<std::pair<LogLevel, std::string>> got;
  EXPECT_FALSE(
      setLogCallback([&](LogLevel l, std::string_view m) { got.emplace_back(l, std::string(m)); }));
  EXPECT_TRUE(detail::logging());
  detail::log(LogLevel::Warning, "first");
  detail::log(LogLevel::Debug, "second");
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], std::make_pair(LogLevel::Warning, std::string("first")));
  EXPECT_EQ(got[1], std::make_pair(LogLevel::Debug, std::string("second")));
  // Replacing returns the one replaced; an empty callback silences again.
  EXPECT_TRUE(setLogCallback({}));
  detail::log(LogLevel::Error, "dropped");
  EXPECT_EQ(got.size(), 2u);
}

TEST(Log, AThrowingCallbackDoesNotEscape) {
  KeepCallback keep;
  setLogCallback([](LogLevel, std::string_view) { throw std::runtime_error("no"); });
  EXPECT_NO_THROW(detail::log(LogLevel::Info, "x"));
}

TEST(Log, LogToStderrWritesOneLineWhenAsked) {
  KeepCallback keep;
  setLogCallback(logToStderr);
  testing::internal::CaptureStderr();
  detail::log(LogLevel::Warning, "disk full");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "flurry warning: disk full\n");
}

// Threads log while another replaces the callback: every message reaches one of them.
TEST(Log, ThreadSafe) {
  KeepCallback keep;
  std::atomic<int> a{0}, b{0};
  const LogCallback countA = [&](LogLevel, std::string_view) { a.fetch_add(1); };
  const LogCallback countB = [&](LogLevel, std::string_view) { b.fetch_add(1); };
  setLogCallback(countA);
  constexpr int kThreads = 4, kEach = 2000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([] {
      for (int i = 0; i < kEach; ++i) detail::log(LogLevel::Info, "m");
    });
  for (int i = 0; i < 200; ++i) setLogCallback(i % 2 ? countA : countB);
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(a.load() + b.load(), kThreads * kEach);
}

// Backend::Auto taking the CPU says why through the log (as well as backendFallback()).
TEST(Log, AutoBackendFallbackIsLogged) {
  KeepCallback keep;
  std::vector<std::string> got;
  setLogCallback([&](LogLevel l, std::string_view m) {
    if (l == LogLevel::Info) got.emplace_back(m);
  });
  ContextOptions o;
  o.threads = 1;
  o.backend = Backend::Auto;
  o.device = "no-such-device-anywhere";
  Context ctx(o);
  if (ctx.backendFallback().empty()) {  // a build without OpenCL has nothing to say
    EXPECT_TRUE(got.empty());
    return;
  }
  ASSERT_EQ(got.size(), 1u);
  EXPECT_NE(got[0].find("running on the CPU"), std::string::npos) << got[0];
  EXPECT_NE(got[0].find(ctx.backendFallback()), std::string::npos) << got[0];
}
