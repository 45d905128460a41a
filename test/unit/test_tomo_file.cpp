// HDF5 tomography files (riner/tomo_file.hpp): NXtomo and Data Exchange written here, read back
// split into projections, flats and darks; the same data as arrays give the same scan; bad
// files name the path.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/flat_field.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/hdf5_writer.hpp"

namespace {

constexpr std::size_t kRows = 4, kCols = 30;
constexpr std::size_t kFrame = kRows * kCols;

// Frame f of a synthetic uint16 detector: a projection of a bump over a flat of ~4000 counts.
std::vector<std::uint16_t> frames(int key, std::size_t count, std::size_t salt) {
  std::vector<std::uint16_t> v(count * kFrame);
  for (std::size_t f = 0; f < count; ++f) {
    for (std::size_t p = 0; p < kFrame; ++p) {
      const double c = static_cast<double>(p % kCols);
      const double flat = 4000.0 + 20.0 * std::sin(0.3 * c) + static_cast<double>(salt + f);
      const double bump = std::exp(-std::pow((c - 12.0 - 0.2 * static_cast<double>(f)) / 5.0, 2));
      const double value = key == 2   ? 100.0 + static_cast<double>(f)
                           : key == 1 ? flat
                                      : 100.0 + (flat - 100.0) * std::exp(-0.8 * bump);
      v[f * kFrame + p] = static_cast<std::uint16_t>(std::lround(value));
    }
  }
  return v;
}

riner::Array as_array(const std::vector<std::uint16_t>& v, std::size_t count) {
  riner::Array a({count, kRows, kCols});
  for (std::size_t i = 0; i < v.size(); ++i) a.data[i] = v[i];
  return a;
}

template <typename T>
std::vector<T> join(std::initializer_list<std::vector<T>> parts) {
  std::vector<T> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

std::string error_of(const std::filesystem::path& p) {
  try {
    riner::read_tomo_file(p);
  } catch (const riner::InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_SUITE("tomo_file") {
  TEST_CASE("NXtomo: frames split by image_key, angles of the projections; same scan as arrays") {
    riner::test::TempDir dir;
    const auto darks = frames(2, 2, 0), flats_a = frames(1, 3, 1), projections = frames(0, 8, 0),
               flats_b = frames(1, 2, 7);
    std::vector<int> keys = {2, 2, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1};
    std::vector<double> angles(keys.size(), 0.0);
    for (std::size_t f = 5; f < 13; ++f) angles[f] = 22.5 * static_cast<double>(f - 5);
    {
      riner::test::Hdf5Writer w(dir / "scan.nxs");
      w.write("/entry/instrument/detector/data", {15, kRows, kCols},
              join({darks, flats_a, projections, flats_b}), H5T_STD_U16LE);
      w.write("/entry/instrument/detector/image_key", {15}, keys, H5T_STD_I32LE);
      w.write("/entry/sample/rotation_angle", {15}, angles, H5T_IEEE_F64LE);
    }
    const riner::TomoFile t = riner::read_tomo_file(dir / "scan.nxs");
    CHECK(t.layout == "nxtomo");
    REQUIRE(t.projections.shape == std::vector<std::size_t>{8, kRows, kCols});
    REQUIRE(t.flats.shape == std::vector<std::size_t>{5, kRows, kCols});
    REQUIRE(t.darks.shape == std::vector<std::size_t>{2, kRows, kCols});
    CHECK(t.projections.data == as_array(projections, 8).data);
    CHECK(t.darks.data == as_array(darks, 2).data);
    REQUIRE(t.angles_deg.size() == 8);
    CHECK(t.angles_deg[7] == 157.5);

    // The same frames given as arrays make the same scan, bit for bit, and the same image.
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel3d, 8, kCols,
                                                         kRows, {kRows, 24, 24}, 1.0, 1.0, M_PI);
    const riner::Array all_flats = as_array(join({flats_a, flats_b}), 5);
    const riner::Scan from_arrays = riner::raw_scan(g, as_array(projections, 8), all_flats,
                                                    as_array(darks, 2), std::nullopt, "arrays");
    const riner::Scan from_file =
        riner::raw_scan(g, t.projections, t.flats, t.darks, std::nullopt, "file");
    CHECK(from_file.measurement.data == from_arrays.measurement.data);
    riner::FbpOptions cpu;
    cpu.engine = riner::Engine::kReference;
    CHECK(riner::fbp(from_file, cpu).data == riner::fbp(from_arrays, cpu).data);
    // One detector row of the stack for a 2D geometry.
    const riner::Geometry g2 = riner::test::make_geometry(riner::GeometryType::kParallel2d, 8,
                                                          kCols, 1, {24, 24}, 1.0, 1.0, M_PI);
    const riner::Scan row2 = riner::raw_scan(g2, t.projections, t.flats, t.darks, 2, "file");
    REQUIRE(row2.measurement.shape == std::vector<std::size_t>{8, kCols});
    CHECK(row2.measurement(3, 7) == from_file.measurement(3, 2, 7));
  }

  TEST_CASE("Data Exchange: data, data_white, data_dark, theta; a dataset by path") {
    riner::test::TempDir dir;
    {
      riner::test::Hdf5Writer w(dir / "tooth.h5");
      w.write("/exchange/data", {6, kRows, kCols}, frames(0, 6, 0), H5T_STD_U16LE);
      w.write("/exchange/data_white", {3, kRows, kCols}, frames(1, 3, 0), H5T_STD_U16LE);
      w.write("/exchange/data_dark", {2, kRows, kCols}, frames(2, 2, 0), H5T_STD_U16LE);
      w.write("/exchange/theta", {6}, std::vector<double>{0, 36, 72, 108, 144, 180},
              H5T_IEEE_F64LE);
    }
    const riner::TomoFile t = riner::read_tomo_file(dir / "tooth.h5");
    CHECK(t.layout == "data exchange");
    CHECK(t.projections.shape == std::vector<std::size_t>{6, kRows, kCols});
    CHECK(t.flats.shape == std::vector<std::size_t>{3, kRows, kCols});
    CHECK(t.angles_deg.back() == 180.0);
    const riner::ArrayFile white =
        riner::read_array((dir / "tooth.h5").string() + ":/exchange/data_white");
    CHECK(white.array.data == t.flats.data);
    CHECK(riner::read_array(dir / "tooth.h5").array.data == t.projections.data);
  }

  TEST_CASE("bad files: not HDF5, no known layout, a missing key, counts that disagree") {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "text.h5", "not an hdf5 file");
    CHECK(error_of(dir / "text.h5").find("is not an HDF5 file") != std::string::npos);
    {
      riner::test::Hdf5Writer w(dir / "other.h5");
      w.write("/somewhere/data", {2, kRows, kCols}, frames(0, 2, 0), H5T_STD_U16LE);
    }
    CHECK(error_of(dir / "other.h5").find("holds neither /exchange/data") != std::string::npos);
    CHECK_THROWS_WITH_AS(riner::read_array((dir / "other.h5").string() + ":/nope"),
                         doctest::Contains("other.h5:/nope: no such dataset"), riner::InputError);
    {
      riner::test::Hdf5Writer w(dir / "nokey.nxs");
      w.write("/entry/data/data", {2, kRows, kCols}, frames(0, 2, 0), H5T_STD_U16LE);
    }
    CHECK(error_of(dir / "nokey.nxs").find("/entry/data/data: has no image_key") !=
          std::string::npos);
    {
      riner::test::Hdf5Writer w(dir / "counts.nxs");
      w.write("/entry/data/data", {3, kRows, kCols}, frames(0, 3, 0), H5T_STD_U16LE);
      w.write("/entry/data/image_key", {2}, std::vector<int>{0, 1}, H5T_STD_I32LE);
    }
    CHECK(error_of(dir / "counts.nxs").find("2 image keys for 3 frames") != std::string::npos);
    {
      riner::test::Hdf5Writer w(dir / "flat.h5");
      w.write("/exchange/data", {kRows, kCols}, frames(0, 1, 0), H5T_STD_U16LE);
    }
    CHECK(error_of(dir / "flat.h5").find("/exchange/data: is [4, 30]; expected [frames") !=
          std::string::npos);
  }
}
