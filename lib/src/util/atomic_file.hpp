// Writing a file so that readers see either the old file or the complete new one, never a
// partial one: write to a unique temporary file beside the target, then rename over it.
#pragma once

#include <filesystem>

namespace riner::util {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  // Where to write the content.
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }

  // Renames the temporary file onto the target; throws Error on failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
  int slot_ = -1;  // where riner::remove_unfinished_outputs finds temp_
};

// A name unique to this process and call, for temporary files.
std::filesystem::path unique_sibling(const std::filesystem::path& target);

}  // namespace riner::util
