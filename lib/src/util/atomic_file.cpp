#include "util/atomic_file.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <system_error>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "util/hash.hpp"

namespace riner {

namespace {

// The temporary files being written, for a signal handler to remove: a fixed table of paths
// and lock-free states, so that the handler reads no memory that is being allocated.
constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;
// kRemoving: a handler took the slot (the process is ending): it is never written again.
enum SlotState : int { kFree = 0, kFilling = 1, kHeld = 2, kRemoving = 3 };
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler reads the states");

struct TempSlot {
  std::atomic<int> state{kFree};
  char path[kPathBytes];
};
TempSlot temp_slots[kSlots];

// The slot that now holds `path`, or -1 when none is free (more writes at once than slots, or
// a path too long): that file is not removed after a signal.
int hold_temp_path(const std::filesystem::path& path) {
  const std::string text = path.string();
  if (text.size() >= kPathBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!temp_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(temp_slots[i].path, text.c_str(), text.size() + 1);
    temp_slots[i].state.store(kHeld);
    return i;
  }
  return -1;
}

void release_temp_path(int slot) {
  if (slot < 0) return;
  int expected = kHeld;  // a handler that took it keeps it
  temp_slots[slot].state.compare_exchange_strong(expected, kFree);
}

}  // namespace

void remove_unfinished_outputs() noexcept {
  for (TempSlot& slot : temp_slots) {
    // Taken, not read while another thread may reuse it (a torn path could name an output).
    int expected = kHeld;
    if (slot.state.compare_exchange_strong(expected, kRemoving)) ::unlink(slot.path);
  }
}

namespace {

// Which processes a PID can name: the host, its boot, and the PID namespace (containers that
// share a host name keep theirs apart).
std::string pid_space() {
  char host[256] = {};
  if (gethostname(host, sizeof(host) - 1) != 0) host[0] = '\0';
  std::string space = host;
  std::ifstream boot("/proc/sys/kernel/random/boot_id");
  std::string boot_id;
  if (std::getline(boot, boot_id)) space += "/" + boot_id;
  struct stat ns {};
  if (::stat("/proc/self/ns/pid", &ns) == 0) space += "/" + std::to_string(ns.st_ino);
  return space;
}

// ".tmp.KEY-", KEY a hash of pid_space(): what every temporary file of this PID space begins with.
const std::string& temporary_prefix() {
  static const std::string prefix = [] {
    char key[17];
    std::snprintf(key, sizeof(key), "%016llx",
                  static_cast<unsigned long long>(util::fnv1a64(pid_space())));
    return ".tmp." + std::string(key) + "-";
  }();
  return prefix;
}

// Whether process `pid` may still write: it exists and is no zombie. A copy of `--processes`
// whose leader was SIGKILLed lingers as a zombie until reaped, and kill(pid, 0) succeeds on
// one: a resume then kept its temporary file for good (a fuzz audit's 2 of 25 kills).
bool may_still_write(long pid) {
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat_file("/proc/" + std::to_string(pid) + "/stat");
  std::string stat_line;
  if (!std::getline(stat_file, stat_line)) return true;  // no /proc: trust kill()
  // "PID (NAME) STATE ...": NAME may hold spaces and parentheses, the last ')' ends it.
  const std::size_t close = stat_line.rfind(')');
  return close == std::string::npos || close + 2 >= stat_line.size() ||
         (stat_line[close + 2] != 'Z' && stat_line[close + 2] != 'X');
}

}  // namespace

std::string temporary_marker(long pid) { return temporary_prefix() + std::to_string(pid) + "."; }

std::size_t remove_stale_temporaries(const std::filesystem::path& folder) {
  const std::string& prefix = temporary_prefix();
  std::size_t removed = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    const std::size_t at = name.find(prefix);
    if (at == std::string::npos) continue;
    const std::size_t digits = at + prefix.size();
    const std::size_t end = name.find('.', digits);
    if (end == std::string::npos || end == digits) continue;
    long pid = 0;
    const auto [stop, failed] = std::from_chars(name.data() + digits, name.data() + end, pid);
    if (failed != std::errc() || stop != name.data() + end || pid <= 0 || pid > INT_MAX) continue;
    // A writer that still runs (or a PID taken again since) keeps its file.
    if (may_still_write(pid)) continue;
    std::error_code ignored;
    removed += std::filesystem::remove(entry.path(), ignored) ? 1 : 0;
  }
  return removed;
}

}  // namespace riner

namespace riner::util {

std::filesystem::path unique_sibling(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  static const unsigned salt = std::random_device{}();
  std::filesystem::path temp = target;
  temp += temporary_marker(::getpid()) + std::to_string(salt) + "." + std::to_string(counter++);
  return temp;
}

AtomicFile::AtomicFile(std::filesystem::path target)
    : target_(std::move(target)), temp_(unique_sibling(target_)), slot_(hold_temp_path(temp_)) {}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(temp_, ignored);
  }
  release_temp_path(slot_);
}

void AtomicFile::commit() {
  std::error_code error;
  std::filesystem::rename(temp_, target_, error);
  if (error) {
    throw Error("cannot move " + temp_.string() + " to " + target_.string() + ": " +
                error.message());
  }
  committed_ = true;
  release_temp_path(slot_);
  slot_ = -1;
}

}  // namespace riner::util
