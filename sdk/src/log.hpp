// The library's side of flurry/log.hpp: what it calls to report.
#pragma once

#include <string_view>

#include "flurry/log.hpp"

namespace flurry::detail {

/// Whether a callback is set: a message costly to compose is composed only then.
bool logging() noexcept;
/// Sends `message` to the callback set with setLogCallback, if any; never throws.
void log(LogLevel level, std::string_view message) noexcept;

}  // namespace flurry::detail
