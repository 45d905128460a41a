// The OpenCL runtime layer: buffers, launches, errors carrying the CL name, event timing.
#include <doctest/doctest.h>

#include <cstdlib>
#include <numeric>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "cl/program.hpp"
#include "ops/vector_ops.hpp"
#include "riner/error.hpp"
#include "support/fixture.hpp"

namespace {
riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }
}  // namespace

TEST_SUITE("cl_runtime") {
  TEST_CASE("the device reports sane capabilities") {
    const riner::DeviceInfo& info = riner::test::device().info();
    CHECK(info.compute_units >= 1);
    CHECK(info.max_work_group_size >= 1);
    CHECK(info.global_mem_bytes > 0);
    CHECK(info.max_alloc_bytes > 0);
    CHECK(info.opencl_c_version.find("OpenCL C") != std::string::npos);
  }

  TEST_CASE("upload and download round-trip at odd sizes, including 0 and 1") {
    for (std::size_t n : {0u, 1u, 7u, 255u, 256u, 257u, 4099u}) {
      CAPTURE(n);
      std::vector<float> host(n);
      std::iota(host.begin(), host.end(), 0.5f);
      riner::cl::Buffer<float> buffer(ctx(), std::span<const float>(host));
      CHECK(buffer.size() == n);
      CHECK(buffer.read() == host);
      if (n >= 4) {
        std::vector<float> part(2);
        buffer.read(std::span<float>(part), n - 2);
        CHECK(part == std::vector<float>{host[n - 2], host[n - 1]});
      }
      CHECK_THROWS_AS(buffer.read(std::span<float>(host.data(), n), 1), riner::Error);
    }
  }

  TEST_CASE("a launch through the runtime layer matches the host computation") {
    const std::size_t n = 1001;  // not a multiple of any work-group size
    std::vector<float> x(n);
    std::vector<float> y(n);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = 0.25f * static_cast<float>(i);
      y[i] = 1.0f - static_cast<float>(i);
    }
    riner::cl::Buffer<float> dx(ctx(), std::span<const float>(x));
    riner::cl::Buffer<float> dy(ctx(), std::span<const float>(y));
    riner::ops::VectorOps ops(ctx());
    ops.axpy(2.0f, dx, dy);
    const std::vector<float> got = dy.read();
    for (std::size_t i = 0; i < n; ++i) CHECK(got[i] == 1.0f - static_cast<float>(i) + 0.5f * i);
  }

  TEST_CASE("explicit local sizes round the global size up; kernels guard the tail") {
    riner::ops::VectorOps ops(ctx());
    const std::size_t n = 13;
    riner::cl::Buffer<float> dx(ctx(), std::span<const float>(std::vector<float>(n, 1.0f)));
    riner::cl::Buffer<float> dy(ctx(), std::span<const float>(std::vector<float>(n, 0.0f)));
    auto program = ctx().program({"common", "vector_ops"});
    riner::cl::Kernel axpy(*program, "vector_ops_axpy");
    axpy.set_args(static_cast<cl_uint>(n), 3.0f, dx, dy);
    ctx().launch(axpy, n, 8);  // 16 work-items for 13 elements
    CHECK(dy.read() == std::vector<float>(n, 3.0f));
  }

  TEST_CASE("CL failures carry the call and the CL error name") {
    auto program = ctx().program({"common", "vector_ops"});
    try {
      riner::cl::Kernel missing(*program, "no_such_kernel");
      FAIL("created a kernel that does not exist");
    } catch (const riner::ClError& e) {
      CHECK(e.status() == CL_INVALID_KERNEL_NAME);
      CHECK(std::string(e.what()).find("clCreateKernel(no_such_kernel in vector_ops) failed: "
                                       "CL_INVALID_KERNEL_NAME (-46) at lib/src/cl/program.cpp:") ==
            0);
    }
    riner::cl::Kernel axpy(*program, "vector_ops_axpy");
    CHECK_THROWS_WITH_AS(axpy.set_arg(9, 1.0f),
                         doctest::Contains("clSetKernelArg(vector_ops_axpy, 9) failed: "
                                           "CL_INVALID_ARG_INDEX"),
                         riner::ClError);
    CHECK_THROWS_AS(ctx().program({"common", "no_such_file"}), riner::Error);
  }

  TEST_CASE("a kernel that does not compile gives the build log") {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "vector_ops.cl", "__kernel void broken( { syntax error }");
    setenv("RINER_KERNEL_DIR", dir.path().c_str(), 1);
    riner::Device fresh = riner::Device::open();
    try {
      riner::cl::context_of(fresh).program({"common", "vector_ops"});
      FAIL("built a broken kernel");
    } catch (const riner::BuildError& e) {
      CHECK(e.status() == CL_BUILD_PROGRAM_FAILURE);
      CHECK(e.log().find("error") != std::string::npos);
      CHECK(e.options().find("-cl-std=CL1.2") != std::string::npos);
    }
    unsetenv("RINER_KERNEL_DIR");
  }

  TEST_CASE("profiling events time each recorded launch") {
    REQUIRE(riner::test::device().profiling());
    riner::ops::VectorOps ops(ctx());
    riner::cl::Buffer<float> dx(ctx(), std::span<const float>(std::vector<float>(1 << 16, 1.0f)));
    riner::cl::Buffer<float> dy(ctx(), std::span<const float>(std::vector<float>(1 << 16, 0.0f)));
    ctx().set_recording(true);
    ops.axpy(1.0f, dx, dy);
    ops.axpy(1.0f, dx, dy);
    ctx().finish();
    ctx().set_recording(false);
    const auto timings = ctx().take_timings();
    REQUIRE(timings.size() == 2);
    CHECK(timings[0].kernel == "vector_ops_axpy");
    CHECK(timings[0].ms >= 0.0);
    CHECK(ctx().take_timings().empty());
  }

  TEST_CASE("device selection by index, by name, and clear errors") {
    CHECK(riner::Device::open("0").info().index == 0);
    const std::string name = riner::test::device().info().name;
    CHECK(riner::Device::open(name.substr(0, 4)).info().name == name);
    CHECK_THROWS_WITH_AS(riner::Device::open("99"),
                         doctest::Contains("--device=99: no such device"), riner::Error);
    CHECK_THROWS_WITH_AS(riner::Device::open("no-such-gpu-xyz"),
                         doctest::Contains("no device name contains it"), riner::Error);
  }

  TEST_CASE("interop: riner runs on a context and queue the caller owns") {
    riner::cl::Context& own = ctx();
    riner::Device shared = riner::Device::from_handles(own.get(), own.queue());
    riner::ops::VectorOps ops(riner::cl::context_of(shared));
    riner::cl::Buffer<float> dx(riner::cl::context_of(shared),
                                std::span<const float>(std::vector<float>(5, 2.0f)));
    riner::cl::Buffer<float> dy(riner::cl::context_of(shared),
                                std::span<const float>(std::vector<float>(5, 1.0f)));
    ops.axpy(0.5f, dx, dy);
    CHECK(dy.read() == std::vector<float>(5, 2.0f));
  }

  TEST_CASE("interop: an out-of-order queue, or one of another context, is refused") {
    // An out-of-order queue trained into garbage without an error (an image summing to 1e36).
    riner::cl::Context& own = ctx();
    cl_int status = CL_SUCCESS;
    cl_command_queue unordered = clCreateCommandQueue(
        own.get(), own.device(), CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &status);
    if (status == CL_SUCCESS) {
      CHECK_THROWS_WITH_AS(riner::Device::from_handles(own.get(), unordered),
                           doctest::Contains("riner needs an in-order queue"), riner::Error);
      clReleaseCommandQueue(unordered);
    }
    const cl_device_id device = own.device();
    cl_context other = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &status);
    REQUIRE(status == CL_SUCCESS);
    CHECK_THROWS_WITH_AS(riner::Device::from_handles(other, own.queue()),
                         doctest::Contains("belongs to another OpenCL context"), riner::Error);
    clReleaseContext(other);
  }
}
