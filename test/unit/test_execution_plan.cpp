// The execution plan: chosen from a device's queried properties, overridable, refused where the
// device cannot run it.
#include <doctest/doctest.h>

#include "riner/error.hpp"
#include "riner/execution_plan.hpp"

namespace {

riner::DeviceInfo cpu_device(std::uint32_t cores) {
  riner::DeviceInfo d;
  d.platform = "Portable Computing Language";
  d.vendor = "AuthenticAMD";
  d.type = "CPU";
  d.compute_units = cores;
  d.max_work_group_size = 4096;
  return d;
}

riner::DeviceInfo gpu_device(const std::string& platform, const std::string& vendor) {
  riner::DeviceInfo d;
  d.platform = platform;
  d.vendor = vendor;
  d.type = "GPU";
  d.compute_units = 132;
  d.max_work_group_size = 1024;
  return d;
}

}  // namespace

TEST_SUITE("execution_plan") {
  TEST_CASE("a CPU gets the cpu plan: owned grid bands, two work-groups per core") {
    for (std::uint32_t cores : {1u, 2u, 16u}) {
      CAPTURE(cores);
      const riner::ExecutionPlan p = riner::choose_execution_plan(cpu_device(cores));
      CHECK(p.kind == riner::PlanKind::kCpu);
      CHECK(p.gradient_slices == 2 * cores);
      CHECK(p.grid_bands == 1);
      CHECK(p.rays_per_step == riner::ExecutionPlan::kCpuRaysPerStep);
      CHECK(p.describe().find("cpu plan") == 0);
    }
  }

  TEST_CASE("a GPU gets the gpu plan with the fastest float atomics it has") {
    const riner::ExecutionPlan nv =
        riner::choose_execution_plan(gpu_device("NVIDIA CUDA", "NVIDIA Corporation"));
    CHECK(nv.kind == riner::PlanKind::kGpu);
    CHECK(nv.float_atomics == riner::FloatAtomics::kNvidiaPtx);
    CHECK(nv.rays_per_step == riner::ExecutionPlan::kGpuRaysPerStep);
    CHECK(nv.gradient_slices == 264);
    riner::DeviceInfo intel = gpu_device("Intel(R) OpenCL Graphics", "Intel(R) Corporation");
    CHECK(riner::choose_execution_plan(intel).float_atomics ==
          riner::FloatAtomics::kCompareExchange);
    intel.fp32_global_atomic_add = true;
    CHECK(riner::choose_execution_plan(intel).float_atomics == riner::FloatAtomics::kExtension);
    riner::DeviceInfo pocl5 = cpu_device(16);  // reports the extension, lacks the builtins
    pocl5.fp32_global_atomic_add = true;
    riner::PlanConfig gpu;
    gpu.kind = "gpu";
    CHECK(riner::choose_execution_plan(pocl5, gpu).float_atomics ==
          riner::FloatAtomics::kCompareExchange);
    const riner::DeviceInfo amd =
        gpu_device("AMD Accelerated Parallel Processing", "Advanced Micro Devices, Inc.");
    CHECK(riner::choose_execution_plan(amd).float_atomics == riner::FloatAtomics::kAmdBuiltin);
  }

  TEST_CASE("the config overrides the choice, within what the device can run") {
    riner::PlanConfig c;
    c.kind = "gpu";
    c.sample_group = 2048;
    const riner::ExecutionPlan p = riner::choose_execution_plan(cpu_device(2), c);
    CHECK(p.kind == riner::PlanKind::kGpu);
    CHECK(p.sample_group == 2048);
    CHECK(p.float_atomics == riner::FloatAtomics::kCompareExchange);
    CHECK(p.reason == "plan.kind = gpu");
    c.sample_group = 8192;
    CHECK_THROWS_WITH_AS(riner::choose_execution_plan(cpu_device(2), c),
                         "plan.sample_group 8192 exceeds the device's largest work-group (4096)",
                         riner::InputError);
    riner::PlanConfig ptx;
    ptx.float_atomics = "nvidia-ptx";
    CHECK_THROWS_WITH_AS(riner::choose_execution_plan(cpu_device(2), ptx),
                         "plan.float_atomics = nvidia-ptx needs an NVIDIA device",
                         riner::InputError);
    riner::PlanConfig ext;
    ext.float_atomics = "cl_ext_float_atomics";
    CHECK_THROWS_AS(riner::choose_execution_plan(cpu_device(2), ext), riner::InputError);
    riner::PlanConfig bands;
    bands.grid_bands = 3;
    bands.gradient_slices = 5;
    const riner::ExecutionPlan b = riner::choose_execution_plan(cpu_device(2), bands);
    CHECK(b.grid_bands == 3);
    CHECK(b.gradient_slices == 5);
    riner::PlanConfig bad;
    bad.kind = "tpu";
    CHECK_THROWS_WITH_AS(riner::choose_execution_plan(cpu_device(2), bad),
                         "plan.kind must be auto, cpu or gpu (got tpu)", riner::InputError);
  }
}
