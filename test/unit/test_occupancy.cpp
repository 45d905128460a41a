// Skipping the air (model/occupancy.hpp): the region carved from the measurements keeps every
// voxel of the object, drops air, gives up without evidence, and clipped rays keep every
// sample inside it, at the same positions. Issue 29: a faint square under neutron-like noise
// keeps every corner, with the centre of rotation 5 pixels off and with outlier views.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "model/air_readings.hpp"
#include "model/occupancy.hpp"
#include "model/shadow_carving.hpp"
#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/geometries.hpp"

namespace {

// An off-centre disc and a small ellipse (mu 0.02 / mm) on the geometry's grid.
riner::Phantom discs(const riner::Geometry& g) {
  const double half = 0.5 * g.voxel_mm * static_cast<double>(g.volume_shape.back());
  riner::Phantom p;
  p.ellipsoids.push_back({{0.2 * half, -0.1 * half, 0.0},
                          {0.45 * half, 0.45 * half, 0.4 * half},
                          {1, 0, 0, 0, 1, 0, 0, 0, 1},
                          0.02});
  p.ellipsoids.push_back({{-0.55 * half, 0.4 * half, 0.0},
                          {0.1 * half, 0.2 * half, 0.15 * half},
                          {1, 0, 0, 0, 1, 0, 0, 0, 1},
                          0.03});
  return p;
}

riner::Scan ring_scan(const riner::Geometry& g, const riner::Phantom& p, double photons) {
  riner::RingModel model;
  model.seed = 11;
  model.photons = photons;
  model.dead_elements = 1;
  const riner::Array clean = riner::exact_projections(p, g);
  const riner::Array alpha = riner::draw_responses(g, model);
  return riner::Scan{riner::corrupt_measurement(clean, alpha, model), g, 0};
}

// The unit tier stays on the CPU: the FBP check runs on the reference engine.
riner::model::OccupancySettings on_cpu() {
  riner::model::OccupancySettings s;
  s.engine = riner::Engine::kReference;
  return s;
}

// Every voxel the object touches is inside; returns the object's share of the grid.
double check_object_kept(const riner::model::Occupancy& o, const riner::Array& truth) {
  std::size_t object = 0, lost = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth.data[i] <= 0.0f) continue;
    ++object;
    lost += o.inside[i] == 0;
  }
  CHECK(lost == 0);
  return static_cast<double>(object) / static_cast<double>(truth.size());
}

}  // namespace

TEST_SUITE("occupancy") {
  TEST_CASE("the carving by blocks decides every voxel as the voxel-by-voxel twin does") {
    riner::Geometry cone_slab = riner::test::small_cone3d();  // a raised grid, few rows
    cone_slab.grid_centre_z_mm = 5.0;
    cone_slab.n_v = 15;
    riner::Geometry wide = riner::test::small_parallel2d();  // the grid wider than the detector
    wide.n_u = 49;
    for (const riner::Geometry& g :
         {riner::test::small_fan2d(), riner::test::small_parallel2d(), wide,
          riner::test::small_cone3d(), cone_slab, riner::test::small_parallel3d()}) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const std::size_t rows = g.is_3d() ? g.n_v : 1;
      // The scan's own evidence (discs under noise), and a shadow band that wanders with the
      // view, with one reading in fifty flipped.
      const riner::Scan scan = ring_scan(g, discs(g), 1e5);
      std::vector<std::uint8_t> read = riner::model::read_air(scan, 4.0).certified(scan, 4.0);
      std::vector<std::uint8_t> band(read.size());
      std::mt19937 flips(7);
      for (std::size_t i = 0; i < band.size(); ++i) {
        const double view = static_cast<double>(i / (rows * g.n_u));
        const double u = static_cast<double>(i % g.n_u), n = static_cast<double>(g.n_u);
        const bool shadow = std::abs(u - n * (0.5 + 0.2 * std::sin(0.3 * view))) < 0.25 * n;
        band[i] = static_cast<std::uint8_t>(shadow == (flips() % 50 == 0));
      }
      for (const std::vector<std::uint8_t>* certified : {&read, &band}) {
        for (double widen : {0.0, 2.5}) {
          for (int min_views : {1, 3}) {
            CAPTURE(widen);
            CAPTURE(min_views);
            const std::vector<std::uint8_t> blocks =
                riner::model::carve_by_shadows(g, rows, *certified, min_views, widen);
            const std::vector<std::uint8_t> each =
                riner::model::carve_each_voxel(g, rows, *certified, min_views, widen);
            REQUIRE(blocks.size() == each.size());
            std::size_t differ = 0, carved = 0;
            for (std::size_t i = 0; i < each.size(); ++i) {
              differ += blocks[i] != each[i];
              carved += each[i] == 0;
            }
            CHECK(differ == 0);
            // Both decisions occur on the band: air carved, object kept (the scan's own
            // readings certify nothing where the grid is wider than the detector).
            if (certified == &band) {
              CHECK(carved > 0);
              CHECK(carved < each.size());
            }
          }
        }
      }
    }
  }

  TEST_CASE("rays that read air carve it away; every voxel of the object stays (2D, 3D)") {
    const riner::Geometry geometries[] = {
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 90, 80, 1, {48, 48}, 1.0, 1.0,
                                   M_PI),
        riner::test::small_fan2d(), riner::test::small_cone3d()};
    for (const riner::Geometry& g : geometries) {
      for (double photons : {1e6, 0.0}) {  // noisy, and noise-free (the noise floor)
        CAPTURE(std::string(riner::geometry_type_name(g.type)));
        CAPTURE(photons);
        const riner::Phantom p = discs(g);
        const riner::Array truth = riner::rasterize(p, g, 2);
        riner::model::OccupancySettings settings = on_cpu();
        settings.fbp_check = !g.is_3d();  // as training.air_fbp_check auto
        const riner::model::Occupancy o =
            riner::model::carve_occupancy(ring_scan(g, p, photons), settings);
        REQUIRE(o.carved);
        CHECK(o.air_elements >= 4);
        CHECK(o.noise > 0.0);
        const double object = check_object_kept(o, truth);
        // Air went: the corners, and most of the grid outside the two shapes' hull.
        CHECK(o.inside[0] == 0);
        CHECK(o.inside_fraction < 0.8);
        CHECK(o.inside_fraction > object);
      }
    }
  }

  TEST_CASE("no element reads only air (the object wider than the detector): nothing carved") {
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 60, 30,
                                                         1, {48, 48}, 1.0, 1.0, M_PI);
    // A disc centred on the axis projects alike in every view: its readings are as steady as
    // air's. Strong, they are no plausible -ln alpha; faint, they do not average 0.
    for (const auto& [mu, why] : {std::pair<double, const char*>{0.02, "too few detector elements"},
                                  {0.005, "not the 0 of air"}}) {
      CAPTURE(mu);
      riner::Phantom p;
      p.ellipsoids.push_back({{0, 0, 0}, {23, 23, 23}, {1, 0, 0, 0, 1, 0, 0, 0, 1}, mu});
      REQUIRE(g.n_u * g.pitch_u < 2 * 23.0);
      const riner::model::Occupancy o =
          riner::model::carve_occupancy(ring_scan(g, p, 1e6), on_cpu());
      CHECK_FALSE(o.carved);
      CHECK(o.inside_fraction == 1.0);
      CHECK_MESSAGE(o.note.find(why) != std::string::npos, o.note);
      for (std::uint8_t v : o.inside) CHECK(v == 1);
      // Off the axis: no element reads only air either.
      p.ellipsoids[0].centre = {6.0, 0.0, 0.0};
      CHECK_FALSE(riner::model::carve_occupancy(ring_scan(g, p, 1e6), on_cpu()).carved);
    }
  }

  TEST_CASE("clipped rays keep every sample inside the region, at the same positions") {
    const riner::Geometry g = riner::test::small_fan2d();
    const riner::Phantom p = discs(g);
    const riner::Scan scan = ring_scan(g, p, 1e6);
    const double spacing = 1.5;
    const riner::model::RaySegments full(g, spacing, false);
    riner::model::RaySegments clipped = full;
    const riner::model::Occupancy o =
        riner::model::carve_occupancy(scan, clipped, spacing / g.voxel_mm, on_cpu());
    REQUIRE(o.carved);
    const double kept = o.samples_kept;
    // clip_segments clips as the carving did.
    riner::model::RaySegments again = full;
    CHECK(riner::model::clip_segments(again, scan, o, spacing / g.voxel_mm) == kept);
    double total = 0.0, inside_samples = 0.0;
    const long n = static_cast<long>(g.volume_shape[1]);
    for (std::size_t r = 0; r < full.size(); ++r) {
      total += full[r].count;
      CHECK(clipped[r].dx == full[r].dx);
      // The clipped run starts at an original sample.
      std::int64_t first = -1;
      if (clipped[r].count > 0) {
        for (std::uint32_t k = 0; k < full[r].count && first < 0; ++k) {
          float a[3], b[3];
          riner::model::sample_position(full[r], k, 0.5f, a);
          riner::model::sample_position(clipped[r], 0, 0.5f, b);
          if (std::fabs(a[0] - b[0]) < 1e-5f && std::fabs(a[1] - b[1]) < 1e-5f) first = k;
        }
        REQUIRE(first >= 0);
      }
      for (std::uint32_t k = 0; k < full[r].count; ++k) {
        float pos[3];
        riner::model::sample_position(full[r], k, 0.5f, pos);
        const long column = std::lround((pos[0] - 0.5) * n + 0.5 * (n - 1));
        const long row = std::lround(0.5 * (n - 1) - (pos[1] - 0.5) * n);
        if (column < 0 || column >= n || row < 0 || row >= n) continue;
        if (!o.inside[static_cast<std::size_t>(row * n + column)]) continue;
        inside_samples += 1.0;
        CHECK(first >= 0);
        CHECK(static_cast<std::int64_t>(k) >= first);
        CHECK(static_cast<std::int64_t>(k) < first + clipped[r].count);
      }
    }
    CHECK(kept < total);
    CHECK(kept >= inside_samples);
  }

  TEST_CASE("rays computed again when drawn are the table's, before and after the clip") {
    // A volume's rays past RaySegments::kTableBytes keep only their clip: each segment is
    // computed from the geometry when drawn, and must be the table's to the bit.
    for (const riner::Geometry& g : {riner::test::small_fan2d(), riner::test::small_cone3d()}) {
      CAPTURE(g.is_3d());
      const double spacing = 1.3 * g.voxel_mm;
      riner::model::RaySegments table(g, spacing, false);
      riner::model::RaySegments computed(g, spacing, false, 0);
      REQUIRE(table.tabled());
      REQUIRE_FALSE(computed.tabled());
      REQUIRE(computed.size() == table.size());
      auto same = [&] {
        std::size_t differing = 0;
        for (std::size_t r = 0; r < table.size(); ++r) {
          const riner::model::RaySegment a = table[r], b = computed[r];
          differing += std::memcmp(&a, &b, sizeof a) != 0 || table.count(r) != computed.count(r);
        }
        return differing;
      };
      CHECK(same() == 0);
      // A ball of half the grid's width: most rays are cut at both ends, some miss it.
      riner::model::Occupancy ball;
      ball.carved = true;
      const std::vector<std::size_t>& shape = g.volume_shape;
      const std::size_t nx = shape.back(), ny = shape[shape.size() - 2];
      const std::size_t nz = shape.size() == 3 ? shape[0] : 1;
      ball.inside.assign(nx * ny * nz, 0);
      for (std::size_t z = 0; z < nz; ++z) {
        for (std::size_t y = 0; y < ny; ++y) {
          for (std::size_t x = 0; x < nx; ++x) {
            const double dx = (x - 0.5 * (nx - 1.0)) / nx, dy = (y - 0.5 * (ny - 1.0)) / ny,
                         dz = nz > 1 ? (z - 0.5 * (nz - 1.0)) / nz : 0.0;
            ball.inside[(z * ny + y) * nx + x] = dx * dx + dy * dy + dz * dz < 0.0625;
          }
        }
      }
      const riner::Scan scan{
          riner::Array(g.is_3d() ? std::vector<std::size_t>{g.n_views(), g.n_v, g.n_u}
                                 : std::vector<std::size_t>{g.n_views(), g.n_u},
                       0.0f),
          g, 0};
      const double kept = riner::model::clip_segments(table, scan, ball, 1.3);
      CHECK(riner::model::clip_segments(computed, scan, ball, 1.3) == kept);
      double before = 0.0;
      std::size_t cut = 0, missed = 0;
      const riner::model::RaySegments whole(g, spacing, false);
      for (std::size_t r = 0; r < whole.size(); ++r) {
        before += whole.count(r);
        cut += table.count(r) > 0 && table.count(r) < whole.count(r);
        missed += whole.count(r) > 0 && table.count(r) == 0;
      }
      CHECK(kept < 0.8 * before);
      CHECK(cut > 0);
      CHECK(missed > 0);
      CHECK(same() == 0);
    }
  }
}

namespace {

// Issue 29's phantom: riner::faint_square over 180 degrees (both ends) in a parallel beam,
// 640 columns, responses within 5% and 2e4 photons (the noise of the shared neutron scans).
riner::SimulatedScan faint_square_scan(std::uint64_t seed) {
  riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 241, 640, 1,
                                                 {640, 640}, 1.0, 1.0, M_PI);
  for (std::size_t v = 0; v < g.n_views(); ++v) g.angles[v] = M_PI * static_cast<double>(v) / 240.0;
  g.uniform_angles.reset();
  const riner::Phantom p = riner::faint_square(g);
  riner::RingModel model;
  model.seed = seed;
  model.photons = 2e4;
  model.alpha_min = 0.95;
  model.alpha_max = 1.05;
  riner::SimulatedScan sim;
  sim.ground_truth = riner::rasterize(p, g, 2);
  sim.clean = riner::exact_projections(p, g);
  sim.alpha = riner::draw_responses(g, model);
  sim.scan = riner::Scan{riner::corrupt_measurement(sim.clean, sim.alpha, model), g, 0};
  return sim;
}

// View v made as a dim, noisy frame: its noise times `gain`, its readings lowered by `drop`.
void spoil_view(riner::SimulatedScan& sim, std::size_t v, double gain, double drop) {
  const std::size_t n = sim.scan.geometry.n_u;
  for (std::size_t e = 0; e < n; ++e) {
    float& x = sim.scan.measurement.data[v * n + e];
    if (!std::isfinite(x)) continue;
    const double clean = sim.clean.data[v * n + e] - std::log(sim.alpha.data[e]);
    x = static_cast<float>(clean + gain * (x - clean) - drop);
  }
}

}  // namespace

TEST_SUITE("occupancy: issue 29") {
  // The carving of 2026-11-24 (commit ce4cd2e) took 32% of this square away (elements that
  // never see past it took its thinnest projection for their offset) and more with the centre
  // off; its corners fell below one ray's noise.
  TEST_CASE("a faint square keeps every voxel: centre off by up to 5 px, outlier views") {
    riner::SimulatedScan sim = faint_square_scan(1);
    auto carve = [&](double shift) {
      riner::Scan scan = sim.scan;
      scan.geometry.offset_u += shift;
      return riner::model::carve_occupancy(scan, on_cpu());
    };
    for (double shift : {0.0, -2.0, 2.0, -5.0, 5.0}) {
      CAPTURE(shift);
      const riner::model::Occupancy o = carve(shift);
      REQUIRE(o.carved);
      const double object = check_object_kept(o, sim.ground_truth);
      // Still worth it: under half the grid sampled (the square is 0.36 of it).
      CHECK(o.inside_fraction < 0.5);
      CHECK(o.inside_fraction > object);
      CHECK(o.outlier_views == 0);
    }
    // The last view dim and five times as noisy (the real scan's), and one more in the middle.
    spoil_view(sim, 240, 5.0, 0.02);
    spoil_view(sim, 100, 5.0, -0.02);
    for (double shift : {0.0, 5.0}) {
      CAPTURE(shift);
      const riner::model::Occupancy o = carve(shift);
      REQUIRE(o.carved);
      CHECK(o.outlier_views == 2);
      check_object_kept(o, sim.ground_truth);
    }
  }

  TEST_CASE("without the FBP check the rays alone cut the square's faint corners") {
    // What the check is for: one ray grazing a corner reads within the noise of air.
    const riner::SimulatedScan sim = faint_square_scan(2);
    riner::model::OccupancySettings rays_only = on_cpu();
    rays_only.fbp_check = false;
    rays_only.margin_px = 0;
    const riner::model::Occupancy o = riner::model::carve_occupancy(sim.scan, rays_only);
    std::size_t lost = 0;
    for (std::size_t i = 0; i < o.inside.size(); ++i) {
      lost += sim.ground_truth.data[i] > 0.0f && !o.inside[i];
    }
    CHECK(lost > 100);
    // The rays through the skipped air see it: beside the cut corners they read above air.
    CHECK(o.skipped_rays > 0);
    CHECK(o.skipped_ray_sigmas > o.ray_check_threshold);
    CHECK(o.skipped_rays_near > 0);
    const riner::model::Occupancy checked = riner::model::carve_occupancy(sim.scan, on_cpu());
    CHECK(checked.kept_by_fbp > 0);
    check_object_kept(checked, sim.ground_truth);
    // With the FBP's voxels kept, no ray through the skipped air reads more than air.
    CHECK(checked.ray_check_threshold >= 5.0);
    CHECK(checked.skipped_ray_sigmas < checked.ray_check_threshold);
    CHECK(checked.skipped_rays_near == 0);
  }

  TEST_CASE("air readings: outlier views, correlated noise, elements that never see air") {
    riner::SimulatedScan sim = faint_square_scan(3);
    spoil_view(sim, 7, 5.0, 0.0);    // noisy
    spoil_view(sim, 50, 1.0, 0.05);  // off level (7 noise sigmas)
    riner::model::AirReadings a = riner::model::read_air(sim.scan, 4.0);
    REQUIRE(a.usable);
    CHECK(a.outlier_views == 2);
    CHECK(a.outlier_view[7] == 1);
    CHECK(a.outlier_view[50] == 1);
    // Poisson noise at 2e4 photons: 1/sqrt(2e4) = 0.0071 in air.
    CHECK(a.noise == doctest::Approx(0.0071).epsilon(0.1));
    // Independent noise: a mean of three is sqrt(3) quieter.
    CHECK(a.view_noise3[0] / a.view_noise[0] == doctest::Approx(1.0 / std::sqrt(3.0)).epsilon(0.2));
    // The middle column crosses the square in every view: it certifies nothing; a column at the
    // detector's edge reads air everywhere, its offset -ln alpha.
    CHECK(std::isnan(a.offset[320]));
    CHECK(a.offset[5] == doctest::Approx(-std::log(sim.alpha.data[5])).epsilon(0.01).scale(1.0));
    CHECK(std::isnan(a.excess_sigmas(sim.scan, 7, 5)));
    const std::vector<std::uint8_t> certified = a.certified(sim.scan, 4.0);
    CHECK(certified[10 * 640 + 5] == 1);
    CHECK(certified[10 * 640 + 320] == 0);
    // Noise correlated between neighbours (a scintillator's blur): measured as such.
    riner::Scan blurred = sim.scan;
    for (std::size_t v = 0; v < 241; ++v) {
      for (std::size_t e = 1; e + 1 < 640; ++e) {
        const float* in = sim.scan.measurement.ptr() + v * 640;
        if (!std::isfinite(in[e - 1]) || !std::isfinite(in[e]) || !std::isfinite(in[e + 1]))
          continue;
        blurred.measurement.data[v * 640 + e] =
            0.25f * in[e - 1] + 0.5f * in[e] + 0.25f * in[e + 1];
      }
    }
    const riner::model::AirReadings b = riner::model::read_air(blurred, 4.0);
    // Weights 1/4 1/2 1/4: one reading's sigma 0.61, a mean of three 0.50 (of the raw noise).
    CHECK(b.view_noise3[0] / b.view_noise[0] == doctest::Approx(0.50 / 0.61).epsilon(0.15));
  }
}

TEST_SUITE("occupancy output") {
  TEST_CASE("the output ramps to 0 over the region's outer voxels; 0 outside; deep voxels kept") {
    // A 9 x 9 region (rows and columns 2..10) in a 13 x 13 grid; the image is all 3.
    riner::model::Occupancy o;
    o.carved = true;
    o.inside.assign(13 * 13, 0);
    for (int r = 2; r <= 10; ++r)
      for (int c = 2; c <= 10; ++c) o.inside[static_cast<std::size_t>(r * 13 + c)] = 1;
    std::vector<float> image(13 * 13, 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 2, image);
    auto at = [&](int r, int c) { return image[static_cast<std::size_t>(r * 13 + c)]; };
    CHECK(at(0, 0) == 0.0f);
    CHECK(at(1, 6) == 0.0f);
    CHECK(at(2, 6) == doctest::Approx(1.0));  // outline: depth 1 of 3
    CHECK(at(2, 2) == doctest::Approx(1.0));  // a corner too
    CHECK(at(3, 6) == doctest::Approx(2.0));
    CHECK(at(4, 6) == doctest::Approx(3.0));
    CHECK(at(6, 6) == doctest::Approx(3.0));
    // No taper: a step, as before; and nothing at all without carving.
    std::fill(image.begin(), image.end(), 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 0, image);
    CHECK(at(2, 6) == 3.0f);
    CHECK(at(1, 6) == 0.0f);
    o.carved = false;
    std::fill(image.begin(), image.end(), 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 2, image);
    CHECK(at(0, 0) == 3.0f);
    CHECK(riner::model::air_taper_px(4) == 2);
    CHECK(riner::model::air_taper_px(1) == 0);
  }
}
