// The exceptions riner throws. Every failure the library can report is one of these.
#pragma once

#include <stdexcept>
#include <string>

namespace riner {

// Base of everything riner throws.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad user-supplied input: a file that is truncated or corrupt, a geometry that does not match
// the data, a setting out of range. The message is one line and names the culprit.
class InputError : public Error {
 public:
  using Error::Error;
};

// Readings that hold nothing to reconstruct (all NaN or infinite, or too few usable): a whole
// scan's is refused; a slab of a larger one (a dead detector row) is written as NaN.
class NoReadingsError : public InputError {
 public:
  using InputError::InputError;
};

// An OpenCL call failed. Carries the call, the status and its CL_* name.
class ClError : public Error {
 public:
  ClError(int status, std::string call, const std::string& where);
  int status() const { return status_; }
  const std::string& call() const { return call_; }
  const char* status_name() const;

 private:
  int status_;
  std::string call_;
};

// A program failed to build. what() is one line; log() is the compiler's full output.
class BuildError : public ClError {
 public:
  BuildError(int status, const std::string& program, std::string options, std::string log,
             const std::string& where);
  const std::string& log() const { return log_; }
  const std::string& options() const { return options_; }

 private:
  std::string options_;
  std::string log_;
};

// "CL_INVALID_VALUE" for -30, "CL_UNKNOWN_ERROR" for codes it does not know.
const char* cl_error_name(int status);

}  // namespace riner
