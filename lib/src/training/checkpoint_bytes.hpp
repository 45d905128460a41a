// The bytes of a training checkpoint (Reconstructor::save_checkpoint): plain values and arrays
// in this machine's byte order, read back with a bound check on every read.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "riner/error.hpp"

namespace riner::detail {

class ByteWriter {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.append(p, sizeof(T));
  }
  // The count, then the values.
  template <typename T>
  void put_array(std::span<const T> values) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<std::uint64_t>(values.size());
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size_bytes());
  }
  void put_string(const std::string& text) {
    put_array(std::span<const char>(text.data(), text.size()));
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Reads what a ByteWriter wrote; InputError "<what>: truncated" past the end.
class ByteReader {
 public:
  ByteReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  template <typename T>
  std::vector<T> get_array() {
    const auto count = get<std::uint64_t>();
    if (count > (bytes_.size() - at_) / sizeof(T)) throw truncated();
    std::vector<T> values(static_cast<std::size_t>(count));
    std::memcpy(values.data(), take(values.size() * sizeof(T)), values.size() * sizeof(T));
    return values;
  }
  std::string get_string() {
    const std::vector<char> chars = get_array<char>();
    return {chars.begin(), chars.end()};
  }
  bool at_end() const { return at_ == bytes_.size(); }

 private:
  const char* take(std::size_t n) {
    if (n > bytes_.size() - at_) throw truncated();
    const char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }
  InputError truncated() const { return InputError(what_ + ": truncated or corrupt"); }

  std::string_view bytes_;
  std::string what_;
  std::size_t at_ = 0;
};

}  // namespace riner::detail
