// The OpenCL context, device and in-order queue every op runs on, plus the program cache and
// per-kernel profiling records.
#pragma once

#include <CL/cl.h>

#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cl/event.hpp"
#include "cl/handle.hpp"
#include "riner/device.hpp"

namespace riner::cl {

class Kernel;
class Program;

// Up to three dimensions; unused ones are 1.
struct Range {
  std::array<std::size_t, 3> size{1, 1, 1};
  cl_uint dims = 0;  // 0 = "let the runtime choose" when used as a local size
  Range() = default;
  Range(std::size_t x) : size{x, 1, 1}, dims(1) {}  // NOLINT: implicit on purpose
  Range(std::size_t x, std::size_t y) : size{x, y, 1}, dims(2) {}
  Range(std::size_t x, std::size_t y, std::size_t z) : size{x, y, z}, dims(3) {}
};

struct KernelTiming {
  std::string kernel;
  double ms = 0.0;
};

// How programs were obtained in this context: a disk hit skips the compiler.
struct ProgramCacheStats {
  int memory_hits = 0;
  int disk_hits = 0;
  int source_builds = 0;
};

class Context {
 public:
  Context(cl_device_id device, bool profiling);
  // Interop: retains the caller's context and queue.
  Context(cl_context context, cl_command_queue queue, bool profiling);
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();

  cl_context get() const { return context_.get(); }
  cl_device_id device() const { return device_; }
  cl_command_queue queue() const { return queue_.get(); }
  const DeviceInfo& info() const { return info_; }
  bool profiling() const { return profiling_; }

  // A built program from kernel files (by stem: {"common", "smoke"}) and -D options; cached
  // in memory for the process and on disk across processes.
  std::shared_ptr<const Program> program(const std::vector<std::string>& sources,
                                         const std::string& options = "");
  ProgramCacheStats program_cache_stats() const;

  // Enqueues the kernel; global is rounded up to a multiple of local (1D without one: the
  // kernel's default_group, so its work-items past the count must return). Records the event
  // when recording is on; finishes the queue when RINER_SYNC_LAUNCHES=1.
  void launch(const Kernel& kernel, const Range& global, const Range& local = Range());

  void finish() const;

  // Per-kernel device times (profiling queues only): start, then take after finish().
  void set_recording(bool on);
  std::vector<KernelTiming> take_timings();

 private:
  void init_common();

  cl_device_id device_ = nullptr;
  Handle<cl_context> context_;
  Handle<cl_command_queue> queue_;
  DeviceInfo info_;
  bool profiling_ = false;
  bool sync_launches_ = false;

  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const Program>> programs_;
  ProgramCacheStats cache_stats_;
  bool recording_ = false;
  std::vector<std::pair<std::string, Event>> recorded_;
};

}  // namespace riner::cl
