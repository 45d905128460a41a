#include "riner/folder_lock.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "riner/error.hpp"

namespace riner {

namespace {

// An open file description's lock (Linux 3.15+): held by this open file, not by the process, so
// closing another descriptor of the same file elsewhere in the process does not drop it, and a
// second lock in this process conflicts like another process's.
bool lock_whole_file(int fd, int& error) {
  struct flock lock {};
  lock.l_type = F_WRLCK;
  lock.l_whence = SEEK_SET;
  lock.l_start = 0;
  lock.l_len = 0;
#ifdef F_OFD_SETLK
  const int done = ::fcntl(fd, F_OFD_SETLK, &lock);
#else
  const int done = ::fcntl(fd, F_SETLK, &lock);
#endif
  error = done == 0 ? 0 : errno;
  return done == 0;
}

std::string holder_of(int fd) {
  char text[300] = {};
  const ssize_t n = ::pread(fd, text, sizeof(text) - 1, 0);
  std::string holder = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : std::string();
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
  return holder;
}

}  // namespace

std::filesystem::path FolderLock::file_in(const std::filesystem::path& folder) {
  return folder / ".riner-run.lock";
}

FolderLock::FolderLock(const std::filesystem::path& folder) {
  const std::filesystem::path path = file_in(folder);
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw InputError(folder.string() + ": cannot open " + path.filename().string() +
                     " to guard the folder (" + std::strerror(errno) + ")");
  }
  int error = 0;
  if (!lock_whole_file(fd, error)) {
    if (error == EACCES || error == EAGAIN) {
      const std::string holder = holder_of(fd);
      ::close(fd);
      throw InputError(folder.string() + ": another riner run" +
                       (holder.empty() ? std::string() : " (" + holder + ")") +
                       " is writing into this folder: wait for it to end, or choose another "
                       "output folder");
    }
    ::close(fd);  // a file system without locks (ENOLCK, EINVAL): written unguarded
    return;
  }
  char host[256] = {};
  if (::gethostname(host, sizeof(host) - 1) != 0) host[0] = '\0';
  const std::string holder = std::string(host) + ":" + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) == 0) {
    (void)!::pwrite(fd, holder.data(), holder.size(), 0);
  }
  fd_ = fd;
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // the lock goes with the file's last descriptor
}

FolderLock::FolderLock(FolderLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }

FolderLock& FolderLock::operator=(FolderLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

}  // namespace riner
