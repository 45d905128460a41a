#include "cl/device_list.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>

#include "cl/check.hpp"
#include "riner/cores.hpp"

namespace riner::cl {

namespace {

std::string platform_string(cl_platform_id platform, cl_platform_info what) {
  std::size_t size = 0;
  RINER_CL_CALL(clGetPlatformInfo, platform, what, 0, nullptr, &size);
  std::string value(size, '\0');
  RINER_CL_CALL(clGetPlatformInfo, platform, what, size, value.data(), nullptr);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

std::string device_string(cl_device_id device, cl_device_info what) {
  std::size_t size = 0;
  RINER_CL_CALL(clGetDeviceInfo, device, what, 0, nullptr, &size);
  std::string value(size, '\0');
  RINER_CL_CALL(clGetDeviceInfo, device, what, size, value.data(), nullptr);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

template <typename T>
T device_value(cl_device_id device, cl_device_info what) {
  T value{};
  RINER_CL_CALL(clGetDeviceInfo, device, what, sizeof(T), &value, nullptr);
  return value;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

const char* type_name(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "GPU";
  if (type & CL_DEVICE_TYPE_CPU) return "CPU";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 6 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

}  // namespace

DeviceInfo query_device_info(cl_device_id device) {
  DeviceInfo info;
  cl_platform_id platform = device_value<cl_platform_id>(device, CL_DEVICE_PLATFORM);
  info.platform = platform_string(platform, CL_PLATFORM_NAME);
  info.platform_version = platform_string(platform, CL_PLATFORM_VERSION);
  info.name = device_string(device, CL_DEVICE_NAME);
  info.vendor = device_string(device, CL_DEVICE_VENDOR);
  info.type = type_name(device_value<cl_device_type>(device, CL_DEVICE_TYPE));
  info.version = device_string(device, CL_DEVICE_VERSION);
  info.driver_version = device_string(device, CL_DRIVER_VERSION);
  info.opencl_c_version = device_string(device, CL_DEVICE_OPENCL_C_VERSION);
  info.compute_units = device_value<cl_uint>(device, CL_DEVICE_MAX_COMPUTE_UNITS);
  info.max_clock_mhz = device_value<cl_uint>(device, CL_DEVICE_MAX_CLOCK_FREQUENCY);
  info.max_work_group_size = device_value<std::size_t>(device, CL_DEVICE_MAX_WORK_GROUP_SIZE);
  info.local_mem_bytes = device_value<cl_ulong>(device, CL_DEVICE_LOCAL_MEM_SIZE);
  info.local_mem_is_global =
      device_value<cl_device_local_mem_type>(device, CL_DEVICE_LOCAL_MEM_TYPE) == CL_GLOBAL;
  info.global_mem_bytes = device_value<cl_ulong>(device, CL_DEVICE_GLOBAL_MEM_SIZE);
  info.max_alloc_bytes = device_value<cl_ulong>(device, CL_DEVICE_MAX_MEM_ALLOC_SIZE);
  info.fp64 = device_value<cl_device_fp_config>(device, CL_DEVICE_DOUBLE_FP_CONFIG) != 0;
  info.preferred_vector_width_float =
      device_value<cl_uint>(device, CL_DEVICE_PREFERRED_VECTOR_WIDTH_FLOAT);
  info.native_vector_width_float =
      device_value<cl_uint>(device, CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT);
  info.preferred_vector_width_int =
      device_value<cl_uint>(device, CL_DEVICE_PREFERRED_VECTOR_WIDTH_INT);
  info.native_vector_width_int = device_value<cl_uint>(device, CL_DEVICE_NATIVE_VECTOR_WIDTH_INT);
  info.extensions = device_string(device, CL_DEVICE_EXTENSIONS);
  if (info.has_extension("cl_ext_float_atomics")) {
    // CL_DEVICE_SINGLE_FP_ATOMIC_CAPABILITIES_EXT and CL_DEVICE_GLOBAL_FP_ATOMIC_ADD_EXT
    // (cl_ext.h of newer headers; Debian 12's do not have them).
    constexpr cl_device_info kSingleFpAtomicCapabilities = 0x4231;
    constexpr cl_bitfield kGlobalFpAtomicAdd = 1 << 1;
    cl_bitfield caps = 0;
    if (clGetDeviceInfo(device, kSingleFpAtomicCapabilities, sizeof(caps), &caps, nullptr) ==
        CL_SUCCESS) {
      info.fp32_global_atomic_add = (caps & kGlobalFpAtomicAdd) != 0;
    }
  }
  return info;
}

std::vector<DeviceEntry> enumerate_devices() {
  fit_opencl_threads_to_usable_cores();
  cl_uint n_platforms = 0;
  cl_int status = clGetPlatformIDs(0, nullptr, &n_platforms);
  // The ICD loader reports "no platform" as an error; for us it is an empty list.
  if (status == -1001 /* CL_PLATFORM_NOT_FOUND_KHR */ || n_platforms == 0) return {};
  check(status, "clGetPlatformIDs", RINER_HERE);
  std::vector<cl_platform_id> platforms(n_platforms);
  RINER_CL_CALL(clGetPlatformIDs, n_platforms, platforms.data(), nullptr);

  std::vector<DeviceEntry> entries;
  for (cl_platform_id platform : platforms) {
    cl_uint n_devices = 0;
    status = clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 0, nullptr, &n_devices);
    if (status == CL_DEVICE_NOT_FOUND || n_devices == 0) continue;
    check(status, "clGetDeviceIDs", RINER_HERE);
    std::vector<cl_device_id> devices(n_devices);
    RINER_CL_CALL(clGetDeviceIDs, platform, CL_DEVICE_TYPE_ALL, n_devices, devices.data(), nullptr);
    for (cl_device_id device : devices) {
      DeviceEntry entry{platform, device, query_device_info(device)};
      entry.info.index = static_cast<int>(entries.size());
      entries.push_back(std::move(entry));
    }
  }
  return entries;
}

DeviceEntry select_device(std::string_view selector) {
  std::string chosen(selector);
  std::string origin = "--device";
  if (chosen.empty()) {
    if (const char* env = std::getenv("RINER_DEVICE"); env != nullptr && *env != '\0') {
      chosen = env;
      origin = "RINER_DEVICE";
    }
  }
  std::vector<DeviceEntry> entries = enumerate_devices();
  if (entries.empty()) {
    throw Error(
        "no OpenCL device found: install an OpenCL driver (on Debian: apt-get install "
        "pocl-opencl-icd) and check with `clinfo -l`");
  }
  if (chosen.empty()) {
    auto gpu = std::find_if(entries.begin(), entries.end(),
                            [](const DeviceEntry& e) { return e.info.type == "GPU"; });
    return gpu != entries.end() ? *gpu : entries.front();
  }
  if (is_index(chosen)) {
    std::size_t index = std::stoul(chosen);
    if (index >= entries.size()) {
      throw Error(origin + "=" + chosen + ": no such device (there are " +
                  std::to_string(entries.size()) + "; see `riner devices`)");
    }
    return entries[index];
  }
  const std::string needle = lower(chosen);
  for (const DeviceEntry& entry : entries) {
    if (lower(entry.info.full_name()).find(needle) != std::string::npos) return entry;
  }
  // A kind, as `riner devices` shows it ("(CPU)"): the first device of it.
  for (const DeviceEntry& entry : entries) {
    if (lower(entry.info.type) == needle) return entry;
  }
  // A kind this machine has none of (a GPU where there is only PoCL) is said as such.
  std::string kinds;
  for (const DeviceEntry& entry : entries) {
    if (kinds.find(lower(entry.info.type)) == std::string::npos)
      kinds += (kinds.empty() ? "" : ", ") + lower(entry.info.type);
  }
  if (needle == "cpu" || needle == "gpu" || needle == "accelerator") {
    throw Error(origin + "=" + chosen + ": this machine has no " + needle +
                " device (its kinds: " + kinds + "; see `riner devices`)");
  }
  throw Error(origin + "=" + chosen + ": no device name contains it and it is no device kind " +
              "(this machine's: " + kinds + "; see `riner devices`)");
}

}  // namespace riner::cl
