// A built OpenCL program and the kernels made from it.
#pragma once

#include <CL/cl.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

#include "cl/buffer.hpp"
#include "cl/handle.hpp"

namespace riner::cl {

class Program {
 public:
  Program(Handle<cl_program> program, std::string name)
      : program_(std::move(program)), name_(std::move(name)) {}
  cl_program get() const { return program_.get(); }
  const std::string& name() const { return name_; }

 private:
  Handle<cl_program> program_;
  std::string name_;
};

// Argument marker for __local memory of a given size.
struct LocalMemory {
  std::size_t bytes;
};

class Kernel {
 public:
  Kernel(const Program& program, const std::string& name);

  const std::string& name() const { return name_; }
  cl_kernel get() const { return kernel_.get(); }

  // Sets arguments 0..n-1 in order.
  template <typename... Args>
  Kernel& set_args(const Args&... args) {
    cl_uint index = 0;
    (set_arg(index++, args), ...);
    return *this;
  }

  template <typename T>
  void set_arg(cl_uint index, const Buffer<T>& buffer) {
    cl_mem mem = buffer.get();
    set_raw(index, sizeof(cl_mem), &mem);
  }
  void set_arg(cl_uint index, const LocalMemory& local) { set_raw(index, local.bytes, nullptr); }
  template <typename T>
  void set_arg(cl_uint index, const T& value) {
    // Structs go by value when their device mirror has the same layout (see ray_geometry.cl).
    static_assert(
        std::is_arithmetic_v<T> || (std::is_class_v<T> && std::is_trivially_copyable_v<T>),
        "kernel arguments are numbers, buffers or plain structs");
    // size_t differs between host and device; kernels take uint/int counts.
    static_assert(!std::is_same_v<T, std::size_t> && !std::is_same_v<T, long> &&
                      !std::is_same_v<T, unsigned long>,
                  "pass kernel counts as cl_uint or cl_int, never size_t");
    static_assert(!std::is_same_v<T, double>, "kernels are fp32: pass float");
    set_raw(index, sizeof(T), &value);
  }

  // Largest work-group the kernel can use on its device.
  std::size_t max_work_group_size(cl_device_id device) const;
  // The work-group size of launches that name none (Context::launch): kDefaultGroup, or the
  // kernel's largest when smaller. Left to the runtime, the group must divide the global size,
  // and a global size with no small factors (a prime count of parameters) ran in groups of one:
  // twice the time of a whole training step on PoCL (docs/history/RESULTS.md, issue 14).
  static constexpr std::size_t kDefaultGroup = 64;
  std::size_t default_group(cl_device_id device) const;

 private:
  void set_raw(cl_uint index, std::size_t size, const void* value);

  Handle<cl_kernel> kernel_;
  std::string name_;
  mutable std::size_t default_group_ = 0;  // 0: not asked yet
};

}  // namespace riner::cl
