// Typed device memory sized in elements, with explicit blocking transfers. A buffer of 0
// elements is valid and every transfer on it is a no-op (OpenCL forbids 0-byte buffers).
#pragma once

#include <CL/cl.h>

#include <atomic>
#include <cstddef>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "cl/context.hpp"
#include "cl/handle.hpp"

namespace riner::cl {

// Buffers alive in this process, for leak checks in stress tests, and the most bytes they held
// at once (device memory the process asked for: summary.json's memory report).
long live_buffer_count();
std::size_t peak_buffer_bytes();
void note_buffer_created(std::size_t bytes);
void note_buffer_released(std::size_t bytes);

template <typename T>
class Buffer {
  static_assert(std::is_trivially_copyable_v<T>, "device buffers hold plain data");

 public:
  Buffer() = default;
  Buffer(Context& context, std::size_t count, cl_mem_flags flags = CL_MEM_READ_WRITE)
      : context_(&context), count_(count) {
    if (count == 0) return;
    cl_int status = CL_SUCCESS;
    cl_mem mem = clCreateBuffer(context.get(), flags, count * sizeof(T), nullptr, &status);
    check(status, "clCreateBuffer", RINER_HERE);
    mem_ = Handle<cl_mem>(mem);
    note_buffer_created(count * sizeof(T));
  }
  Buffer(Context& context, std::span<const T> host, cl_mem_flags flags = CL_MEM_READ_WRITE)
      : Buffer(context, host.size(), flags) {
    write(host);
  }
  Buffer(Buffer&& other) noexcept = default;
  Buffer& operator=(Buffer&& other) noexcept {
    if (this != &other) {
      release();
      context_ = other.context_;
      mem_ = std::move(other.mem_);
      count_ = std::exchange(other.count_, 0);
    }
    return *this;
  }
  ~Buffer() { release(); }

  std::size_t size() const { return count_; }
  std::size_t bytes() const { return count_ * sizeof(T); }
  cl_mem get() const { return mem_.get(); }

  void write(std::span<const T> host, std::size_t offset = 0) {
    check_range(host.size(), offset, "write");
    if (host.empty()) return;
    RINER_CL_CALL(clEnqueueWriteBuffer, context_->queue(), mem_.get(), CL_TRUE, offset * sizeof(T),
                  host.size_bytes(), host.data(), 0, nullptr, nullptr);
  }
  // Non-blocking: `host` must stay unchanged until *done completes (cl/upload_ring.hpp).
  void write_async(std::span<const T> host, cl_event* done) {
    check_range(host.size(), 0, "write");
    if (host.empty()) return;
    RINER_CL_CALL(clEnqueueWriteBuffer, context_->queue(), mem_.get(), CL_FALSE, 0,
                  host.size_bytes(), host.data(), 0, nullptr, done);
  }
  void read(std::span<T> host, std::size_t offset = 0) const {
    check_range(host.size(), offset, "read");
    if (host.empty()) return;
    RINER_CL_CALL(clEnqueueReadBuffer, context_->queue(), mem_.get(), CL_TRUE, offset * sizeof(T),
                  host.size_bytes(), host.data(), 0, nullptr, nullptr);
  }
  std::vector<T> read() const {
    std::vector<T> host(count_);
    read(std::span<T>(host));
    return host;
  }
  // Device-side copy of count elements (all by default) into dst at dst_offset; asynchronous.
  void copy_to(Buffer<T>& dst, std::size_t dst_offset,
               std::size_t count = static_cast<std::size_t>(-1)) const {
    if (count == static_cast<std::size_t>(-1)) count = count_;
    if (count > count_ || dst_offset > dst.size() || count > dst.size() - dst_offset) {
      throw Error("buffer copy of " + std::to_string(count) + " elements does not fit");
    }
    if (count == 0) return;
    RINER_CL_CALL(clEnqueueCopyBuffer, context_->queue(), mem_.get(), dst.get(), 0,
                  dst_offset * sizeof(T), count * sizeof(T), 0, nullptr, nullptr);
  }
  void fill(const T& value) {
    if (count_ == 0) return;
    RINER_CL_CALL(clEnqueueFillBuffer, context_->queue(), mem_.get(), &value, sizeof(T), 0, bytes(),
                  0, nullptr, nullptr);
  }

 private:
  void check_range(std::size_t n, std::size_t offset, const char* what) const {
    if (offset > count_ || n > count_ - offset) {
      throw Error(std::string("buffer ") + what + " of " + std::to_string(n) + " elements at " +
                  std::to_string(offset) + " exceeds its size " + std::to_string(count_));
    }
  }
  void release() noexcept {
    if (mem_) {
      mem_.reset();
      note_buffer_released(count_ * sizeof(T));
    }
  }

  Context* context_ = nullptr;
  Handle<cl_mem> mem_;
  std::size_t count_ = 0;
};

}  // namespace riner::cl
