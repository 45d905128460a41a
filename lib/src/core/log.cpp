#include "riner/log.hpp"

#include <cstdio>
#include <mutex>
#include <string>

namespace riner {

namespace {

std::mutex& handler_mutex() {
  static std::mutex mutex;
  return mutex;
}

WarningHandler& handler() {
  static WarningHandler h = [](std::string_view message) {
    std::fprintf(stderr, "riner: warning: %.*s\n", static_cast<int>(message.size()),
                 message.data());
  };
  return h;
}

}  // namespace

WarningHandler set_warning_handler(WarningHandler new_handler) {
  std::lock_guard<std::mutex> lock(handler_mutex());
  WarningHandler old = std::move(handler());
  handler() = std::move(new_handler);
  return old;
}

void warn(std::string_view message) {
  WarningHandler h;
  {
    std::lock_guard<std::mutex> lock(handler_mutex());
    h = handler();
  }
  if (h) h(message);
}

}  // namespace riner
