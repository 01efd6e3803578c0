#include "log.hpp"

#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <utility>

namespace flurry {
namespace {

// The callback is shared so that a message in flight keeps the one it found alive while
// another thread replaces it, and called outside the lock so that it may log or replace
// itself.
std::mutex g_mutex;
std::shared_ptr<const LogCallback> g_callback;  // null: silent
std::atomic<bool> g_set{false};

}  // namespace

const char* logLevelName(LogLevel level) noexcept {
  switch (level) {
    case LogLevel::Debug:
      return "debug";
    case LogLevel::Info:
      return "info";
    case LogLevel::Warning:
      return "warning";
    case LogLevel::Error:
      return "error";
  }
  return "unknown";
}

LogCallback setLogCallback(LogCallback callback) {
  auto next = callback ? std::make_shared<const LogCallback>(std::move(callback)) : nullptr;
  std::shared_ptr<const LogCallback> previous;
  {
    std::lock_guard lock(g_mutex);
    previous = std::exchange(g_callback, std::move(next));
    g_set.store(g_callback != nullptr, std::memory_order_release);
  }
  return previous ? *previous : LogCallback();
}

void logToStderr(LogLevel level, std::string_view message) {
  std::fprintf(stderr, "flurry %s: %.*s\n", logLevelName(level), int(message.size()),
               message.data());
}

namespace detail {

bool logging() noexcept {
  return g_set.load(std::memory_order_acquire);
}

void log(LogLevel level, std::string_view message) noexcept {
  if (!logging()) return;
  std::shared_ptr<const LogCallback> callback;
  {
    std::lock_guard lock(g_mutex);
    callback = g_callback;
  }
  if (!callback) return;
  try {
    (*callback)(level, message);
  } catch (...) {  // a reporting callback must not break the library (this runs in destructors)
  }
}

}  // namespace detail
}  // namespace flurry
