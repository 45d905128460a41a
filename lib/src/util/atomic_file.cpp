#include "util/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <random>
#include <string>
#include <system_error>

#include "riner/error.hpp"

namespace riner::util {

std::filesystem::path unique_sibling(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  static const unsigned salt = std::random_device{}();
  std::filesystem::path temp = target;
  temp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(salt) + "." +
          std::to_string(counter++);
  return temp;
}

AtomicFile::AtomicFile(std::filesystem::path target)
    : target_(std::move(target)), temp_(unique_sibling(target_)) {}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(temp_, ignored);
  }
}

void AtomicFile::commit() {
  std::error_code error;
  std::filesystem::rename(temp_, target_, error);
  if (error) {
    throw Error("cannot move " + temp_.string() + " to " + target_.string() + ": " +
                error.message());
  }
  committed_ = true;
}

}  // namespace riner::util
