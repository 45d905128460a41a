// Where the library's warnings go. riner never writes to stdout; by default warnings go to
// stderr, one line each. Applications and tests may redirect them.
#pragma once

#include <functional>
#include <string_view>

namespace riner {

using WarningHandler = std::function<void(std::string_view message)>;

// Replaces the handler; returns the previous one. Thread-safe.
WarningHandler set_warning_handler(WarningHandler handler);

void warn(std::string_view message);

}  // namespace riner
