// Cutting a volume into slabs: the slabs cover every slice once, each slab's rows are the rows
// its slices project to (in a cone beam: every row that sees them, on the slices those rows'
// rays cross), and a slab's geometry projects its slices onto exactly those rows.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "riner/error.hpp"
#include "riner/geometry.hpp"
#include "riner/projector.hpp"
#include "riner/rays.hpp"
#include "riner/slab_fbp.hpp"
#include "riner/slab_plan.hpp"

namespace {

riner::Geometry parallel3d(std::size_t nz, std::size_t n_v, double pitch_v, double offset_v) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel3d;
  g.n_u = 20;
  g.n_v = n_v;
  g.pitch_u = 1.0;
  g.pitch_v = pitch_v;
  g.offset_v = offset_v;
  for (int i = 0; i < 24; ++i) g.angles.push_back(M_PI * i / 24.0);
  g.volume_shape = {nz, 16, 16};
  g.voxel_mm = 1.0;
  return g;
}

// A synchrotron stack: 2560 columns, 3600 views, 2000 rows, its volume on the same grid.
riner::Geometry synchrotron_stack() {
  riner::Geometry g = parallel3d(2000, 2000, 1.0, 0.0);
  g.n_u = 2560;
  g.angles.clear();
  for (int i = 0; i < 3600; ++i) g.angles.push_back(M_PI * i / 3600.0);
  g.volume_shape = {2000, 2560, 2560};
  return g;
}

}  // namespace

TEST_CASE("slabs cover every slice once, as even as they come") {
  const riner::Geometry g = parallel3d(64, 64, 1.0, 0.0);
  const std::vector<riner::Slab> slabs = riner::plan_slabs(g, 30);
  REQUIRE(slabs.size() == 3);
  std::size_t next = 0;
  for (const riner::Slab& s : slabs) {
    CHECK(s.first_slice == next);
    CHECK((s.slices == 21 || s.slices == 22));
    // Detector rows on the voxel grid: a slab reads its own slices' rows.
    CHECK(s.rows.first == s.first_slice);
    CHECK(s.rows.count == s.slices);
    next += s.slices;
  }
  CHECK(next == 64);
  CHECK(riner::plan_slabs(g, 1000).size() == 1);
  CHECK(riner::plan_slabs(g, 1).size() == 64);
}

TEST_CASE("a slab's rows are those whose centres fall in its slices, wherever the detector sits") {
  // Rows half a voxel apart and shifted by 0.3 rows: every row falls in exactly one slab (or
  // none, above or below the volume).
  const riner::Geometry g = parallel3d(10, 24, 0.5, 0.3);
  const std::vector<riner::Slab> slabs = riner::plan_slabs(g, 3);
  std::vector<int> owners(g.n_v, 0);
  for (const riner::Slab& s : slabs) {
    for (std::size_t r = s.rows.first; r < s.rows.end(); ++r) {
      ++owners[r];
      const double z = (static_cast<double>(r) - (g.n_v - 1) / 2.0 + g.offset_v) * g.pitch_v;
      const double bottom = (static_cast<double>(s.first_slice) - 0.5 - 4.5) * g.voxel_mm;
      CHECK(z >= bottom - 1e-9);
      CHECK(z < bottom + static_cast<double>(s.slices) * g.voxel_mm + 1e-9);
    }
  }
  for (std::size_t r = 0; r < g.n_v; ++r) CHECK(owners[r] <= 1);
}

TEST_CASE("a slab's geometry projects its slices onto the same rows as the whole volume does") {
  // Rows on slice centres (offset 0, or a whole number of rows: the detector shifted along the
  // axis), where Joseph's projector samples each slice alone. (A row between two slices
  // interpolates across a slab border in the voxel model; Riner's field is continuous and
  // answers at the row's own height.)
  for (const double offset_v : {0.0, 2.0}) {
    CAPTURE(offset_v);
    const riner::Geometry g = parallel3d(12, 12, 1.0, offset_v);
    riner::Array volume({12, 16, 16});
    for (std::size_t z = 0; z < 12; ++z)
      for (std::size_t y = 0; y < 16; ++y)
        for (std::size_t x = 0; x < 16; ++x)
          volume(z, y, x) = 0.01f * static_cast<float>((z * 7 + y * 3 + x) % 13);
    const riner::Array whole =
        riner::Projector(g, riner::Engine::kReference).project(volume);
    for (const riner::Slab& s : riner::plan_slabs(g, 5)) {
      CAPTURE(s.index);
      const riner::Geometry sg = riner::slab_geometry(g, s);
      CHECK(sg.volume_shape[0] == s.slices);
      riner::Array part({s.slices, 16, 16});
      std::copy_n(volume.data.begin() + static_cast<std::ptrdiff_t>(s.first_slice * 256),
                  part.size(), part.data.begin());
      const riner::Array projected =
          riner::Projector(sg, riner::Engine::kReference).project(part);
      const riner::Array expected = riner::detector_rows(whole, s.rows);
      REQUIRE(projected.shape == expected.shape);
      double worst = 0.0;
      for (std::size_t i = 0; i < expected.size(); ++i) {
        worst = std::max(worst, std::fabs(double(projected.data[i]) - expected.data[i]));
      }
      CHECK(worst < 1e-5);
    }
  }
}

namespace {

// 30 views of a 40 x 48 detector at magnification 2 round a 24 x 16 x 16 volume: the rows at
// the top and bottom climb through up to 5 slices inside the box.
riner::Geometry cone3d() {
  riner::Geometry g = parallel3d(24, 48, 1.0, 0.0);
  g.type = riner::GeometryType::kCone3d;
  g.n_u = 40;
  g.source_origin_mm = 60;
  g.origin_detector_mm = 60;
  g.angles.clear();
  for (int i = 0; i < 30; ++i) g.angles.push_back(2.0 * M_PI * i / 30.0);
  return g;
}

// The volume's values in slices [first, end), zero elsewhere.
riner::Array only_slices(const riner::Array& volume, std::size_t first, std::size_t end) {
  riner::Array part = volume;
  const std::size_t each = volume.shape[1] * volume.shape[2];
  for (std::size_t i = 0; i < part.size(); ++i) {
    const std::size_t z = i / each;
    if (z < first || z >= end) part.data[i] = 0.0f;
  }
  return part;
}

double largest_difference(const riner::Array& a, const riner::Array& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::fabs(double(a.data[i]) - b.data[i]));
  }
  return worst;
}

}  // namespace

TEST_CASE(
    "a cone-beam slab trains every row that sees its slices, on the slices those rows cross") {
  // Joseph's projector interpolates between slice centres, so a voxel model's slice reaches a
  // voxel beyond its edges: the checks keep a slice's distance where they mean "no ray".
  const riner::Geometry g = cone3d();
  riner::Array volume({24, 16, 16});
  for (std::size_t i = 0; i < volume.size(); ++i) {
    volume.data[i] = 0.01f * static_cast<float>(1 + (i * 7 + i / 16 * 3) % 13);
  }
  const riner::Projector whole(g, riner::Engine::kReference);
  std::vector<int> mapped(g.n_v, 0);
  const std::vector<riner::Slab> slabs = riner::plan_slabs(g, 6);
  REQUIRE(slabs.size() == 4);
  for (const riner::Slab& s : slabs) {
    CAPTURE(s.index);
    const std::size_t end = s.first_slice + s.slices,
                      trained_end = s.trained_first + s.trained_slices;
    CHECK(s.trained_first <= s.first_slice);
    CHECK(trained_end >= end);
    // Every row that sees the slab's own slices (inside them by a slice) is one of its rows.
    const riner::Array own = whole.project(only_slices(volume, s.first_slice + 1, end - 1));
    for (std::size_t r = 0; r < g.n_v; ++r) {
      if (r >= s.rows.first && r < s.rows.end()) continue;
      CAPTURE(r);
      CHECK(largest_difference(riner::detector_rows(own, {r, 1}),
                               riner::Array({g.n_views(), 1, g.n_u})) == 0.0);
    }
    // Its rows see nothing beyond its trained slices (a slice's distance away).
    riner::Array outside = volume;
    for (std::size_t z = std::max<std::size_t>(s.trained_first, 1) - 1;
         z < std::min<std::size_t>(trained_end + 1, 24); ++z) {
      std::fill_n(outside.data.begin() + static_cast<std::ptrdiff_t>(z * 256), 256, 0.0f);
    }
    const riner::Array beyond = riner::detector_rows(whole.project(outside), s.rows);
    CHECK(largest_difference(beyond, riner::Array(beyond.shape)) == 0.0);
    // Its geometry projects its trained slices as the whole volume's geometry does.
    const riner::Geometry sg = riner::slab_geometry(g, s);
    CHECK(sg.volume_shape[0] == s.trained_slices);
    riner::Array part({s.trained_slices, 16, 16});
    std::copy_n(volume.data.begin() + static_cast<std::ptrdiff_t>(s.trained_first * 256),
                part.size(), part.data.begin());
    const riner::Array expected = riner::detector_rows(
        whole.project(only_slices(volume, s.trained_first, trained_end)), s.rows);
    const riner::Array projected = riner::Projector(sg, riner::Engine::kReference).project(part);
    REQUIRE(projected.shape == expected.shape);
    CHECK(largest_difference(projected, expected) < 1e-5);
    for (std::size_t r = s.map_rows.first; r < s.map_rows.end(); ++r) ++mapped[r];
    CHECK(s.map_rows.first >= s.rows.first);
    CHECK(s.map_rows.end() <= s.rows.end());
  }
  // The outer slabs cross slices beside their own; every row's response comes from one slab.
  CHECK(slabs.front().trained_slices > 6);
  CHECK(slabs.back().trained_slices > 6);
  for (std::size_t r = 0; r < g.n_v; ++r) {
    CAPTURE(r);
    CHECK(mapped[r] == 1);
  }
  // Cut at the source's plane first: slabs of up to 8 of 24 slices are 4 of 6, not 3 of 8, of
  // which the middle one would cross the plane, its rows climbing away both ways.
  const std::vector<riner::Slab> eights = riner::plan_slabs(g, 8);
  REQUIRE(eights.size() == 4);
  std::size_t most_rows = 0;
  for (const riner::Slab& s : eights) {
    CHECK(s.slices == 6);
    CHECK((s.first_slice + s.slices <= 12 || s.first_slice >= 12));
    most_rows = std::max(most_rows, s.rows.count);
  }
  const riner::Slab across = riner::slab_extent(g, 8, 8);
  CHECK(across.trained_first < 8);
  CHECK(across.trained_first + across.trained_slices > 16);
  CHECK(across.rows.count > most_rows);
  MESSAGE("cone slabs of up to 8 of 24 slices: at most " << most_rows
                                                         << " rows each; the middle "
                                                            "one of 3 even slabs would read "
                                                         << across.rows.count);
  // Whole, a cone beam keeps its detector and grid.
  const std::vector<riner::Slab> one = riner::plan_slabs(g, 24);
  REQUIRE(one.size() == 1);
  CHECK(one[0].rows == riner::RowRange{0, g.n_v});
  CHECK(riner::slab_geometry(g, one[0]).grid_centre_z_mm == 0.0);
  // A cone's slabs cost more than their share of the detector: the rows of the slices beside.
  riner::Geometry flat = g;
  flat.type = riner::GeometryType::kParallel3d;
  CHECK(riner::slab_bytes(g, 6) > riner::slab_bytes(flat, 6));
  CHECK(riner::slab_bytes(g, 6) < riner::slab_bytes(g, 24));
  // Whole, the cone reads every row; a parallel beam only the rows its grid's height reaches.
  CHECK(riner::slab_extent(flat, 0, 24).rows.count < g.n_v);
  CHECK(riner::slab_bytes(g, 24) > riner::slab_bytes(flat, 24));
}

TEST_CASE("a cone-beam slab's field of view: the heights of its grid that every view sees") {
  const riner::Geometry g = cone3d();
  // The whole detector, centred: as before, symmetric about the source's plane.
  const riner::FieldOfView whole = riner::field_of_view(g);
  CHECK(whole.centre_z_mm == 0.0);
  CHECK(whole.half_height_mm ==
        doctest::Approx(24.0 * (60.0 - whole.radius_mm) / 120.0).epsilon(1e-12));
  for (const riner::Slab& s : riner::plan_slabs(g, 6)) {
    CAPTURE(s.index);
    const riner::Geometry sg = riner::slab_geometry(g, s);
    const riner::FieldOfView f = riner::field_of_view(sg);
    CHECK(f.radius_mm == whole.radius_mm);
    // Points on the field's edge, top and bottom, land on the slab's rows at every view.
    for (double z :
         {f.centre_z_mm - 0.999 * f.half_height_mm, f.centre_z_mm + 0.999 * f.half_height_mm}) {
      for (double phi = 0.0; phi < 6.28; phi += 0.5) {
        const riner::Vec3 p{0.999 * f.radius_mm * std::cos(phi),
                            0.999 * f.radius_mm * std::sin(phi), z};
        for (std::size_t view = 0; view < sg.n_views(); ++view) {
          const double v = riner::project_to_detector(sg, view, p).v;
          CHECK(v >= -0.5);
          CHECK(v <= static_cast<double>(sg.n_v) - 0.5);
        }
      }
    }
  }
}

TEST_CASE("sizes and memory parse") {
  CHECK(riner::parse_memory_size("8G") == (std::size_t{8} << 30));
  CHECK(riner::parse_memory_size("512M") == (std::size_t{512} << 20));
  CHECK(riner::parse_memory_size("8g") == (std::size_t{8} << 30));
  CHECK(riner::parse_memory_size("2000000") == 2000000);
  // Under a mebibyte, or beyond any machine: a unit's slip (1000 bytes, 1e99G were taken).
  CHECK_THROWS_AS(riner::parse_memory_size("1000"), riner::InputError);
  CHECK_THROWS_AS(riner::parse_memory_size("1e99G"), riner::InputError);
  CHECK_THROWS_AS(riner::parse_memory_size("lots"), riner::InputError);
  CHECK_THROWS_AS(riner::parse_memory_size("-1G"), riner::InputError);
  CHECK_THROWS_AS(riner::parse_memory_size("2X"), riner::InputError);
  // More memory never means thinner slabs, and the whole volume fits an ample limit.
  const riner::Geometry g = parallel3d(64, 64, 1.0, 0.0);
  CHECK(riner::slices_within(g, std::size_t{1} << 40) == 64);
  CHECK(riner::slices_within(g, 0) == 1);
  CHECK(riner::slab_bytes(g, 8) < riner::slab_bytes(g, 16));
}

TEST_CASE("a 2D geometry as a stack of slices, and a slice of it back") {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel2d;
  g.n_u = 40;
  g.pitch_u = 0.5;
  g.offset_u = 2.5;
  g.uniform_angles = riner::UniformAngles{30, 0.0, M_PI};
  g.angles = riner::uniform_angles(*g.uniform_angles);
  g.volume_shape = {24, 28};
  g.voxel_mm = 0.5;
  const riner::Geometry stack = riner::stack_of_slices(g, 6);
  CHECK(stack.type == riner::GeometryType::kParallel3d);
  CHECK(stack.n_v == 6);
  CHECK(stack.volume_shape == std::vector<std::size_t>{6, 24, 28});
  CHECK(stack.pitch_v == 0.5);
  stack.validate();
  // Each row is a slice: the slabs of one slice read one row each.
  const std::vector<riner::Slab> slabs = riner::plan_slabs(stack, 1);
  REQUIRE(slabs.size() == 6);
  for (const riner::Slab& s : slabs) CHECK(s.rows.first == s.index);
  for (const riner::Slab& s : slabs) CHECK(s.rows.count == 1);
  const riner::Geometry back = riner::axial_slice_geometry(stack);
  CHECK(back.to_json() == g.to_json());
  CHECK_THROWS_AS(riner::stack_of_slices(stack, 2), riner::InputError);
  CHECK_THROWS_AS(riner::axial_slice_geometry(g), riner::InputError);
}

TEST_CASE("a GPU's own memory bounds the slabs trained on it at once") {
  const riner::Geometry g = synchrotron_stack();
  const std::size_t gib = std::size_t{1} << 30;
  riner::SlabMemory host_only{96 * gib, 0, 0};
  const riner::SlabSizing cpu = riner::size_slabs(g, host_only, 8, 1);
  CHECK_FALSE(cpu.device_bound);
  CHECK(cpu.workers * riner::slab_bytes(g, cpu.slices_per_slab) <= 96 * gib);

  // A 16 GB GPU (14 GB usable, buffers up to 4 GB): the slabs its 8 workers hold at once fit
  // in it, and their largest buffer within one allocation.
  riner::SlabMemory gpu{96 * gib, 14 * gib, 4 * gib};
  const riner::SlabSizing on_gpu = riner::size_slabs(g, gpu, 8, 1);
  MESSAGE("host only: " << cpu.slices_per_slab << " slices x " << cpu.workers
                        << "; a 16 GB GPU: " << on_gpu.slices_per_slab << " x " << on_gpu.workers);
  CHECK(on_gpu.workers == 8);
  CHECK(on_gpu.slices_per_slab < cpu.slices_per_slab);
  CHECK(on_gpu.device_bound);
  CHECK(on_gpu.workers * riner::slab_device_bytes(g, on_gpu.slices_per_slab) <= 14 * gib);
  CHECK(riner::slab_largest_buffer_bytes(g, on_gpu.slices_per_slab) <= 4 * gib);
  CHECK(on_gpu.workers * riner::slab_bytes(g, on_gpu.slices_per_slab) <= 96 * gib);
  // An 80 GB one does not bind before the host's memory does.
  const riner::SlabSizing big = riner::size_slabs(g, {96 * gib, 72 * gib, 20 * gib}, 8, 1);
  CHECK(big.slices_per_slab == cpu.slices_per_slab);
  CHECK_FALSE(big.device_bound);

  // An 8 GB GPU with 2 GB buffers: thinner slabs still, never none.
  riner::SlabMemory small{96 * gib, 7 * gib, 2 * gib};
  const riner::SlabSizing little = riner::size_slabs(g, small, 8, 1);
  CHECK(little.slices_per_slab >= 1);
  CHECK(little.slices_per_slab < on_gpu.slices_per_slab);
  CHECK(little.workers * riner::slab_device_bytes(g, little.slices_per_slab) <= 7 * gib);
  CHECK(riner::slab_largest_buffer_bytes(g, little.slices_per_slab) <= 2 * gib);

  // Slabs of a size asked for: the workers are what the device holds of them, at least one.
  const riner::SlabSizing asked = riner::size_slabs(g, small, 8, 1, 40);
  CHECK(asked.slices_per_slab == 40);
  CHECK(asked.workers == 1);
  CHECK(asked.device_bound);
  const std::size_t per_40 = riner::slab_device_bytes(g, 40);
  CHECK(per_40 > riner::slab_device_bytes(g, 20));
  // Slabs no thicker than gives each worker one, and workers no more than the slabs.
  const riner::Geometry few = parallel3d(6, 6, 1.0, 0.0);
  const riner::SlabSizing tiny = riner::size_slabs(few, gpu, 8, 1);
  CHECK(tiny.slices_per_slab == 1);
  CHECK(tiny.workers == 6);
}

TEST_CASE("a slab never holds more readings or voxels than the kernels' 32-bit indices reach") {
  // The synchrotron stack again (9.2e6 readings and 6.6e6 voxels a slice) on a 1 TB node: the
  // memory alone would take slabs of 4.6e9 readings (an audit's plan, 2026-12-07).
  const riner::Geometry g = synchrotron_stack();
  const std::size_t gib = std::size_t{1} << 30;
  const std::size_t most = riner::slices_within_piece_size(g);
  CHECK(most == 233);  // 2^31 / (3600 x 2560)
  const riner::SlabSizing big = riner::size_slabs(g, {1024 * gib, 0, 0}, 1, 1);
  CHECK(big.slices_per_slab == most);
  CHECK(riner::slab_bytes(g, 500) < 1024 * gib);  // the memory would have allowed more
  // Slabs of a size asked for beyond it are refused, naming the most.
  CHECK_THROWS_WITH_AS(riner::size_slabs(g, {1024 * gib, 0, 0}, 1, 1, 500),
                       doctest::Contains("at most 233 slices a slab"), riner::InputError);
  CHECK(riner::size_slabs(g, {1024 * gib, 0, 0}, 1, 1, 233).slices_per_slab == 233);
  // The same refusal before anything is planned (the CLI: before the output folder is made).
  CHECK_THROWS_WITH_AS(riner::check_slabs_within_piece_size(g, 500),
                       doctest::Contains("at most 233 slices a slab"), riner::InputError);
  CHECK_NOTHROW(riner::check_slabs_within_piece_size(g, 0));
  CHECK_NOTHROW(riner::check_slabs_within_piece_size(g, 233));
  // A slab's own geometry within it passes the training's and the kernels' check; the whole
  // stack does not.
  const std::vector<riner::Slab> slabs = riner::plan_slabs(g, most);
  CHECK_NOTHROW(riner::check_piece_size(riner::slab_geometry(g, slabs[0]), "training"));
  CHECK_THROWS_WITH_AS(riner::check_piece_size(g, "training"),
                       doctest::Contains("training: 1.843e+10 readings, more than the 2^31 - 1"),
                       riner::InputError);

  // FBP's slabs likewise (the rows a slab reaches include one either side for its sampling).
  const std::size_t fbp_most = riner::fbp_slices_within_piece_size(g);
  CHECK(fbp_most == 231);
  const double fbp_rows = static_cast<double>(riner::fbp_rows_reached(g, 0, fbp_most).count);
  CHECK(fbp_rows * 3600.0 * 2560.0 <= riner::kMostElementsPerPiece);

  // A cone beam: 2000 views of a 1280 x 1280 detector (3.3e9 readings), a 1280^3 volume. Each
  // slab's rows and trained slices (its own and those its rows' rays cross) stay within it.
  riner::Geometry cone;
  cone.type = riner::GeometryType::kCone3d;
  cone.n_u = cone.n_v = 1280;
  cone.pitch_u = cone.pitch_v = 0.2;
  cone.source_origin_mm = 500.0;
  cone.origin_detector_mm = 500.0;
  for (int i = 0; i < 2000; ++i) cone.angles.push_back(2.0 * M_PI * i / 2000.0);
  cone.volume_shape = {1280, 1280, 1280};
  cone.voxel_mm = 0.1;
  const std::size_t cone_most = riner::slices_within_piece_size(cone);
  const riner::SlabSizing cone_big = riner::size_slabs(cone, {1024 * gib, 0, 0}, 1, 1);
  MESSAGE("cone: at most " << cone_most << " slices a slab");
  CHECK(cone_big.slices_per_slab == cone_most);
  CHECK(cone_most < 1280);
  for (const riner::Slab& s : riner::plan_slabs(cone, cone_most)) {
    CHECK_NOTHROW(riner::check_piece_size(riner::slab_geometry(cone, s), "training"));
  }
  // Twice the grid and the detector: the thinnest slab's rays cross 512 or more of the 2048
  // slices (2^31 voxels and more), which no slab can hold: refused before anything is read.
  cone.n_u = cone.n_v = 2048;
  cone.volume_shape = {2048, 2048, 2048};
  CHECK_THROWS_WITH_AS(riner::size_slabs(cone, {1024 * gib, 0, 0}, 1, 1),
                       doctest::Contains("use larger voxels or a smaller volume"),
                       riner::InputError);
  CHECK_THROWS_WITH_AS(riner::check_slabs_within_piece_size(cone, 0),
                       doctest::Contains("use larger voxels or a smaller volume"),
                       riner::InputError);
}

TEST_CASE(
    "a parallel slab's memory counts the rows its slices reach, not a share of the detector") {
  // A grid of 17 slices on an 8000-row detector (a region of interest): a slab of 4 slices reads
  // 4 rows, as on a detector of 17 rows (an audit's run: "need about 59.0 GiB", 350 MB measured).
  const riner::Geometry roi = parallel3d(17, 8000, 1.0, 0.0);
  const riner::Geometry matched = parallel3d(17, 17, 1.0, 0.0);
  CHECK(riner::slab_extent(roi, 0, 4).rows.count == 4);
  CHECK(riner::slab_bytes(roi, 4) == riner::slab_bytes(matched, 4));
  CHECK(riner::slab_device_bytes(roi, 4) == riner::slab_device_bytes(matched, 4));
  // Trained whole (not by slabs), a scan reads every row: the decision to go by slabs counts
  // them all (a review: a region of interest went whole on the slabs' estimate, out of memory).
  CHECK(riner::whole_run_bytes(roi) > riner::slab_bytes(roi, 17));
  CHECK(riner::whole_run_bytes(matched) == riner::slab_bytes(matched, 17));
  // Rows twice as fine as the voxels: twice the rows.
  const riner::Geometry fine = parallel3d(17, 34, 0.5, 0.0);
  CHECK(riner::slab_extent(fine, 0, 4).rows.count == 8);
  CHECK(riner::slab_bytes(fine, 4) > riner::slab_bytes(matched, 4));
}
