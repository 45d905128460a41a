// A folder or a wildcard pattern of 2D images read as one stack [files, rows, cols].
#include "io/stack.hpp"

#include <fnmatch.h>
#include <algorithm>
#include <cctype>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/row_blocks.hpp"
#include "riner/error.hpp"
#include "riner/volume_writer.hpp"

namespace riner::io {

namespace {

bool has_wildcard(const std::string& name) {
  return name.find_first_of("*?[") != std::string::npos;
}

bool is_image_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".tif" || ext == ".tiff";
}

}  // namespace

bool is_stack_path(const std::filesystem::path& path) {
  return has_wildcard(path.filename().string()) || std::filesystem::is_directory(path);
}

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < a.size() && j < b.size()) {
    const bool digit_a = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool digit_b = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (digit_a && digit_b) {
      // Compare the digit runs as numbers: skip leading zeros, then longer is larger.
      std::size_t end_a = i;
      std::size_t end_b = j;
      while (end_a < a.size() && std::isdigit(static_cast<unsigned char>(a[end_a]))) ++end_a;
      while (end_b < b.size() && std::isdigit(static_cast<unsigned char>(b[end_b]))) ++end_b;
      std::size_t start_a = i;
      std::size_t start_b = j;
      while (start_a + 1 < end_a && a[start_a] == '0') ++start_a;
      while (start_b + 1 < end_b && b[start_b] == '0') ++start_b;
      const std::string_view run_a(a.data() + start_a, end_a - start_a);
      const std::string_view run_b(b.data() + start_b, end_b - start_b);
      if (run_a.size() != run_b.size()) return run_a.size() < run_b.size();
      if (run_a != run_b) return run_a < run_b;
      i = end_a;
      j = end_b;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  if ((a.size() - i) != (b.size() - j)) return (a.size() - i) < (b.size() - j);
  return a < b;  // equal up to leading zeros: any fixed order
}

std::vector<std::filesystem::path> stack_files(const std::filesystem::path& path) {
  const bool folder = std::filesystem::is_directory(path);
  const std::filesystem::path dir =
      folder ? path : (path.has_parent_path() ? path.parent_path() : std::filesystem::path("."));
  const std::string pattern = folder ? "" : path.filename().string();
  if (!std::filesystem::is_directory(dir)) {
    throw InputError(prefix(path) + "no such folder '" + dir.string() + "'");
  }
  if (folder && std::filesystem::exists(dir / VolumeWriter::kUnfinishedMarker)) {
    throw InputError(prefix(path) + "an unfinished volume (" + VolumeWriter::kUnfinishedMarker +
                     ": riner was stopped before its last slice); run that command again");
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    // macOS's AppleDouble files ("._proj_0.tif") beside each image copied from a Mac.
    if (name.rfind("._", 0) == 0) continue;
    const bool wanted = folder ? is_image_file(entry.path())
                               : fnmatch(pattern.c_str(), name.c_str(), FNM_PERIOD) == 0;
    if (wanted) files.push_back(entry.path());
  }
  if (files.empty()) {
    throw InputError(
        prefix(path) +
        (folder ? "is a folder without .tif/.tiff files (a folder reads as a stack of TIFFs)"
                : "no file matches the pattern"));
  }
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return files;
}

namespace {

// Each file, read by `read_one`, must be 2D, shaped like the first and of its sample type.
template <typename ReadOne>
ArrayFile stack_of(const std::vector<std::filesystem::path>& files, ReadOne&& read_one) {
  ArrayFile stack;
  std::vector<std::size_t> frame_shape;
  for (const std::filesystem::path& file : files) {
    ArrayFile frame = read_one(file);
    if (frame.array.rank() != 2) {
      throw InputError(prefix(file) + "is " + shape_string(frame.array.shape) +
                       "; a stack is made of 2D images");
    }
    if (frame_shape.empty()) {
      frame_shape = frame.array.shape;
      stack.format = frame.format;
      stack.dtype = frame.dtype;
      stack.array.data.reserve(files.size() * frame.array.size());
    } else if (frame.array.shape != frame_shape) {
      throw InputError(prefix(file) + "is " + shape_string(frame.array.shape) + " where " +
                       files.front().filename().string() + " is " + shape_string(frame_shape));
    } else if (frame.dtype != stack.dtype) {
      // Line integrals beside raw counts (float32 and uint16 frames) merged into one scan
      // without a word.
      throw InputError(prefix(file) + "holds " + frame.dtype + " samples where " +
                       files.front().filename().string() + " holds " + stack.dtype +
                       ": a stack's frames are of one kind");
    }
    stack.non_finite += frame.non_finite;
    stack.array.data.insert(stack.array.data.end(), frame.array.data.begin(),
                            frame.array.data.end());
  }
  stack.array.shape = {files.size(), frame_shape[0], frame_shape[1]};
  return stack;
}

}  // namespace

ArrayFile read_stack(const std::filesystem::path& path,
                     ArrayFile (*read_one)(const std::filesystem::path&)) {
  return stack_of(stack_files(path), read_one);
}

ArrayFile read_stack_rows(const std::filesystem::path& path, RowRange rows) {
  const std::vector<std::filesystem::path> files = stack_files(path);
  return stack_of(files, [&](const std::filesystem::path& file) {
    const std::string ext = lower_extension(file);
    if (ext == ".tif" || ext == ".tiff") {
      ArrayFile frame = read_tiff_rows(file, rows);
      if (frame.array.rank() != 2) {
        throw InputError(prefix(file) + "has several pages; a stack is made of 2D images");
      }
      return frame;
    }
    // Another format named by a pattern: read the image whole and keep the rows.
    ArrayFile frame = read_array(file);
    if (frame.array.rank() != 2) return frame;  // stack_of names the mistake
    frame.array.shape.insert(frame.array.shape.begin(), 1);
    frame = cut_rows(std::move(frame), file, rows);
    frame.array.shape.erase(frame.array.shape.begin());
    return frame;
  });
}

std::vector<std::size_t> stack_shape(const std::filesystem::path& path) {
  const std::vector<std::filesystem::path> files = stack_files(path);
  const std::string ext = lower_extension(files.front());
  const std::vector<std::size_t> first = (ext == ".tif" || ext == ".tiff")
                                             ? tiff_shape(files.front())
                                             : read_array(files.front()).array.shape;
  if (first.size() != 2) {
    throw InputError(prefix(files.front()) + "is " + shape_string(first) +
                     "; a stack is made of 2D images");
  }
  return {files.size(), first[0], first[1]};
}

}  // namespace riner::io
