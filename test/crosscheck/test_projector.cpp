// kernels/project.cl and kernels/backproject.cl against the reference projector.
#include <doctest/doctest.h>

#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/project.hpp"
#include "reference/project_ref.hpp"
#include "riner/error.hpp"
#include "riner/projector.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/tolerances.hpp"

namespace {

riner::Array random_array(std::vector<std::size_t> shape, std::uint64_t salt) {
  std::mt19937_64 rng(riner::test::seed() + salt);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  riner::Array a(std::move(shape));
  for (float& v : a.data) v = u(rng);
  return a;
}

double inner(const riner::Array& a, const riner::Array& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += static_cast<double>(a.data[i]) * b.data[i];
  return s;
}

// Views from exactly 0 over half a turn: view 15 lies at 90 degrees, where the rotation's cos
// is 6e-17 and a ray that misses the grid has plane bounds near 1e17, which no int holds (the
// kernels once looped over ~2^31 planes there).
riner::Geometry axis_aligned(riner::Geometry g) {
  g.uniform_angles = riner::UniformAngles{30, 0.0, M_PI};
  g.angles = riner::uniform_angles(*g.uniform_angles);
  return g;
}

// A cone beam's grid above the source's plane, as a slab's: the rays move, not the grid.
riner::Geometry raised(riner::Geometry g) {
  g.grid_centre_z_mm = 3.5 * g.voxel_mm;
  return g;
}

const riner::Geometry kGeometries[] = {riner::test::small_fan2d(),
                                       riner::test::small_parallel2d(),
                                       riner::test::small_cone3d(),
                                       raised(riner::test::small_cone3d()),
                                       riner::test::small_parallel3d(),
                                       axis_aligned(riner::test::small_parallel2d()),
                                       axis_aligned(riner::test::small_parallel3d())};

// Geometries for the projector's two shapes (ops::ProjectOp::Shape): the suite's, and the cases
// of the CPU's shape.
std::vector<riner::Geometry> forward_shape_geometries() {
  using riner::GeometryType;
  using riner::test::make_geometry;
  // Lines under the 32 values a group reads: gathered.
  const riner::Geometry narrow =
      make_geometry(GeometryType::kParallel2d, 20, 37, 1, {20, 24}, 1.0, 1.0, M_PI);
  // 1.6 voxels between rays at the axis: some groups span more than a read of 32 values.
  const riner::Geometry coarse = make_geometry(GeometryType::kFan2d, 45, 61, 1, {64, 64}, 2.4, 1.0);
  // Each detector row on a slice: one line per plane.
  const riner::Geometry level =
      make_geometry(GeometryType::kParallel3d, 30, 47, 20, {20, 32, 32}, 1.0, 1.0, M_PI);
  riner::Geometry between = riner::test::small_parallel3d();  // rows between slices
  between.offset_v = 0.37;
  // A tall detector close to the source: the outer rows' rays run mostly along z.
  riner::Geometry steep = make_geometry(GeometryType::kCone3d, 12, 33, 31, {36, 36, 36}, 1.0, 1.0);
  steep.source_origin_mm = 30.0;
  steep.origin_detector_mm = 10.0;
  steep.pitch_v = 4.0;
  steep.validate();
  std::vector<riner::Geometry> geometries(std::begin(kGeometries), std::end(kGeometries));
  geometries.insert(geometries.end(), {narrow, coarse, level, between, steep});
  return geometries;
}

// Both shapes against the reference and each other, on random volumes.
void check_forward_shapes(const std::vector<riner::Geometry>& geometries) {
  riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
  for (const riner::Geometry& g : geometries) {
    CAPTURE(std::string(riner::geometry_type_name(g.type)));
    CAPTURE(g.n_u);
    const riner::Array x = random_array(g.volume_shape, 8);
    const std::vector<double> expected =
        riner::ref::project(g, std::vector<double>(x.data.begin(), x.data.end()));
    double largest = 0.0;
    for (double v : expected) largest = std::max(largest, std::fabs(v));
    riner::ops::ProjectOp op(ctx, g);
    const riner::cl::Buffer<float> d_volume(ctx, std::span<const float>(x.data));
    std::vector<float> shapes[2];
    using Shape = riner::ops::ProjectOp::Shape;
    for (Shape shape : {Shape::kPerRay, Shape::kLanes}) {
      CAPTURE(static_cast<int>(shape));
      op.use_shape(shape);
      riner::cl::Buffer<float> d_out(ctx, op.measurement_size());
      op.forward(d_volume, d_out);
      std::vector<float>& out = shapes[static_cast<int>(shape)];
      out.resize(op.measurement_size());
      d_out.read(std::span<float>(out));
      // A float sum over a few dozen planes, each a product of a few roundings; one cell
      // read from the wrong place moves a ray by up to a cell's value (~1 of ~60).
      const auto stats = riner::test::compare(out, expected);
      CHECK_MESSAGE(stats.max_abs < riner::test::tolerance::kChained * largest, stats.describe());
      CHECK(stats.non_finite == 0);
    }
    // The same terms in the same order: on PoCL the two agree to the bit.
    const auto between_shapes = riner::test::compare(shapes[1], shapes[0]);
    CHECK_MESSAGE(between_shapes.max_abs < riner::test::tolerance::kOnePass * largest,
                  between_shapes.describe());
  }
}

}  // namespace

TEST_SUITE("projector") {
  TEST_CASE("OpenCL forward and adjoint match the reference") {
    for (const riner::Geometry& g : kGeometries) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const riner::Projector device(g, riner::Engine::kOpenCL, riner::test::device());
      const riner::Projector reference(g, riner::Engine::kReference);
      const riner::Array x = random_array(g.volume_shape, 3);
      const riner::Array y = random_array(g.measurement_shape(), 4);
      // fp32 accumulation over a few hundred samples per ray: ~1e-6 relative; 1e-4 leaves room
      // for devices without fused multiply-add.
      const auto forward = riner::test::compare(device.project(x).data, reference.project(x).data);
      CHECK_MESSAGE(forward.rms_rel < riner::test::tolerance::kChained, forward.describe());
      const auto adjoint = riner::test::compare(device.adjoint(y).data, reference.adjoint(y).data);
      CHECK_MESSAGE(adjoint.rms_rel < riner::test::tolerance::kChained, adjoint.describe());
    }
  }

  TEST_CASE(
      "both forward shapes (a GPU's, a CPU's) match the reference: lines read whole and gathered, "
      "partial groups, rays off the grid, a fan's groups across 45 degrees, every main axis") {
    check_forward_shapes(forward_shape_geometries());
  }

  // The same on four views each (0.1, 45 degrees and a little more, exactly 90, 2.0 rad), for
  // oclgrind's out-of-bounds checks (ctest oclgrind_projector_shapes).
  TEST_CASE("both forward shapes on four views") {
    std::vector<riner::Geometry> geometries = forward_shape_geometries();
    for (riner::Geometry& g : geometries) {
      g.uniform_angles.reset();
      g.angles = {0.1, M_PI / 4 + 0.05, M_PI / 2, 2.0};
    }
    check_forward_shapes(geometries);
  }

  TEST_CASE("OpenCL adjoint property holds in fp32") {
    for (const riner::Geometry& g : kGeometries) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const riner::Projector p(g, riner::Engine::kOpenCL, riner::test::device());
      const riner::Array x = random_array(g.volume_shape, 5);
      const riner::Array y = random_array(g.measurement_shape(), 6);
      const double ax_y = inner(p.project(x), y);
      const double x_aty = inner(x, p.adjoint(y));
      CHECK(std::fabs(ax_y - x_aty) <= riner::test::tolerance::kChained * std::fabs(ax_y));
    }
  }

  TEST_CASE("forward projection is bit-identical across repeats") {
    const riner::Geometry g = riner::test::small_cone3d();
    const riner::Projector p(g, riner::Engine::kOpenCL, riner::test::device());
    const riner::Array x = random_array(g.volume_shape, 7);
    const riner::Array first = p.project(x);
    for (int i = 0; i < 5; ++i) CHECK(p.project(x).data == first.data);
  }

  TEST_CASE("shape mismatches are InputErrors") {
    const riner::Geometry g = riner::test::small_fan2d();
    const riner::Projector p(g, riner::Engine::kReference);
    CHECK_THROWS_AS(p.project(riner::Array({3, 3})), riner::InputError);
    CHECK_THROWS_AS(p.adjoint(riner::Array({3, 3})), riner::InputError);
  }
}
