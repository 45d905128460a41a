#include "cl/context.hpp"

#include <cstdlib>
#include <cstring>

#include "cl/device_list.hpp"
#include "cl/program.hpp"
#include "cl/program_builder.hpp"

namespace riner::cl {

namespace {

bool env_flag(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' && std::strcmp(value, "0") != 0;
}

Handle<cl_command_queue> create_queue(cl_context context, cl_device_id device, bool profiling) {
  cl_int status = CL_SUCCESS;
  cl_command_queue_properties props = profiling ? CL_QUEUE_PROFILING_ENABLE : 0;
  cl_command_queue queue = clCreateCommandQueue(context, device, props, &status);
  check(status, "clCreateCommandQueue", RINER_HERE);
  return Handle<cl_command_queue>(queue);
}

}  // namespace

Context::Context(cl_device_id device, bool profiling) : device_(device), profiling_(profiling) {
  cl_int status = CL_SUCCESS;
  cl_context context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &status);
  check(status, "clCreateContext", RINER_HERE);
  context_ = Handle<cl_context>(context);
  queue_ = create_queue(context, device, profiling);
  init_common();
}

Context::Context(cl_context context, cl_command_queue queue, bool profiling)
    : context_(Handle<cl_context>::retain(context)),
      queue_(Handle<cl_command_queue>::retain(queue)),
      profiling_(profiling) {
  RINER_CL_CALL(clGetCommandQueueInfo, queue, CL_QUEUE_DEVICE, sizeof(device_), &device_, nullptr);
  cl_command_queue_properties props = 0;
  RINER_CL_CALL(clGetCommandQueueInfo, queue, CL_QUEUE_PROPERTIES, sizeof(props), &props, nullptr);
  if (profiling && !(props & CL_QUEUE_PROFILING_ENABLE)) {
    throw Error(
        "profiling was requested but the given queue was created without "
        "CL_QUEUE_PROFILING_ENABLE");
  }
  // Every step relies on the queue's order (a kernel reads what the one before it wrote): an
  // out-of-order queue trained into garbage (an image summing to 1e36) without an error.
  if (props & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE) {
    throw Error(
        "the given queue was created with CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE; riner needs an "
        "in-order queue");
  }
  cl_context owner = nullptr;
  RINER_CL_CALL(clGetCommandQueueInfo, queue, CL_QUEUE_CONTEXT, sizeof(owner), &owner, nullptr);
  if (owner != context) {
    throw Error("the given queue belongs to another OpenCL context than the one given with it");
  }
  init_common();
}

Context::~Context() = default;

void Context::init_common() {
  info_ = query_device_info(device_);
  sync_launches_ = env_flag("RINER_SYNC_LAUNCHES");
}

std::shared_ptr<const Program> Context::program(const std::vector<std::string>& sources,
                                                const std::string& options) {
  std::string key;
  for (const std::string& s : sources) key += s + "+";
  key += "|" + options;
  std::lock_guard<std::mutex> lock(mutex_);
  if (auto it = programs_.find(key); it != programs_.end()) {
    ++cache_stats_.memory_hits;
    return it->second;
  }
  const std::string device_key =
      info_.platform + "|" + info_.platform_version + "|" + info_.name + "|" + info_.driver_version;
  BuiltProgram built = build_program(context_.get(), device_, sources, options, device_key,
                                     disk_cache_serves(info_.platform));
  ++(built.from_disk ? cache_stats_.disk_hits : cache_stats_.source_builds);
  auto program = std::make_shared<const Program>(std::move(built.program), sources.back());
  programs_.emplace(key, program);
  return program;
}

ProgramCacheStats Context::program_cache_stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cache_stats_;
}

void Context::launch(const Kernel& kernel, const Range& global, const Range& local) {
  std::size_t rounded[3];
  const cl_uint dims = global.dims;
  // 1D launches that name no group get the kernel's default one (every such kernel returns
  // past its count); in 2D and 3D the runtime chooses.
  const Range group = local.dims == 0 && dims == 1 ? Range(kernel.default_group(device_)) : local;
  for (cl_uint d = 0; d < dims; ++d) {
    const std::size_t g = global.size[d];
    const std::size_t l = group.dims == 0 ? 1 : group.size[d];
    rounded[d] = (g + l - 1) / l * l;
    // A zero-sized launch is an error in OpenCL; an empty batch is simply no work.
    if (rounded[d] == 0) return;
  }
  const bool record = recording_ && profiling_;
  cl_event event = nullptr;
  RINER_CL_CALL(clEnqueueNDRangeKernel, queue_.get(), kernel.get(), dims, nullptr, rounded,
                group.dims == 0 ? nullptr : group.size.data(), 0, nullptr,
                record ? &event : nullptr);
  if (record) {
    std::lock_guard<std::mutex> lock(mutex_);
    recorded_.emplace_back(kernel.name(), Event(event));
  }
  if (sync_launches_) {
    cl_int status = clFinish(queue_.get());
    if (status != CL_SUCCESS) throw ClError(status, "clFinish after " + kernel.name(), RINER_HERE);
  }
}

void Context::finish() const { RINER_CL_CALL(clFinish, queue_.get()); }

void Context::set_recording(bool on) {
  std::lock_guard<std::mutex> lock(mutex_);
  recording_ = on;
}

std::vector<KernelTiming> Context::take_timings() {
  std::vector<std::pair<std::string, Event>> events;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    events.swap(recorded_);
  }
  std::vector<KernelTiming> timings;
  timings.reserve(events.size());
  for (auto& [name, event] : events) timings.push_back({name, event.elapsed_ms()});
  return timings;
}

}  // namespace riner::cl
