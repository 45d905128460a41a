#include "cl/event.hpp"

namespace riner::cl {

void Event::wait() const {
  cl_event e = handle_.get();
  if (e != nullptr) RINER_CL_CALL(clWaitForEvents, 1, &e);
}

double Event::elapsed_ms() const {
  wait();
  cl_ulong start = 0;
  cl_ulong end = 0;
  RINER_CL_CALL(clGetEventProfilingInfo, handle_.get(), CL_PROFILING_COMMAND_START, sizeof(start),
                &start, nullptr);
  RINER_CL_CALL(clGetEventProfilingInfo, handle_.get(), CL_PROFILING_COMMAND_END, sizeof(end), &end,
                nullptr);
  return static_cast<double>(end - start) * 1e-6;
}

}  // namespace riner::cl
