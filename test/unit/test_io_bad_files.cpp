// Crafted broken files: each must give an InputError with a precise message, never a crash.
// ctest runs this suite again under valgrind (label "valgrind").
#include <doctest/doctest.h>

#include <tiffio.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/scan.hpp"
#include "support/crafted_files.hpp"
#include "support/fixture.hpp"

namespace {

using riner::test::append;

std::string floats(std::size_t n, float value = 1.0f) {
  std::string data;
  for (std::size_t i = 0; i < n; ++i) append<float>(data, value);
  return data;
}

// Reading `name` (written with `bytes`) fails with exactly `message` after the path prefix.
void expect_error(const riner::test::TempDir& dir, const std::string& name,
                  const std::string& bytes, const std::string& message) {
  const auto path = dir / name;
  riner::test::write_bytes(path, bytes);
  try {
    riner::read_array(path);
    FAIL("read a bad file without error: " << name);
  } catch (const riner::InputError& e) {
    CHECK(std::string(e.what()) == path.string() + ": " + message);
  }
}

}  // namespace

TEST_SUITE("io_bad_files") {
  TEST_CASE("missing, directory, unknown or output-only formats") {
    riner::test::TempDir dir;
    CHECK_THROWS_WITH_AS(riner::read_array(dir / "none.npy"),
                         ((dir / "none.npy").string() + ": no such file").c_str(),
                         riner::InputError);
    std::filesystem::create_directory(dir / "d.npy");
    CHECK_THROWS_WITH_AS(riner::read_array(dir / "d.npy"),
                         ((dir / "d.npy").string() +
                          ": is a folder without .tif/.tiff files (a folder reads as a stack of "
                          "TIFFs)")
                             .c_str(),
                         riner::InputError);
    CHECK_THROWS_AS(riner::read_array(dir / "x.dcm"), riner::InputError);
    CHECK_THROWS_AS(riner::read_array(dir / "x.nii.gz"), riner::InputError);
    CHECK_THROWS_AS(riner::read_array(dir / "x.png"), riner::InputError);
  }

  TEST_CASE("npy") {
    riner::test::TempDir dir;
    const std::string good = riner::test::make_npy("<f4", false, {4, 5}, floats(20));
    expect_error(dir, "empty.npy", "", "not a NumPy .npy file (bad magic)");
    expect_error(dir, "magic.npy", "\x93NUMPX" + good.substr(6),
                 "not a NumPy .npy file (bad magic)");
    expect_error(dir, "truncated.npy", good.substr(0, good.size() - 3),
                 "header says [4, 5] float32 (20 values) but the file holds 77 data bytes");
    expect_error(dir, "long.npy", good + "xxxx",
                 "header says [4, 5] float32 (20 values) but the file holds 84 data bytes");
    expect_error(dir, "header_cut.npy", good.substr(0, 40), "truncated header");
    expect_error(dir, "absurd.npy",
                 riner::test::make_npy("<f4", false, {4000000000, 4000000000}, floats(4)),
                 "header says [4000000000, 4000000000] float32 (16000000000000000000 values) but "
                 "the file holds 16 data bytes");
    expect_error(dir, "overflow.npy",
                 riner::test::make_npy("<f4", false, {999999999999, 999999999999}, floats(1)),
                 "array shape [999999999999, 999999999999] is too large");
    expect_error(dir, "complex.npy", riner::test::make_npy("<c8", false, {2}, floats(4)),
                 "unsupported dtype '<c8' (riner reads float32/64, int8/16/32, uint8/16/32)");
    // Found by fuzz_npy: an item size too long for an int once escaped as std::out_of_range.
    expect_error(dir, "long_descr.npy",
                 riner::test::make_npy(">u2888888888888888888888", false, {2}, floats(1)),
                 "header has no simple 'descr' (structured dtypes are not supported)");
    expect_error(dir, "scalar.npy", riner::test::make_npy("<f4", false, {}, floats(1)),
                 "holds a scalar, not an array");
    // A negative dimension was read as its digits ([4, 5] here).
    std::string negative = good;
    const std::size_t at = negative.find("(4, 5)");
    REQUIRE(at != std::string::npos);
    negative.replace(at, 6, "(-4,5)");
    expect_error(dir, "negative.npy", negative,
                 "header's shape (-4,5) is not a tuple of non-negative whole numbers");
    expect_error(dir, "version.npy", std::string("\x93NUMPY\x09\x00\x10\x00", 10) + good.substr(10),
                 "unsupported .npy version 9");
  }

  TEST_CASE("npy: garbage after the magic never crashes") {
    riner::test::TempDir dir;
    const std::string good = riner::test::make_npy("<f4", false, {3, 3}, floats(9));
    // Flip every header byte in turn; each file either reads or fails with InputError.
    for (std::size_t i = 6; i < 74; ++i) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ 0x5a);
      riner::test::write_bytes(dir / "flip.npy", bad);
      try {
        riner::read_array(dir / "flip.npy");
      } catch (const riner::InputError&) {
      }
    }
  }

  TEST_CASE("nifti") {
    riner::test::TempDir dir;
    const std::string good = riner::test::make_nifti({4, 5}, 16, 32, 1.0f, 0.0f, floats(20));
    expect_error(dir, "short.nii", good.substr(0, 100),
                 "too short for a NIfTI-1 header (100 bytes)");
    std::string bad_size = good;
    bad_size[0] = 7;
    expect_error(dir, "size.nii", bad_size, "not a NIfTI-1 file (sizeof_hdr is not 348)");
    std::string bad_magic = good;
    bad_magic[345] = 'x';
    expect_error(dir, "magic.nii", bad_magic, "not a NIfTI-1 file (bad magic)");
    expect_error(dir, "truncated.nii", good.substr(0, good.size() - 8),
                 "header says [5, 4] float32 but the file holds only 72 data bytes");
    expect_error(dir, "absurd.nii",
                 riner::test::make_nifti({30000, 30000, 30000}, 16, 32, 1, 0, floats(4)),
                 "header says [30000, 30000, 30000] float32 but the file holds only 16 data bytes");
    expect_error(dir, "negative.nii", riner::test::make_nifti({4, -5}, 16, 32, 1, 0, floats(20)),
                 "dim[2] = -5 is not positive");
    expect_error(dir, "rank.nii",
                 riner::test::make_nifti({4, 5, 1, 1, 1, 1, 1, 1}, 16, 32, 1, 0, floats(20)),
                 "dim[0] = 8 is not in 1..7");
    expect_error(dir, "type.nii", riner::test::make_nifti({4, 5}, 32, 64, 1, 0, floats(40)),
                 "unsupported NIfTI datatype code 32");
    // Found by fuzz_nifti: vox_offset 0 means 352, beyond a file that ends inside 348..351.
    std::string no_data = good.substr(0, 350);
    no_data.replace(108, 4, std::string(4, '\0'));
    expect_error(dir, "no_data.nii", no_data,
                 "ends at byte 350, before its data starts at byte 352");
  }

  TEST_CASE("tiff") {
    riner::test::TempDir dir;
    expect_error(dir, "empty.tif", "", "not a readable TIFF file (Cannot read TIFF header)");
    expect_error(dir, "text.tif", "this is not a tiff file at all",
                 "not a readable TIFF file (Not a TIFF or MDI file, bad magic number 26740 "
                 "(0x6874))");
    // A valid float TIFF cut in the middle of its pixel data.
    riner::write_array(dir / "good.tif", riner::Array({64, 64}, 2.0f));
    const std::string good = riner::test::read_bytes(dir / "good.tif");
    riner::test::write_bytes(dir / "cut.tif", good.substr(0, good.size() / 2));
    CHECK_THROWS_AS(riner::read_array(dir / "cut.tif"), riner::InputError);
    // Random corruption anywhere: read or InputError, never a crash.
    for (std::size_t i = 0; i < good.size(); i += 97) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ 0xff);
      riner::test::write_bytes(dir / "flip.tif", bad);
      try {
        riner::read_array(dir / "flip.tif");
      } catch (const riner::InputError&) {
      }
    }
  }

  TEST_CASE("raw sidecars") {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "a.raw", floats(6));
    const auto sidecar = (dir / "a.raw.json").string();
    CHECK_THROWS_WITH_AS(riner::read_array(dir / "a.raw"), (sidecar + ": no such file").c_str(),
                         riner::InputError);
    auto expect_sidecar = [&](const std::string& json, const std::string& message) {
      riner::test::write_bytes(dir / "a.raw.json", json);
      try {
        riner::read_array(dir / "a.raw");
        FAIL("accepted sidecar " << json);
      } catch (const riner::InputError& e) {
        CHECK(std::string(e.what()) == message);
      }
    };
    expect_sidecar(R"({"shape": [2, 3]})", sidecar + ": needs \"dtype\" (string)");
    expect_sidecar(R"({"dtype": "float16", "shape": [2, 3]})",
                   sidecar + ": unsupported dtype \"float16\"");
    expect_sidecar(R"({"dtype": "float32", "shape": [2, 0]})",
                   sidecar + ": \"shape\" entries must be positive integers");
    expect_sidecar(R"({"dtype": "float32", "shape": [3, 3]})",
                   (dir / "a.raw").string() +
                       ": sidecar says [3, 3] float32 from byte 0 but the file has 24 bytes");
    expect_sidecar(R"({"dtype": "float32", "shape": [2, 3], "byte_order": "middle"})",
                   sidecar + ": \"byte_order\" must be little or big");
    // Found by fuzz_raw: a non-string "order" escaped as nlohmann's type_error.
    expect_sidecar(R"({"dtype": "float32", "shape": [2, 3], "order": 8})",
                   sidecar + ": \"order\" must be a string");
    expect_sidecar(R"({"dtype": "float32", "shape": [2, 3], "byte_order": null})",
                   sidecar + ": \"byte_order\" must be a string");
    // A file longer than described (uint16 samples declared uint8 were read as 24 bytes of
    // noise), and a misspelt key (byte-swapped samples read without a word).
    expect_sidecar(R"({"dtype": "uint8", "shape": [2, 3]})",
                   (dir / "a.raw").string() +
                       ": sidecar says [2, 3] uint8 from byte 0 (6 bytes) but the file has 24: "
                       "check dtype and shape (a footer after the samples: \"trailing_bytes\")");
    expect_sidecar(R"({"dtype": "float32", "shape": [2, 3], "endian": "big"})",
                   sidecar +
                       ": unknown key \"endian\" (a sidecar takes dtype, shape, byte_order, "
                       "order, offset_bytes, trailing_bytes, voxel_size_mm; comments as "
                       "comment, description, notes or a key starting with _)");
    riner::test::write_bytes(dir / "a.raw.json",
                             R"({"dtype": "float32", "shape": [2, 2], "trailing_bytes": 8,
                                 "comment": "a footer of 8 bytes"})");
    CHECK(riner::read_array(dir / "a.raw").array.shape == std::vector<std::size_t>{2, 2});
  }

  TEST_CASE("a NaN-filled measurement is refused as a scan") {
    riner::test::TempDir dir;
    riner::write_array(dir / "sino.npy", riner::Array({3, 4}, NAN));
    riner::test::write_bytes(dir / "geometry.json", R"({"type": "parallel2d",
      "detector": {"count": 4, "pitch_mm": 1.0}, "angles": {"count": 3, "range_rad": 3.14159},
      "volume": {"shape": [4, 4], "voxel_mm": 1.0}})");
    CHECK_THROWS_WITH_AS(riner::load_scan(dir / "sino.npy"),
                         ((dir / "sino.npy").string() +
                          ": all 12 values are NaN or infinite; there is nothing to reconstruct")
                             .c_str(),
                         riner::InputError);
    riner::write_array(dir / "short.npy", riner::Array({2, 4}, 1.0f));
    CHECK_THROWS_AS(riner::load_scan(dir / "short.npy", dir / "geometry.json"), riner::InputError);
    riner::write_array(dir / "ok.npy", riner::Array({3, 4}, 1.0f));
    const riner::Scan scan = riner::load_scan(dir / "ok.npy");
    CHECK(scan.geometry.n_u == 4);
  }

  TEST_CASE("transmissions I/I0 given as the measurement get a note; their logarithm none") {
    riner::Geometry g;
    g.type = riner::GeometryType::kParallel2d;
    g.n_u = 40;
    g.angles.assign(30, 0.0);
    for (std::size_t v = 0; v < 30; ++v) g.angles[v] = M_PI * static_cast<double>(v) / 30.0;
    g.volume_shape = {40, 40};
    // A disc's chords over columns 5-34, air beside it.
    riner::Scan rho{riner::Array({30, 40}), g, 0};
    for (std::size_t i = 0; i < rho.measurement.size(); ++i) {
      const double x = (static_cast<double>(i % 40) - 19.5) / 15.0;
      rho.measurement.data[i] =
          static_cast<float>(x * x < 1.0 ? 1.5 * std::sqrt(1.0 - x * x) : 0.0);
    }
    CHECK_FALSE(riner::transmission_note(rho).has_value());
    riner::Scan transmission = rho;
    for (float& v : transmission.measurement.data) v = std::exp(-v);
    const std::optional<std::string> note = riner::transmission_note(transmission);
    REQUIRE(note.has_value());
    CHECK(note->find("note: the readings look like transmissions I/I0, not -ln(I/I0): all within "
                     "0.") == 0);
    CHECK(note->find("the detector's outer columns at 1.00") != std::string::npos);
    // A faint object whose transmissions stay above 0.6 of the air's: no object far below the
    // air, no note (nor for a scan of readings near 1 everywhere).
    riner::Scan faint = rho;
    for (float& v : faint.measurement.data) v = std::exp(-0.2f * v);
    CHECK_FALSE(riner::transmission_note(faint).has_value());
  }

  TEST_CASE("raw intensities, or readings nearly all beyond 1e6, are refused as a scan") {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "geometry.json", R"({"type": "parallel2d",
      "detector": {"count": 40, "pitch_mm": 1.0}, "angles": {"count": 30, "range_rad": 3.14159},
      "volume": {"shape": [40, 40], "voxel_mm": 1.0}})");
    // Counts of a 16-bit detector: 2000 behind the object, 60000 in the beam.
    riner::Array counts({30, 40});
    for (std::size_t i = 0; i < counts.size(); ++i) {
      counts.data[i] = i % 40 < 5 || i % 40 >= 35 ? 60000.0f : 2000.0f + 10.0f * (i % 40);
    }
    riner::write_array(dir / "counts.npy", counts);
    CHECK_THROWS_WITH_AS(
        riner::load_scan(dir / "counts.npy"),
        ((dir / "counts.npy").string() +
         ": 99% of the readings exceed 20 (the 1st percentile: 2050), beyond any line integral "
         "-ln(I/I0): these look like raw intensities; give their flat field (--flat and --dark) "
         "or take -ln(I/I0) first")
            .c_str(),
        riner::InputError);
    // Their logarithm passes, and so do large line integrals beside air (a dense object).
    riner::Array rho = counts;
    for (float& v : rho.data) v = std::log(60000.0f / v);
    riner::write_array(dir / "rho.npy", rho);
    CHECK_NOTHROW(riner::load_scan(dir / "rho.npy"));
    riner::Array dense = rho;
    for (float& v : dense.data) v *= 5.0f;  // 16-17 on the object, beyond a 16-bit detector's 11
    riner::write_array(dir / "dense.npy", dense);
    CHECK_NOTHROW(riner::load_scan(dir / "dense.npy"));
    // Dead elements read 0 counts: a few dead columns do not hide the intensities.
    for (std::size_t i = 0; i < counts.size(); i += 40) counts.data[i + 20] = 0.0f;
    riner::write_array(dir / "dead.npy", counts);
    CHECK_THROWS_WITH_AS(riner::load_scan(dir / "dead.npy"),
                         doctest::Contains("dead.npy: 99% of the readings exceed 20 (the 1st "
                                           "percentile: 2050)"),
                         riner::InputError);
    // 95% of the readings corrupt (1e30): FBP would interpolate an image from the rest.
    riner::Array corrupt = rho;
    for (std::size_t i = 0; i < corrupt.size(); ++i) {
      if (i % 20 != 0) corrupt.data[i] = 1e30f;
    }
    riner::write_array(dir / "corrupt.npy", corrupt);
    CHECK_THROWS_WITH_AS(riner::load_scan(dir / "corrupt.npy"),
                         ((dir / "corrupt.npy").string() +
                          ": 95.0% of the readings are NaN, infinite or beyond 1e+06: there is "
                          "too little left to reconstruct")
                             .c_str(),
                         riner::InputError);
  }
}
