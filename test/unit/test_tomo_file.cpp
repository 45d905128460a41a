// HDF5 tomography files (riner/tomo_file.hpp): NXtomo and Data Exchange written here, read back
// split into projections, flats and darks; the same data as arrays give the same scan; bad
// files name the path.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/flat_field.hpp"
#include "riner/io.hpp"
#include "riner/scan_source.hpp"
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
    const riner::ArrayFile whole = riner::read_array(dir / "tooth.h5");
    CHECK(whole.array.data == t.projections.data);
    CHECK(whole.dtype == "uint16");  // as stored (read as float32; info said "float32")
    CHECK(white.dtype == "uint16");
  }

  TEST_CASE("a tomography file's own angles against the geometry's: a note where they differ") {
    // A 360-degree NXtomo scan under a 180-degree geometry reconstructed garbage without a word.
    const riner::Geometry half = riner::test::make_geometry(riner::GeometryType::kParallel2d, 360,
                                                            64, 1, {48, 48}, 1.0, 1.0, M_PI);
    std::vector<double> full(360), same(360), radians(360);
    for (std::size_t v = 0; v < 360; ++v) {
      full[v] = static_cast<double>(v);
      same[v] = 0.5 * static_cast<double>(v);
      radians[v] = same[v] * M_PI / 180.0;
    }
    CHECK(riner::file_angles_note("scan.nxs", full, half) ==
          "note: scan.nxs states angles spanning 359.0 degrees over its 360 views, the geometry "
          "179.5: riner takes the geometry's; check them");
    CHECK(riner::file_angles_note("scan.nxs", same, half).empty());
    CHECK(riner::file_angles_note("scan.nxs", radians, half).empty());
    CHECK(riner::file_angles_note("scan.nxs", {}, half).empty());
  }

  TEST_CASE("Data Exchange: one flat frame stored 2D, an empty dark dataset") {
    // Refused ("expected [frames, rows, columns]", "must be one frame ... or a stack"), though
    // --flat takes one 2D frame and a missing data_dark is none.
    riner::test::TempDir dir;
    const std::vector<std::uint16_t> flat = frames(1, 1, 0);
    {
      riner::test::Hdf5Writer w(dir / "scan.h5");
      w.write("/exchange/data", {6, kRows, kCols}, frames(0, 6, 0), H5T_STD_U16LE);
      w.write("/exchange/data_white", {kRows, kCols}, flat, H5T_STD_U16LE);
      w.write("/exchange/data_dark", {0, kRows, kCols}, std::vector<std::uint16_t>{},
              H5T_STD_U16LE);
    }
    const riner::TomoFile t = riner::read_tomo_file(dir / "scan.h5");
    CHECK(t.flats.shape == std::vector<std::size_t>{1, kRows, kCols});
    CHECK(t.flats.data == as_array(flat, 1).data);
    CHECK(t.darks.shape.empty());
    const riner::TomoFile two = riner::read_tomo_file(dir / "scan.h5", riner::RowRange{1, 2});
    CHECK(two.flats.shape == std::vector<std::size_t>{1, 2, kCols});
    CHECK(two.flats(0, 1, 5) == t.flats(0, 2, 5));
  }

  TEST_CASE("a saturated reading (65535 in uint16) is invalid, not a bright one") {
    // It read as rho = -2.8 in every view (more light than the flat's 4000 counts).
    riner::test::TempDir dir;
    std::vector<std::uint16_t> projections = frames(0, 6, 0);
    projections[2 * kFrame + 7] = 65535;
    {
      riner::test::Hdf5Writer w(dir / "scan.h5");
      w.write("/exchange/data", {6, kRows, kCols}, projections, H5T_STD_U16LE);
      w.write("/exchange/data_white", {3, kRows, kCols}, frames(1, 3, 0), H5T_STD_U16LE);
    }
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel3d, 6, kCols,
                                                         kRows, {kRows, 24, 24}, 1.0, 1.0, M_PI);
    riner::write_text(dir / "geometry.json", g.to_json());
    const riner::LoadedScan loaded =
        riner::load_scan_source({(dir / "scan.h5").string(), "", "", "", std::nullopt, "", ""});
    REQUIRE(loaded.flat_field);
    CHECK(loaded.flat_field->saturated_readings == 1);
    CHECK(std::isnan(loaded.scan.measurement.data[2 * kFrame + 7]));
    CHECK(riner::saturation_line(*loaded.flat_field).find("note: 1 readings at their type's") == 0);
    riner::Array floats({2}, std::vector<float>{65535.0f, 1.0f});
    CHECK(riner::mark_saturated(floats, "float32") == 0);  // no largest count to know
    CHECK(riner::mark_saturated(floats, "uint16") == 1);
  }

  TEST_CASE("riner's own HDF5 volume reads back by the file's name alone") {
    // fbp --out vol.h5 writes /volume; info, compare and read_array of vol.h5 said "holds
    // neither /exchange/data ...".
    riner::test::TempDir dir;
    riner::Array volume({3, 5, 4});
    for (std::size_t i = 0; i < volume.size(); ++i) volume.data[i] = 0.25f * static_cast<float>(i);
    {
      riner::test::Hdf5Writer w(dir / "vol.h5");
      w.write("/volume", {3, 5, 4}, volume.data, H5T_IEEE_F32LE);
    }
    const riner::ArrayFile f = riner::read_array(dir / "vol.h5");
    CHECK(f.array.shape == volume.shape);
    CHECK(f.array.data == volume.data);
    CHECK(f.dtype == "float32");
    CHECK(riner::read_array_shape(dir / "vol.h5") == volume.shape);
    CHECK(riner::read_array_rows(dir / "vol.h5", {1, 2}).array(2, 1, 3) == volume(2, 2, 3));
  }

  TEST_CASE("a field beside a tomography file replaces its own; a tomography file as a field") {
    // --flat beside a Data Exchange file dropped the file's darks (rho off by up to 0.3), and a
    // Data Exchange file given as --flat or --dark gave its projections as the field.
    riner::test::TempDir dir;
    const auto projections = frames(0, 6, 0), flats = frames(1, 3, 0), darks = frames(2, 2, 0),
               other_flats = frames(1, 2, 40), other_darks = frames(2, 5, 0);
    {
      riner::test::Hdf5Writer w(dir / "scan.h5");
      w.write("/exchange/data", {6, kRows, kCols}, projections, H5T_STD_U16LE);
      w.write("/exchange/data_white", {3, kRows, kCols}, flats, H5T_STD_U16LE);
      w.write("/exchange/data_dark", {2, kRows, kCols}, darks, H5T_STD_U16LE);
    }
    riner::write_array(dir / "projections.npy", as_array(projections, 6));
    riner::write_array(dir / "flats.npy", as_array(flats, 3));
    riner::write_array(dir / "darks.npy", as_array(darks, 2));
    riner::write_array(dir / "other_flats.npy", as_array(other_flats, 2));
    riner::write_array(dir / "other_darks.npy", as_array(other_darks, 5));
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel3d, 6, kCols,
                                                         kRows, {kRows, 24, 24}, 1.0, 1.0, M_PI);
    riner::write_text(dir / "geometry.json", g.to_json());
    const auto measured = [&](const std::string& scan, const std::string& flat,
                              const std::string& dark, const std::string& after = "") {
      riner::ScanSource source{(dir / scan).string(),
                               "",
                               flat.empty() ? "" : (dir / flat).string(),
                               dark.empty() ? "" : (dir / dark).string(),
                               std::nullopt,
                               "",
                               after.empty() ? "" : (dir / after).string()};
      return riner::load_scan_source(source).scan.measurement.data;
    };
    const auto expected = [&](const std::vector<std::uint16_t>& f, std::size_t n_flats,
                              const std::vector<std::uint16_t>& d, std::size_t n_darks) {
      return riner::raw_scan(g, as_array(projections, 6), as_array(f, n_flats),
                             as_array(d, n_darks), std::nullopt, "arrays")
          .measurement.data;
    };
    CHECK(measured("scan.h5", "", "") == expected(flats, 3, darks, 2));
    // A flat given beside the file: the file's darks stay.
    CHECK(measured("scan.h5", "other_flats.npy", "") == expected(other_flats, 2, darks, 2));
    // A dark given beside it replaces the file's, its flats stay.
    CHECK(measured("scan.h5", "", "other_darks.npy") == expected(flats, 3, other_darks, 5));
    // The file as the flat or the dark field of projections in another file: its own fields.
    CHECK(measured("projections.npy", "scan.h5", "scan.h5") == expected(flats, 3, darks, 2));
    CHECK(measured("projections.npy", "scan.h5", "darks.npy") == expected(flats, 3, darks, 2));
    // Flats after the scan beside the file add a second series to its own.
    const riner::FlatStack both =
        riner::flats_before_after(as_array(flats, 3), as_array(other_flats, 2), {6, kRows, kCols});
    CHECK(measured("scan.h5", "", "", "other_flats.npy") ==
          riner::raw_scan(g, as_array(projections, 6), both.frames, as_array(darks, 2),
                          std::nullopt, "arrays", nullptr, both.positions)
              .measurement.data);
    // The slab reader reads the same rows the same way.
    riner::ScanRows rows({(dir / "scan.h5").string(), "", (dir / "other_flats.npy").string(), "",
                          std::nullopt, "", ""});
    const riner::Scan two = rows.read({1, 2});
    const std::vector<float> whole = expected(other_flats, 2, darks, 2);
    CHECK(two.measurement(3, 1, 5) == whole[(3 * kRows + 2) * kCols + 5]);
    // A tomography file without that field, as the field: said so.
    {
      riner::test::Hdf5Writer w(dir / "no_dark.h5");
      w.write("/exchange/data", {6, kRows, kCols}, projections, H5T_STD_U16LE);
      w.write("/exchange/data_white", {3, kRows, kCols}, flats, H5T_STD_U16LE);
    }
    CHECK_THROWS_WITH_AS(measured("projections.npy", "flats.npy", "no_dark.h5"),
                         doctest::Contains("holds no dark field"), riner::InputError);
  }

  TEST_CASE("NXtomo entries where ESRF and Diamond put them; other frames left out") {
    // ESRF's nxtomomill writes /entry0000 and marks alignment frames by image_key_control -1
    // (image_key 0: they were read as projections); Diamond writes /entry1/tomo_entry. Neither
    // was found ("holds neither ...").
    riner::test::TempDir dir;
    const auto darks = frames(2, 2, 0), flats = frames(1, 2, 1), projections = frames(0, 5, 0),
               extra = frames(0, 2, 9);
    {
      riner::test::Hdf5Writer w(dir / "esrf.nxs");
      w.write("/entry0000/instrument/detector/data", {11, kRows, kCols},
              join({darks, flats, projections, extra}), H5T_STD_U16LE);
      w.write("/entry0000/instrument/detector/image_key", {11},
              std::vector<int>{2, 2, 1, 1, 0, 0, 0, 0, 0, 0, 3}, H5T_STD_I32LE);
      w.write("/entry0000/instrument/detector/image_key_control", {11},
              std::vector<int>{2, 2, 1, 1, 0, 0, 0, 0, 0, -1, 3}, H5T_STD_I32LE);
    }
    const riner::TomoFile esrf = riner::read_tomo_file(dir / "esrf.nxs");
    CHECK(esrf.projections.shape == std::vector<std::size_t>{5, kRows, kCols});
    CHECK(esrf.projections.data == as_array(projections, 5).data);
    CHECK(esrf.frames_left_out == 2);
    CHECK(riner::read_array_shape(dir / "esrf.nxs") == std::vector<std::size_t>{5, kRows, kCols});
    {
      riner::test::Hdf5Writer w(dir / "dls.nxs");
      w.write("/entry1/tomo_entry/data/data", {9, kRows, kCols}, join({darks, flats, projections}),
              H5T_STD_U16LE);
      w.write("/entry1/tomo_entry/instrument/detector/image_key", {9},
              std::vector<int>{2, 2, 1, 1, 0, 0, 0, 0, 0}, H5T_STD_I32LE);
    }
    const riner::TomoFile dls = riner::read_tomo_file(dir / "dls.nxs");
    CHECK(dls.flats.data == as_array(flats, 2).data);
    CHECK(dls.frames_left_out == 0);
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
    // Compressed by a filter this library lacks (bitshuffle on Eiger detectors): registered here
    // to write the file, gone when it is read. It read as "truncated or corrupt".
    {
      constexpr H5Z_filter_t kBitshuffle = 32008;
      const H5Z_class2_t identity{H5Z_CLASS_T_VERS,
                                  kBitshuffle,
                                  1,
                                  1,
                                  "bitshuffle",
                                  nullptr,
                                  nullptr,
                                  [](unsigned, std::size_t, const unsigned[], std::size_t bytes,
                                     std::size_t*, void**) { return bytes; }};
      REQUIRE(H5Zregister(&identity) >= 0);
      const hid_t file =
          H5Fcreate((dir / "plugin.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
      const hsize_t shape[3] = {2, kRows, kCols};
      const hid_t space = H5Screate_simple(3, shape, nullptr);
      const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
      H5Pset_chunk(plist, 3, shape);
      H5Pset_filter(plist, kBitshuffle, H5Z_FLAG_MANDATORY, 0, nullptr);
      const hid_t group = H5Gcreate2(file, "/exchange", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      const hid_t set =
          H5Dcreate2(file, "/exchange/data", H5T_STD_U16LE, space, H5P_DEFAULT, plist, H5P_DEFAULT);
      const std::vector<std::uint16_t> values = frames(0, 2, 0);
      REQUIRE(H5Dwrite(set, H5T_NATIVE_USHORT, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0);
      H5Dclose(set);
      H5Gclose(group);
      H5Pclose(plist);
      H5Sclose(space);
      H5Fclose(file);
      REQUIRE(H5Zunregister(kBitshuffle) >= 0);
    }
    CHECK(error_of(dir / "plugin.h5")
              .find("/exchange/data: is compressed with HDF5 filter 32008 "
                    "(bitshuffle), which this HDF5 library lacks") != std::string::npos);
  }
}
