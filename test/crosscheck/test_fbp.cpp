// FBP/FDK: OpenCL against the reference, and both against phantoms.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "analytic/fbp_setup.hpp"
#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/device_geometry.hpp"
#include "ops/fbp.hpp"
#include "ops/project.hpp"
#include "reference/fbp_ref.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/projector.hpp"
#include "riner/simulate.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/random_inputs.hpp"
#include "support/tolerances.hpp"

namespace {

riner::Scan phantom_scan(const riner::Geometry& g, riner::Array* truth) {
  const riner::Phantom p = riner::shepp_logan(g);
  *truth = riner::rasterize(p, g, 4);
  return riner::Scan{riner::exact_projections(p, g), g, 0};
}

// Grids and detectors that put the backprojections' clamped reads at their edges.
std::vector<riner::Geometry> backprojection_shape_geometries() {
  riner::Geometry raised = riner::test::small_cone3d();  // a cone-beam slab's grid
  raised.grid_centre_z_mm = 3.5 * raised.voxel_mm;
  riner::Geometry between = riner::test::small_parallel3d();  // slices between two rows
  between.offset_v = 0.37;
  riner::Geometry narrow = riner::test::small_fan2d();  // the grid's corners off the detector
  narrow.n_u = 41;
  riner::Geometry tall = riner::test::small_cone3d();  // voxels above and below the rows
  tall.n_v = 9;
  return {riner::test::small_fan2d(),
          riner::test::small_parallel2d(),
          riner::test::small_cone3d(),
          raised,
          riner::test::small_parallel3d(),
          between,
          narrow,
          tall};
}

// Both shapes against the reference on random filtered readings; the CPU's shape also by
// chunks of `chunk_views` views (the last one shorter), added up.
void check_backprojection_shapes(const std::vector<riner::Geometry>& geometries,
                                 std::size_t chunk_views) {
  riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
  for (const riner::Geometry& g : geometries) {
    CAPTURE(std::string(riner::geometry_type_name(g.type)));
    CAPTURE(g.n_u);
    const std::size_t readings = g.n_views() * g.n_u * (g.is_3d() ? g.n_v : 1);
    const std::vector<float> filtered = riner::test::uniform(readings, -1.0f, 2.0f, g.n_u + 7);
    const std::vector<float> weights_f = riner::test::uniform(g.n_views(), 0.5f, 1.5f, 3);
    const std::vector<double> weights(weights_f.begin(), weights_f.end());
    // 3D: every third slice from the second; 2D: the one slice.
    const std::size_t first = g.is_3d() ? 1 : 0, step = g.is_3d() ? 3 : 1;
    const std::size_t count = g.is_3d() ? (g.volume_shape[0] - 1 + step - 1) / step : 1;
    const std::vector<double> expected = riner::ref::fbp_backproject(
        g, std::vector<double>(filtered.begin(), filtered.end()), weights, first, step, count);
    riner::ops::FbpOp op(
        ctx, g, riner::analytic::filter_taps(g.n_u, 1.0, riner::FbpFilter::kRamLak), weights);
    const riner::cl::Buffer<float> d_filtered(ctx, std::span<const float>(filtered));
    using Shape = riner::ops::FbpOp::Shape;
    const std::size_t chunk_bytes = chunk_views * (g.is_3d() ? g.n_v : 1) * (g.n_u + 3) * 8;
    for (auto [shape, pairs_bytes] :
         {std::pair{Shape::kPerVoxel, std::size_t{0}}, std::pair{Shape::kLanes, std::size_t{0}},
          std::pair{Shape::kLanes, chunk_bytes}}) {
      CAPTURE(static_cast<int>(shape));
      CAPTURE(pairs_bytes);
      op.use_shape(shape, pairs_bytes);
      riner::cl::Buffer<float> d_volume(ctx, expected.size());
      op.backproject(d_filtered, d_volume, first, step);
      std::vector<float> volume(expected.size());
      d_volume.read(std::span<float>(volume));
      // One pass of float sums over the views, each a product of a few roundings.
      const auto stats =
          riner::test::compare(volume, std::vector<float>(expected.begin(), expected.end()));
      CHECK_MESSAGE(stats.rms_rel < riner::test::tolerance::kOnePass, stats.describe());
    }
  }
}

}  // namespace

TEST_SUITE("fbp") {
  TEST_CASE(
      "the FFT filter (local and global memory), the direct convolution and the reference agree at "
      "awkward sizes") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    // Columns around powers of two and odd; an odd line count leaves the last pair half empty.
    for (std::size_t n_u : {1, 2, 3, 37, 64, 65, 300}) {
      for (riner::FbpFilter filter : {riner::FbpFilter::kRamLak, riner::FbpFilter::kHann}) {
        CAPTURE(n_u);
        riner::Geometry g = riner::test::small_parallel2d();
        g.n_u = n_u;
        g.angles.resize(7);
        const std::vector<double> taps = riner::analytic::filter_taps(n_u, 0.7, filter);
        const std::vector<float> in = riner::test::uniform(7 * n_u, -1.0f, 2.0f, n_u);
        const std::vector<double> expected =
            riner::ref::fbp_filter(std::vector<double>(in.begin(), in.end()), n_u, taps);
        riner::ops::FbpOp op(ctx, g, taps, std::vector<double>(7, 1.0));
        CHECK(op.filters_by_fft());  // PoCL's local memory holds any of these lines
        riner::cl::Buffer<float> d_in(ctx, std::span<const float>(in));
        riner::cl::Buffer<float> d_out(ctx, in.size());
        using Path = riner::ops::LineFilterOp::Path;
        // The global FFT on 2 work-groups: each filters every second pair of lines.
        for (Path path : {Path::kLocalFft, Path::kGlobalFft, Path::kDirect}) {
          CAPTURE(static_cast<int>(path));
          op.use_filter_path(path, 2);
          op.filter(d_in, d_out);
          std::vector<float> out(in.size());
          d_out.read(std::span<float>(out));
          const auto stats =
              riner::test::compare(out, std::vector<float>(expected.begin(), expected.end()));
          CHECK_MESSAGE(stats.rms_rel < riner::test::tolerance::kOnePass, stats.describe());
        }
      }
    }
  }

  TEST_CASE("OpenCL and reference agree for every geometry type and filter") {
    riner::Geometry raised = riner::test::small_cone3d();  // a cone-beam slab's grid
    raised.grid_centre_z_mm = 3.5 * raised.voxel_mm;
    for (const riner::Geometry& g :
         {riner::test::small_fan2d(), riner::test::small_parallel2d(), riner::test::small_cone3d(),
          raised, riner::test::small_parallel3d()}) {
      for (riner::FbpFilter filter : {riner::FbpFilter::kRamLak, riner::FbpFilter::kHann}) {
        CAPTURE(std::string(riner::geometry_type_name(g.type)));
        CAPTURE(std::string(riner::fbp_filter_name(filter)));
        riner::Array truth;
        const riner::Scan scan = phantom_scan(g, &truth);
        riner::FbpOptions options;
        options.filter = filter;
        options.device = riner::test::device();
        const riner::Array device = riner::fbp(scan, options);
        options.engine = riner::Engine::kReference;
        const riner::Array reference = riner::fbp(scan, options);
        // The reference once returned n_y images for a 2D scan (its rows taken for slices).
        REQUIRE(reference.shape == device.shape);
        REQUIRE(reference.data.size() == device.data.size());
        // fp32 convolution over n_u taps and sums over views: ~1e-6; 1e-4 is the bar.
        const auto stats = riner::test::compare(device.data, reference.data);
        CHECK_MESSAGE(stats.rms_rel < riner::test::tolerance::kChained, stats.describe());
      }
    }
  }

  TEST_CASE(
      "both backprojection shapes (a GPU's, a CPU's) agree with the reference: partial tiles, "
      "voxels off the detector, slices between rows, a selection of slices") {
    check_backprojection_shapes(backprojection_shape_geometries(), 7);
  }

  // The same on five views (chunks of 3 and 2), for oclgrind's out-of-bounds checks (ctest
  // oclgrind_fbp_shapes): the clamped indices depend on the voxels and the angles, not on how
  // many views are summed, and the interpreter's time on how many are.
  TEST_CASE("both backprojection shapes on five views") {
    std::vector<riner::Geometry> geometries = backprojection_shape_geometries();
    for (riner::Geometry& g : geometries) {
      g.uniform_angles.reset();
      g.angles = {0.1, M_PI / 4 + 0.05, M_PI / 2, 2.0, 4.0};
    }
    check_backprojection_shapes(geometries, 3);
  }

  TEST_CASE("a selection of slices gives exactly those slices of the whole volume") {
    for (const riner::Geometry& g :
         {riner::test::small_cone3d(), riner::test::small_parallel3d()}) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      riner::Array truth;
      const riner::Scan scan = phantom_scan(g, &truth);
      const std::size_t per_slice = g.volume_shape[1] * g.volume_shape[2];
      for (riner::Engine engine : {riner::Engine::kOpenCL, riner::Engine::kReference}) {
        riner::FbpOptions options;
        options.engine = engine;
        options.device = riner::test::device();
        const riner::Array whole = riner::fbp(scan, options);
        options.slices = riner::SliceSelection::spread(g.volume_shape[0], 4);
        const std::vector<std::size_t> slices = options.slices.slices(g.volume_shape[0]);
        REQUIRE(slices.size() == 4);
        const riner::Array part = riner::fbp(scan, options);
        REQUIRE(part.shape == std::vector<std::size_t>{4, g.volume_shape[1], g.volume_shape[2]});
        for (std::size_t s = 0; s < 4; ++s) {
          for (std::size_t i = 0; i < per_slice; ++i) {
            // The same work-item's arithmetic: bit for bit.
            REQUIRE(part.data[s * per_slice + i] == whole.data[slices[s] * per_slice + i]);
          }
        }
      }
    }
  }

  TEST_CASE("a few slices of a grid past 2^31 voxels: FBP fills them, a projector refuses") {
    // FBP by slabs keeps the whole grid and fills a slab's slices: the voxels that count are
    // the selected ones (an over-cap check on the grid refused every slab of a 2048^3 FDK).
    riner::Geometry g = riner::test::small_parallel3d();
    g.volume_shape = {std::size_t{1} << 25, 8, 8};  // 2^31 voxels, one over the bound
    g.voxel_mm = g.pitch_v;
    const riner::Scan scan{riner::Array(g.measurement_shape(), 1.0f), g, 0};
    riner::FbpOptions options;
    options.device = riner::test::device();
    options.slices = riner::SliceSelection{g.volume_shape[0] / 2 - 1, 1, 2};
    const riner::Array two = riner::fbp(scan, options);
    CHECK(two.shape == std::vector<std::size_t>{2, 8, 8});
    CHECK(std::isfinite(two.data[0]));
    riner::cl::Context& context = riner::cl::context_of(riner::test::device());
    CHECK_THROWS_WITH_AS(riner::ops::ProjectOp(context, g),
                         doctest::Contains("the volume: 2.147e+09 voxels, more than the 2^31 - 1"),
                         riner::InputError);
    riner::Geometry wide = riner::test::small_parallel3d();
    wide.n_u = std::size_t{1} << 28;  // 2^28 columns x views x rows: past the readings' bound
    CHECK_THROWS_WITH_AS(riner::ops::ray_count(wide), doctest::Contains("readings, more than"),
                         riner::InputError);
  }

  TEST_CASE("slice selections: spread, centred, and refused past the volume") {
    using riner::SliceSelection;
    CHECK(SliceSelection::spread(100, 16).slices(100) ==
          std::vector<std::size_t>{0, 7, 14, 21, 28, 35, 42, 49, 56, 63, 70, 77, 84, 91, 98});
    CHECK(SliceSelection::spread(10, 16).slices(10).size() == 10);
    CHECK(SliceSelection{2, 3, 0}.slices(10) == std::vector<std::size_t>{2, 5, 8});
    CHECK_THROWS_WITH(SliceSelection({10, 1, 0}).slices(10),
                      doctest::Contains("starts past the volume's 10 slices"));
    CHECK_THROWS_WITH(SliceSelection({2, 3, 4}).slices(10),
                      doctest::Contains("runs past the volume's 10 slices"));
    CHECK_THROWS_AS(SliceSelection({0, 0, 1}).slices(10), riner::InputError);
  }

  TEST_CASE("FBP reconstructs Shepp-Logan from exact fan-beam projections") {
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    riner::Array truth;
    const riner::Scan scan = phantom_scan(g, &truth);
    riner::FbpOptions options;
    options.device = riner::test::device();
    const riner::Array image = riner::fbp(scan, options);
    const riner::ImageMetrics m = riner::compare_images(image, truth);
    MESSAGE("fan2d-paper Shepp-Logan FBP (ram-lak): PSNR " << m.psnr << " dB, SSIM " << m.ssim);
    // Measured 31.7 dB / 0.74: the ramp's ringing at the skull edges is the error left.
    CHECK(m.psnr > 30.0);
    // The brain region is flat at 0.02 / mm; its mean comes back within 1%.
    const riner::Array mask = riner::circle_mask(image.shape, 0.15);
    double sum = 0.0;
    double n = 0.0;
    for (std::size_t i = 0; i < image.size(); ++i) {
      if (mask.data[i] != 0.0f) {
        sum += image.data[i];
        n += 1.0;
      }
    }
    CHECK(sum / n == doctest::Approx(0.02).epsilon(0.01));
  }

  TEST_CASE("a fan beam's short scan (half a turn plus the fan) with Parker's weights") {
    // The paper's fan over pi + its fan + 0.05 rad, either way round and from another start,
    // against the full turn's 31.7 dB: without the weights the doubly measured lines counted
    // twice and the missing ones none, 8.4 dB.
    riner::Geometry base = riner::preset_geometry("fan2d-paper");
    base.offset_u = 3.3;
    const double fan = std::atan(0.5 * (static_cast<double>(base.n_u) + 6.6) * base.pitch_u /
                                 (base.source_origin_mm + base.origin_detector_mm));
    riner::FbpOptions options;
    options.device = riner::test::device();
    for (const auto& [start, range] :
         {std::pair{0.0, M_PI + 2.0 * fan + 0.05}, std::pair{1.0, -(M_PI + 2.0 * fan + 0.05)},
          std::pair{0.4, 1.5 * M_PI}}) {
      CAPTURE(start);
      CAPTURE(range);
      riner::Geometry g = base;
      g.uniform_angles = riner::UniformAngles{240, start, range};
      g.angles = riner::uniform_angles(*g.uniform_angles);
      riner::Array truth;
      const riner::Scan scan = phantom_scan(g, &truth);
      for (const riner::Engine engine : {riner::Engine::kOpenCL, riner::Engine::kReference}) {
        options.engine = engine;
        riner::FbpReport report;
        const riner::Array image = riner::fbp(scan, options, &report);
        CHECK(report.short_scan);
        CHECK(report.parker_weighted);
        const double psnr = riner::compare_images(image, truth).psnr;
        MESSAGE("short fan scan from " << start << " over " << range << ": " << psnr << " dB");
        CHECK(psnr > 28.0);  // measured 28.7-30.3
      }
    }
    // Less than half a turn plus the fan: lines never measured, said so, no weights.
    riner::Geometry g = base;
    g.uniform_angles = riner::UniformAngles{200, 0.0, M_PI + fan};
    g.angles = riner::uniform_angles(*g.uniform_angles);
    riner::Array truth;
    riner::FbpReport report;
    (void)riner::fbp(phantom_scan(g, &truth), options, &report);
    CHECK(report.short_scan);
    CHECK_FALSE(report.parker_weighted);
  }

  TEST_CASE("parallel FBP over 180 degrees with an off-centre rotation axis") {
    riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 180, 200, 1,
                                                   {128, 128}, 1.0, 1.0, M_PI);
    g.offset_u = 7.3;
    riner::Array truth;
    const riner::Scan scan = phantom_scan(g, &truth);
    riner::FbpOptions options;
    options.device = riner::test::device();
    const riner::ImageMetrics m = riner::compare_images(riner::fbp(scan, options), truth);
    MESSAGE("parallel2d 180 deg, offset 7.3 px: PSNR " << m.psnr << " dB, SSIM " << m.ssim);
    CHECK(m.psnr > 30.0);  // measured 31.6 dB
  }

  TEST_CASE("half acquisition: a full turn with the axis near one end of the detector") {
    // 128 x 128 grid (radius 64 mm) seen by 76 elements whose rays reach from -12 to +64 mm:
    // the axis 12 elements from one end, a 24 mm overlap. Fan and parallel beams.
    for (riner::GeometryType type :
         {riner::GeometryType::kParallel2d, riner::GeometryType::kFan2d}) {
      riner::Geometry g = riner::test::make_geometry(type, 360, 76, 1, {128, 128}, 1.0, 1.0);
      if (g.is_divergent()) g.pitch_u = 1.5;  // the fan magnifies 1.5x: 1 mm at the axis
      g.offset_u = 26.0;                      // element 37.5 + 26 = 63.5 sees the axis
      CAPTURE(riner::geometry_type_name(type));
      riner::Array truth;
      const riner::Scan scan = phantom_scan(g, &truth);
      riner::FbpReport report;
      riner::FbpOptions options;
      options.device = riner::test::device();
      const riner::Array image = riner::fbp(scan, options, &report);
      const riner::ImageMetrics m = riner::compare_images(image, truth);
      MESSAGE("PSNR " << m.psnr << " dB, SSIM " << m.ssim << ", overlap +-"
                      << report.half_acquisition_overlap_mm << " mm");
      CHECK(report.half_acquisition_overlap_mm == doctest::Approx(12.0).epsilon(0.1));
      // The same FBP without the weights: the far side at half its value, the near edge's step
      // filtered into streaks and a ring.
      riner::Array plain = scan.measurement;
      riner::analytic::cosine_weight(plain, g);
      const std::vector<double> filtered = riner::ref::fbp_filter(
          std::vector<double>(plain.data.begin(), plain.data.end()), g.n_u,
          riner::analytic::filter_taps(g.n_u, riner::analytic::filter_spacing(g),
                                       riner::FbpFilter::kRamLak));
      const std::vector<double> unweighted = riner::ref::fbp_backproject(
          g, filtered, riner::analytic::view_weights(g, nullptr), 0, 1, 1);
      riner::Array before(truth.shape);
      before.data.assign(unweighted.begin(), unweighted.end());
      const double psnr_before = riner::compare_images(before, truth).psnr;
      MESSAGE("without the weights: PSNR " << psnr_before << " dB");
      CHECK(m.psnr > 28.0);
      CHECK(m.psnr > psnr_before + 8.0);
      // The reference engine weights the same way.
      options.engine = riner::Engine::kReference;
      const riner::ImageMetrics r = riner::compare_images(riner::fbp(scan, options), truth);
      CHECK(r.psnr == doctest::Approx(m.psnr).epsilon(0.01));
    }
    // A centred detector is left as it was.
    riner::Geometry centred = riner::test::make_geometry(riner::GeometryType::kParallel2d, 360, 181,
                                                         1, {128, 128}, 1.0, 1.0);
    centred.offset_u = 3.0;
    riner::Array measurement({360, 181}, 1.0f);
    riner::Geometry same = centred;
    CHECK(riner::analytic::extend_half_acquisition(measurement, same) == 0.0);
    CHECK(measurement.data == riner::Array({360, 181}, 1.0f).data);
    CHECK(same.n_u == centred.n_u);
  }

  TEST_CASE("FDK reconstructs the central slices of a 3D Shepp-Logan") {
    riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kCone3d, 120, 128, 96,
                                                   {64, 64, 64}, 2.0, 2.0);
    riner::Array truth;
    const riner::Scan scan = phantom_scan(g, &truth);
    riner::FbpOptions options;
    options.device = riner::test::device();
    const riner::Array volume = riner::fbp(scan, options);
    const riner::ImageMetrics m = riner::compare_images(volume, truth, nullptr);
    MESSAGE("cone3d 64^3 FDK: PSNR " << m.psnr << " dB, SSIM " << m.ssim);
    CHECK(m.psnr > 29.0);  // measured 31.4 dB
  }

  TEST_CASE("non-finite measurements are repaired and counted") {
    const riner::Geometry g = riner::test::small_fan2d();
    riner::Array truth;
    riner::Scan scan = phantom_scan(g, &truth);
    for (std::size_t v = 0; v < g.n_views(); ++v) scan.measurement(v, 40) = INFINITY;
    scan.measurement(3, 7) = NAN;
    riner::FbpReport report;
    riner::FbpOptions options;
    options.device = riner::test::device();
    const riner::Array image = riner::fbp(scan, options, &report);
    CHECK(report.non_finite_replaced == g.n_views() + 1);
    for (float v : image.data) REQUIRE(std::isfinite(v));
  }
}
