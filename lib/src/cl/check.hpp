// Checking OpenCL status codes: RINER_CL_CALL throws ClError with the call name, the CL error
// name and file:line; report_cl_error is the non-throwing form for destructors.
#pragma once

#include <CL/cl.h>

#include "riner/error.hpp"

#define RINER_STRINGIFY_IMPL(x) #x
#define RINER_STRINGIFY(x) RINER_STRINGIFY_IMPL(x)
#define RINER_HERE __FILE__ ":" RINER_STRINGIFY(__LINE__)

namespace riner::cl {

[[noreturn]] void throw_cl_error(cl_int status, const char* call, const char* where);

inline void check(cl_int status, const char* call, const char* where) {
  if (status != CL_SUCCESS) throw_cl_error(status, call, where);
}

// Sends a warning instead of throwing; for destructors and deleters.
void report_cl_error(cl_int status, const char* call, const char* where) noexcept;

}  // namespace riner::cl

// RINER_CL_CALL(clFinish, queue) calls clFinish(queue) and throws on failure.
#define RINER_CL_CALL(fn, ...) ::riner::cl::check((fn)(__VA_ARGS__), #fn, RINER_HERE)
