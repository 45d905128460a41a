// A completed-or-pending OpenCL event, with profiling times when the queue records them.
#pragma once

#include "cl/handle.hpp"

namespace riner::cl {

class Event {
 public:
  Event() = default;
  explicit Event(cl_event raw) : handle_(raw) {}

  cl_event get() const { return handle_.get(); }
  explicit operator bool() const { return static_cast<bool>(handle_); }

  void wait() const;
  // Device time between start and end in milliseconds; needs a profiling queue.
  double elapsed_ms() const;

 private:
  Handle<cl_event> handle_;
};

}  // namespace riner::cl
