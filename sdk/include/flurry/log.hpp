// Where the library's messages go. Flurry never prints: what it has to say (e.g. the OpenCL
// profile asked for by FLURRY_OPENCL_PROFILE=1) goes to the callback set here, and nowhere
// when none is set (the default).
#pragma once

#include <functional>
#include <string_view>

namespace flurry {

enum class LogLevel { Debug, Info, Warning, Error };

/// "debug", "info", "warning", "error".
const char* logLevelName(LogLevel level) noexcept;

/// Receives one message (one line, no newline). The view is valid only during the call.
using LogCallback = std::function<void(LogLevel level, std::string_view message)>;

/// Sends the library's messages, from every Context, to `callback`; an empty one (the
/// default) drops them. Process-wide, not per Context: some messages come from what Contexts
/// share (the OpenCL runtime) or from no Context at all. Thread-safe: it may be called at any
/// time, and the callback may be called from any thread, from several at once, so it guards
/// what it shares; a message being sent while the callback is replaced may still reach the old
/// one. An exception the callback throws is dropped. Returns the callback it replaces.
LogCallback setLogCallback(LogCallback callback);

/// A ready-made callback: writes "flurry LEVEL: message" and a newline to stderr, for a
/// program that wants the messages there: setLogCallback(flurry::logToStderr).
void logToStderr(LogLevel level, std::string_view message);

}  // namespace flurry
