// riner devices: every OpenCL device with the capabilities riner's kernels depend on.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "riner/execution_plan.hpp"

#include "cli_args.hpp"
#include "commands.hpp"
#include "summary_json.hpp"
#include "riner/device.hpp"

namespace riner::app {

namespace {

std::string bytes_text(std::uint64_t bytes) {
  char buf[32];
  if (bytes >= (1ull << 30)) {
    std::snprintf(buf, sizeof(buf), "%.1f GiB", static_cast<double>(bytes) / (1ull << 30));
  } else if (bytes >= (1ull << 20)) {
    std::snprintf(buf, sizeof(buf), "%.1f MiB", static_cast<double>(bytes) / (1ull << 20));
  } else {
    std::snprintf(buf, sizeof(buf), "%.1f KiB", static_cast<double>(bytes) / 1024.0);
  }
  return buf;
}

void print_table(const std::vector<DeviceInfo>& devices) {
  for (const DeviceInfo& d : devices) {
    std::printf("#%d  %s  (%s)\n", d.index, d.full_name().c_str(), d.type.c_str());
    auto row = [](const char* key, const std::string& value) {
      std::printf("    %-24s %s\n", key, value.c_str());
    };
    row("vendor", d.vendor);
    row("device version", d.version);
    row("OpenCL C", d.opencl_c_version);
    row("driver", d.driver_version);
    row("compute units",
        std::to_string(d.compute_units) + " @ " + std::to_string(d.max_clock_mhz) + " MHz");
    row("max work-group size", std::to_string(d.max_work_group_size));
    row("local memory", bytes_text(d.local_mem_bytes) +
                            (d.local_mem_is_global ? " (emulated in global memory)" : ""));
    row("global memory", bytes_text(d.global_mem_bytes));
    row("max allocation", bytes_text(d.max_alloc_bytes));
    row("fp64", d.fp64 ? "yes" : "no");
    row("float vector width", "preferred " + std::to_string(d.preferred_vector_width_float) +
                                  ", native " + std::to_string(d.native_vector_width_float));
    row("int vector width", "preferred " + std::to_string(d.preferred_vector_width_int) +
                                ", native " + std::to_string(d.native_vector_width_int));
    row("float atomic add", d.fp32_global_atomic_add ? "cl_ext_float_atomics" : "not reported");
    row("training plan", choose_execution_plan(d).describe());
  }
}

}  // namespace

int run_devices(int argc, char** argv, int first) {
  Args args("devices",
            "Lists every OpenCL device riner can use, with the capabilities its "
            "kernels depend on. Choose one with --device N or RINER_DEVICE.");
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  const std::vector<DeviceInfo> devices = list_devices();
  if (args.is_set("json")) {
    nlohmann::json out = nlohmann::json::array();
    for (const DeviceInfo& d : devices) out.push_back(device_json(d));
    std::printf("%s\n", out.dump(1).c_str());
  } else if (!args.is_set("quiet")) {
    if (devices.empty()) {
      std::printf(
          "no OpenCL devices (on Debian: apt-get install pocl-opencl-icd; check with "
          "clinfo -l)\n");
    }
    print_table(devices);
  }
  return devices.empty() ? 1 : 0;
}

}  // namespace riner::app
