// Writing a volume a block of slices at a time: every format reads back as the volume, in any
// block order where the format allows it; a file appears only when complete; and a stack's FBP
// by slabs equals its FBP whole.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/scan_source.hpp"
#include "riner/slab_fbp.hpp"
#include "riner/volume_writer.hpp"
#include "support/fixture.hpp"

namespace {

// [5 slices, 4 rows, 3 columns], every value distinct.
riner::Array counting_volume() {
  riner::Array a({5, 4, 3});
  for (std::size_t i = 0; i < a.size(); ++i) a.data[i] = 0.5f + static_cast<float>(i);
  return a;
}

riner::Array slices_of(const riner::Array& v, std::size_t first, std::size_t count) {
  const std::size_t plane = v.shape[1] * v.shape[2];
  return riner::Array({count, v.shape[1], v.shape[2]},
                      std::vector<float>(v.data.begin() + static_cast<long>(first * plane),
                                         v.data.begin() + static_cast<long>((first + count) * plane)));
}

}  // namespace

TEST_CASE("a volume written by blocks reads back whole, in every format") {
  riner::test::TempDir dir;
  const riner::Array v = counting_volume();
  for (const std::string name : {"v.npy", "v.nii", "v.raw", "v.h5", "v.tif", "slices"}) {
    CAPTURE(name);
    const std::string target = (dir / name).string();
    riner::VolumeWriter writer(target, v.shape, 0.5);
    if (name == "v.tif") {  // pages in order
      CHECK_THROWS_AS(writer.write(2, slices_of(v, 2, 3)), std::invalid_argument);
      writer.write(0, slices_of(v, 0, 2));
      writer.write(2, slices_of(v, 2, 3));
    } else {  // any order
      writer.write(3, slices_of(v, 3, 2));
      if (name != "slices") CHECK_FALSE(std::filesystem::exists(dir / name));
      writer.write(0, slices_of(v, 0, 3));
    }
    writer.close();
    const std::string read = name == "v.h5" ? target + ":/volume" : target;
    const riner::Array back = riner::read_array(read).array;
    CHECK(back.shape == v.shape);
    CHECK(back.data == v.data);
  }
  // A dataset named inside its file, and write_array's HDF5 path.
  riner::write_array(dir / "w.h5:/entry/recon", v);
  CHECK(riner::read_array((dir / "w.h5:/entry/recon").string()).array.data == v.data);
  CHECK_THROWS_AS(riner::write_array(dir / "image.h5", riner::Array({4, 3})), riner::InputError);
}

TEST_CASE("a dataset written into an HDF5 file already there is added to what it holds") {
  // Before: the whole file was replaced (a Data Exchange scan's projections and flats lost).
  riner::test::TempDir dir;
  const riner::Array v = counting_volume();
  riner::write_array(dir / "scan.h5:/exchange/data", v);
  riner::Array twice = v;
  for (float& x : twice.data) x *= 2.0f;
  riner::write_array(dir / "scan.h5:/exchange/recon", twice);
  riner::write_array(dir / "scan.h5:/exchange/more", twice);
  // The same dataset again replaces it, the rest kept (read last: a file read is an input).
  riner::write_array(dir / "scan.h5:/exchange/recon", v);
  CHECK(riner::read_array((dir / "scan.h5:/exchange/data").string()).array.data == v.data);
  CHECK(riner::read_array((dir / "scan.h5:/exchange/more").string()).array.data == twice.data);
  CHECK(riner::read_array((dir / "scan.h5:/exchange/recon").string()).array.data == v.data);
  // A file of that name that is no HDF5 file is not replaced.
  riner::test::write_bytes(dir / "notes.h5", "notes");
  CHECK_THROWS_AS(riner::write_array(dir / "notes.h5:/x", v), riner::InputError);
  CHECK(riner::test::read_bytes(dir / "notes.h5") == "notes");
}

TEST_CASE("a folder of slices left unfinished is marked, refused as a stack, and replaced") {
  // Before: a stopped `riner fbp --out FOLDER` left some slices and no sign of the rest.
  riner::test::TempDir dir;
  const riner::Array v = counting_volume();
  {
    riner::VolumeWriter writer((dir / "slices").string(), v.shape, 0.5);
    writer.write(0, slices_of(v, 0, 2));  // stopped here: never closed
  }
  CHECK(std::filesystem::exists(dir / "slices" / riner::VolumeWriter::kUnfinishedMarker));
  CHECK_THROWS_WITH_AS(riner::read_array(dir / "slices"), doctest::Contains("an unfinished volume"),
                       riner::InputError);
  riner::VolumeWriter again((dir / "slices").string(), v.shape, 0.5);
  again.write(2, slices_of(v, 2, 3));
  again.write(0, slices_of(v, 0, 2));
  again.close();
  CHECK_FALSE(std::filesystem::exists(dir / "slices" / riner::VolumeWriter::kUnfinishedMarker));
  CHECK(riner::read_array(dir / "slices").array.data == v.data);
}

TEST_CASE("a volume is in place only once every slice is written, and each slice once") {
  riner::test::TempDir dir;
  const riner::Array v = counting_volume();
  {
    riner::VolumeWriter writer((dir / "v.npy").string(), v.shape, 1.0);
    writer.write(0, slices_of(v, 0, 4));
    CHECK_THROWS_AS(writer.write(3, slices_of(v, 3, 2)), std::invalid_argument);  // 3 again
    CHECK_THROWS_AS(writer.write(4, slices_of(v, 0, 2)), std::invalid_argument);  // past the end
    CHECK_THROWS_WITH_AS(writer.close(), doctest::Contains("slice 4 of 5 was never written"),
                         riner::Error);
  }  // abandoned: nothing left behind
  CHECK(std::filesystem::is_empty(dir.path()));
  CHECK_THROWS_AS(riner::VolumeWriter((dir / "v.npy").string(), {5, 4}, 1.0), riner::InputError);
  CHECK_THROWS_AS(riner::VolumeWriter((dir / "v.png").string(), v.shape, 1.0), riner::InputError);
  // A folder that already holds slices is not written over.
  {
    riner::VolumeWriter writer((dir / "slices").string(), v.shape, 1.0);
    writer.write(0, v);
    writer.close();
  }
  CHECK_THROWS_AS(riner::VolumeWriter((dir / "slices").string(), v.shape, 1.0),
                  riner::InputError);
}

TEST_CASE("a stack's FBP (parallel) or FDK (cone) by slabs equals its FBP whole") {
  // Parallel: rows a third of a voxel off the slices' centres, so each slice interpolates
  // between two rows, which at a slab's border belong to different slabs. Cone: a slab's
  // voxels reach rows well beyond its own slices' (magnification 1.6 to 2.6 here).
  const std::vector<std::string> geometries = {
      R"({"type": "parallel3d",
          "detector": {"count": [48, 9], "pitch_mm": [1.0, 1.0], "offset_px": [0.0, 0.33]},
          "angles": {"count": 36, "range_rad": 3.141592653589793},
          "volume": {"shape": [8, 32, 32], "voxel_mm": 1.0}})",
      R"({"type": "cone3d", "source_origin_mm": 60, "origin_detector_mm": 60,
          "detector": {"count": [64, 24], "pitch_mm": [1.5, 1.5]},
          "angles": {"count": 40, "range_rad": 6.283185307179586},
          "volume": {"shape": [10, 24, 24], "voxel_mm": 1.0}})"};
  for (const std::string& json : geometries) {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "geometry.json", json);
    const riner::Geometry g = riner::Geometry::from_json(json);
    CAPTURE(riner::geometry_type_name(g.type));
    riner::Array sino({g.n_views(), g.n_v, g.n_u});
    for (std::size_t i = 0; i < sino.size(); ++i) {
      sino.data[i] = static_cast<float>(0.2 + 0.1 * std::sin(0.37 * static_cast<double>(i)));
    }
    riner::write_array(dir / "sino.npy", sino);
    riner::FbpOptions options;
    options.engine = riner::Engine::kReference;
    const riner::Array whole = riner::fbp(riner::Scan{sino, g}, options);
    const riner::ScanRows source({(dir / "sino.npy").string(), "", "", "", std::nullopt, "", ""});
    const std::size_t nz = g.volume_shape[0];
    for (std::size_t per : {std::size_t{1}, std::size_t{3}, nz}) {
      CAPTURE(per);
      if (g.type == riner::GeometryType::kCone3d && per < nz) {
        // The outermost slice of the cone reaches more rows than its own.
        CHECK(riner::fbp_rows_reached(g, 0, 1).count > 3);
      }
      const std::string out = (dir / ("slabs" + std::to_string(per) + ".npy")).string();
      riner::VolumeWriter writer(out, g.volume_shape, g.voxel_mm);
      const riner::SlabFbpReport report = riner::fbp_by_slabs(source, options, writer, per);
      writer.close();
      CHECK(report.slabs == (nz + per - 1) / per);
      const riner::Array slabbed = riner::read_array(out).array;
      REQUIRE(slabbed.shape == whole.shape);
      float worst = 0.0f, largest = 0.0f;
      for (std::size_t i = 0; i < whole.size(); ++i) {
        worst = std::max(worst, std::fabs(slabbed.data[i] - whole.data[i]));
        largest = std::max(largest, std::fabs(whole.data[i]));
      }
      CHECK(worst <= 1e-5f * largest);  // float rounding of the rows' re-centred offset
    }
  }
}
