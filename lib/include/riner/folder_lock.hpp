// The one run writing into an output folder. A second run started on the same folder while the
// first lives (the same command typed twice, a job queued again, --resume while the first still
// trains) would train every slab again beside it and overwrite its outputs as they land; it is
// refused instead. The lock goes with its process however the process ends (SIGKILL, out of
// memory), so a killed run's --resume is never blocked by it. A folder whose file system takes
// no locks is written unguarded, as before.
#pragma once

#include <filesystem>
#include <string>

namespace riner {

class FolderLock {
 public:
  FolderLock() = default;
  // InputError "FOLDER: another riner run (HOST:PID) is writing into this folder ..." when a
  // live process holds it.
  explicit FolderLock(const std::filesystem::path& folder);
  ~FolderLock();
  FolderLock(FolderLock&& other) noexcept;
  FolderLock& operator=(FolderLock&& other) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  bool held() const { return fd_ >= 0; }
  // The file that carries it (kept after the run: removing it would let a third run lock a
  // file the second still waits on).
  static std::filesystem::path file_in(const std::filesystem::path& folder);

 private:
  int fd_ = -1;
};

}  // namespace riner
