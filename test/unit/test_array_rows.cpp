// Reading a slab's detector rows: every format gives exactly the rows of the whole array, and
// a scan's rows normalise like the whole scan's.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "riner/error.hpp"
#include "riner/flat_field.hpp"
#include "riner/io.hpp"
#include "riner/scan_source.hpp"
#include "support/crafted_files.hpp"
#include "support/fixture.hpp"
#include "support/hdf5_writer.hpp"

namespace {

// [5 frames, 7 rows, 6 columns], every value distinct.
riner::Array counting_stack() {
  riner::Array a({5, 7, 6});
  for (std::size_t i = 0; i < a.size(); ++i) a.data[i] = 100.0f + static_cast<float>(i);
  return a;
}

void check_rows(const std::filesystem::path& path, const riner::Array& whole) {
  CAPTURE(path.string());
  CHECK(riner::read_array_shape(path) == whole.shape);
  for (const riner::RowRange rows : {riner::RowRange{0, 7}, riner::RowRange{2, 3},
                                     riner::RowRange{6, 1}, riner::RowRange{0, 1}}) {
    CAPTURE(rows.first);
    CAPTURE(rows.count);
    const riner::ArrayFile file = riner::read_array_rows(path, rows);
    const riner::Array expected = riner::detector_rows(whole, rows);
    CHECK(file.array.shape == expected.shape);
    CHECK(file.array.data == expected.data);
  }
  CHECK_THROWS_AS(riner::read_array_rows(path, {5, 3}), riner::InputError);
  CHECK_THROWS_AS(riner::read_array_rows(path, {0, 0}), riner::InputError);
}

}  // namespace

TEST_CASE("a stack's rows read alone equal the rows of the whole, in every format") {
  riner::test::TempDir dir;
  const riner::Array whole = counting_stack();
  for (const char* name : {"stack.npy", "stack.raw", "stack.tif", "stack.nii"}) {
    riner::write_array(dir / name, whole);
    check_rows(dir / name, whole);
  }
  // A folder of 2D TIFFs, one per view.
  std::filesystem::create_directories(dir / "tiffs");
  for (std::size_t f = 0; f < whole.shape[0]; ++f) {
    riner::Array view({whole.shape[1], whole.shape[2]});
    std::copy_n(whole.data.begin() + static_cast<std::ptrdiff_t>(f * view.size()), view.size(),
                view.data.begin());
    riner::write_array(dir / ("tiffs/p_" + std::to_string(f) + ".tif"), view);
  }
  check_rows(dir / "tiffs", whole);
  // An HDF5 dataset (hyperslab) and a Fortran-order .npy (read whole, then cut).
  {
    riner::test::Hdf5Writer h5(dir / "data.h5");
    h5.write<float>("/group/proj", {5, 7, 6}, whole.data, H5T_IEEE_F32LE);
  }
  check_rows((dir / "data.h5").string() + ":/group/proj", whole);
  std::string header = "{'descr': '<f4', 'fortran_order': True, 'shape': (5, 7, 6), }";
  header.resize(118, ' ');
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8) + char(header.size() & 0xff) +
                      char(header.size() >> 8) + header;
  for (std::size_t k = 0; k < 6; ++k)
    for (std::size_t j = 0; j < 7; ++j)
      for (std::size_t i = 0; i < 5; ++i) {
        const float v = whole(i, j, k);
        bytes.append(reinterpret_cast<const char*>(&v), 4);
      }
  riner::test::write_bytes(dir / "fortran.npy", bytes);
  check_rows(dir / "fortran.npy", whole);
  // A 2D array has no rows to read.
  riner::write_array(dir / "slice.npy", riner::Array({5, 6}, 1.0f));
  CHECK_THROWS_AS(riner::read_array_rows(dir / "slice.npy", {0, 1}), riner::InputError);
}

TEST_CASE("a scan's rows normalise by the flats and darks of the same rows") {
  riner::test::TempDir dir;
  riner::Array raw({4, 6, 5}), flat({2, 6, 5}), dark({6, 5});
  for (std::size_t i = 0; i < raw.size(); ++i) raw.data[i] = 300.0f + static_cast<float>(i % 37);
  for (std::size_t i = 0; i < flat.size(); ++i) flat.data[i] = 900.0f + static_cast<float>(i % 11);
  for (std::size_t i = 0; i < dark.size(); ++i) dark.data[i] = 10.0f + static_cast<float>(i % 5);
  raw.data[3] = 0.0f;  // below the dark: an invalid reading, NaN
  riner::write_array(dir / "raw.npy", raw);
  riner::write_array(dir / "flat.npy", flat);
  riner::write_array(dir / "dark.npy", dark);
  riner::test::write_bytes(dir / "geometry.json", R"({"type": "parallel3d",
      "detector": {"count": [5, 6], "pitch_mm": [1.0, 1.0]},
      "angles": {"count": 4, "range_rad": 3.141592653589793},
      "volume": {"shape": [6, 5, 5], "voxel_mm": 1.0}})");
  const riner::ScanSource spec{(dir / "raw.npy").string(), "", (dir / "flat.npy").string(),
                               (dir / "dark.npy").string(), std::nullopt, "", ""};
  const riner::LoadedScan whole = riner::load_scan_source(spec);
  const riner::ScanRows rows(spec);
  CHECK(rows.shape() == std::vector<std::size_t>{4, 6, 5});
  CHECK(rows.raw());
  const riner::Scan part = rows.read({1, 3});
  const riner::Array expected = riner::detector_rows(whole.scan.measurement, {1, 3});
  REQUIRE(part.measurement.shape == expected.shape);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    CAPTURE(i);
    if (std::isnan(expected.data[i])) {
      CHECK(std::isnan(part.measurement.data[i]));
    } else {
      CHECK(part.measurement.data[i] == expected.data[i]);
    }
  }
  // The rows keep their place along the axis: row 1 of 6 with 3 rows is centred 0.5 below.
  CHECK(part.geometry.n_v == 3);
  CHECK(part.geometry.offset_v == doctest::Approx(-0.5));
  const riner::Scan first = rows.read({0, 1});
  CHECK(first.non_finite == 1);  // raw.data[3] is in row 0
  // A 2D geometry cannot be read by rows.
  riner::test::write_bytes(dir / "g2.json", R"({"type": "parallel2d",
      "detector": {"count": 5, "pitch_mm": 1.0},
      "angles": {"count": 4, "range_rad": 3.141592653589793},
      "volume": {"shape": [5, 5], "voxel_mm": 1.0}})");
  riner::write_array(dir / "sino.npy", riner::Array({4, 5}, 0.5f));
  CHECK_THROWS_WITH_AS(
      riner::ScanRows({(dir / "sino.npy").string(), (dir / "g2.json").string(), "", "",
                       std::nullopt, "", ""}),
      doctest::Contains("slabs of detector rows need a 3D geometry"), riner::InputError);
}

TEST_CASE("a NIfTI stack's shape comes from its header, checked against the file's size") {
  riner::test::TempDir dir;
  const riner::Array whole = counting_stack();
  riner::write_array(dir / "stack.nii", whole);
  CHECK(riner::read_array_shape(dir / "stack.nii") == whole.shape);
  const auto size = std::filesystem::file_size(dir / "stack.nii");
  std::filesystem::resize_file(dir / "stack.nii", size - 10);
  CHECK_THROWS_WITH_AS(riner::read_array_shape(dir / "stack.nii"),
                       doctest::Contains("but the file holds only"), riner::InputError);
  std::filesystem::resize_file(dir / "stack.nii", 100);
  CHECK_THROWS_AS(riner::read_array_shape(dir / "stack.nii"), riner::InputError);
}

TEST_CASE("a scaled, big-endian int16 NIfTI stack's rows read alone equal its rows read whole") {
  riner::test::TempDir dir;
  // dims x = 4 columns, y = 5 rows, z = 3 frames; values 0..59 as big-endian int16.
  std::string data;
  for (int i = 0; i < 60; ++i) {
    data += static_cast<char>((i >> 8) & 0xff);
    data += static_cast<char>(i & 0xff);
  }
  riner::test::write_bytes(dir / "scaled.nii",
                           riner::test::make_nifti({4, 5, 3}, 4, 16, 0.5f, -2.0f, data, true));
  const riner::Array whole = riner::read_array(dir / "scaled.nii").array;
  REQUIRE(whole.shape == std::vector<std::size_t>{3, 5, 4});
  CHECK(whole.data[7] == doctest::Approx(0.5 * 7 - 2.0));
  const riner::ArrayFile rows = riner::read_array_rows(dir / "scaled.nii", {1, 3});
  const riner::Array expected = riner::detector_rows(whole, {1, 3});
  CHECK(rows.array.shape == expected.shape);
  CHECK(rows.array.data == expected.data);
  CHECK(rows.voxel_size == std::vector<double>{2.0, 1.5, 1.0});
}
