#include "cl/check.hpp"

#include <string>

#include "riner/log.hpp"

namespace riner::cl {

void throw_cl_error(cl_int status, const char* call, const char* where) {
  throw ClError(status, call, where);
}

void report_cl_error(cl_int status, const char* call, const char* where) noexcept {
  if (status == CL_SUCCESS) return;
  try {
    warn(std::string(call) + " failed: " + cl_error_name(status) + " at " + where);
  } catch (...) {
    // A warning must never escape a destructor.
  }
}

}  // namespace riner::cl
