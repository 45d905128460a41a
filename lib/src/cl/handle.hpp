// Move-only owner of one OpenCL object, released through the matching clRelease* call.
// Handle<T>::retain wraps an object the caller keeps owning too (interop).
#pragma once

#include <CL/cl.h>

#include <utility>

#include "cl/check.hpp"

namespace riner::cl {

template <typename T>
struct HandleTraits;

#define RINER_HANDLE_TRAITS(type, retain_fn, release_fn)     \
  template <>                                                \
  struct HandleTraits<type> {                                \
    static cl_int retain(type h) { return retain_fn(h); }    \
    static cl_int release(type h) { return release_fn(h); }  \
    static constexpr const char* kReleaseName = #release_fn; \
  }

RINER_HANDLE_TRAITS(cl_context, clRetainContext, clReleaseContext);
RINER_HANDLE_TRAITS(cl_command_queue, clRetainCommandQueue, clReleaseCommandQueue);
RINER_HANDLE_TRAITS(cl_mem, clRetainMemObject, clReleaseMemObject);
RINER_HANDLE_TRAITS(cl_program, clRetainProgram, clReleaseProgram);
RINER_HANDLE_TRAITS(cl_kernel, clRetainKernel, clReleaseKernel);
RINER_HANDLE_TRAITS(cl_event, clRetainEvent, clReleaseEvent);
#undef RINER_HANDLE_TRAITS

template <typename T>
class Handle {
 public:
  Handle() = default;
  // Takes ownership of a freshly created object.
  explicit Handle(T raw) : raw_(raw) {}

  // Shares an object someone else owns: retains it so both may release.
  static Handle retain(T raw) {
    if (raw != nullptr) check(HandleTraits<T>::retain(raw), "clRetain*", RINER_HERE);
    return Handle(raw);
  }

  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : raw_(std::exchange(other.raw_, nullptr)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      raw_ = std::exchange(other.raw_, nullptr);
    }
    return *this;
  }
  ~Handle() { reset(); }

  T get() const { return raw_; }
  explicit operator bool() const { return raw_ != nullptr; }

  void reset() noexcept {
    if (raw_ != nullptr) {
      report_cl_error(HandleTraits<T>::release(raw_), HandleTraits<T>::kReleaseName, RINER_HERE);
      raw_ = nullptr;
    }
  }

 private:
  T raw_ = nullptr;
};

}  // namespace riner::cl
