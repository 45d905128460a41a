// Every format and sample type: write (or craft) then read, values identical.
#include <doctest/doctest.h>
#include <tiffio.h>

#include <cmath>
#include <random>

#include "io/stack.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "support/crafted_files.hpp"
#include "support/fixture.hpp"

namespace {

using riner::Array;
using riner::test::append;

Array random_array(std::vector<std::size_t> shape, std::uint64_t salt) {
  std::mt19937_64 rng(riner::test::seed() + salt);
  std::normal_distribution<float> normal(0.0f, 3.0f);
  Array a(std::move(shape));
  for (float& v : a.data) v = normal(rng);
  return a;
}

// Writes through riner and reads back.
void check_roundtrip(const std::filesystem::path& path, const Array& a) {
  riner::write_array(path, a);
  const riner::ArrayFile f = riner::read_array(path);
  CHECK(f.array.shape == a.shape);
  CHECK(f.array.data == a.data);
  CHECK(f.dtype == "float32");
  CHECK(f.non_finite == 0);
}

void write_tiff_u16(const std::filesystem::path& path, std::size_t pages, std::size_t rows,
                    std::size_t cols, int bits, std::uint32_t rows_per_strip = 0) {
  TIFF* tif = TIFFOpen(path.c_str(), "w");
  REQUIRE(tif != nullptr);
  std::vector<unsigned char> row(cols * bits / 8);
  for (std::size_t p = 0; p < pages; ++p) {
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<uint32_t>(cols));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<uint32_t>(rows));
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_LZW);
    if (rows_per_strip > 0) TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, rows_per_strip);
    for (std::size_t y = 0; y < rows; ++y) {
      for (std::size_t x = 0; x < cols; ++x) {
        const unsigned v =
            static_cast<unsigned>((p * 1000 + y * 10 + x) % (bits == 8 ? 256 : 65536));
        if (bits == 8) {
          row[x] = static_cast<unsigned char>(v);
        } else {
          const std::uint16_t v16 = static_cast<std::uint16_t>(v);
          std::memcpy(&row[2 * x], &v16, 2);
        }
      }
      REQUIRE(TIFFWriteScanline(tif, row.data(), static_cast<uint32_t>(y), 0) >= 0);
    }
    TIFFWriteDirectory(tif);
  }
  TIFFClose(tif);
}

}  // namespace

TEST_SUITE("io_roundtrip") {
  TEST_CASE("float32 through every writable format, 2D non-square and 3D") {
    riner::test::TempDir dir;
    const Array flat = random_array({37, 53}, 1);
    const Array stack = random_array({5, 11, 7}, 2);
    for (const char* ext : {".npy", ".nii", ".tif", ".raw"}) {
      CAPTURE(ext);
      check_roundtrip(dir / (std::string("flat") + ext), flat);
      check_roundtrip(dir / (std::string("stack") + ext), stack);
    }
  }

  TEST_CASE("non-finite values survive and are counted") {
    riner::test::TempDir dir;
    Array a({2, 3}, std::vector<float>{1, NAN, INFINITY, -INFINITY, 0, 2});
    for (const char* ext : {".npy", ".nii", ".tif", ".raw"}) {
      riner::write_array(dir / (std::string("x") + ext), a);
      const riner::ArrayFile f = riner::read_array(dir / (std::string("x") + ext));
      CHECK(f.non_finite == 3);
      CHECK(std::isnan(f.array.data[1]));
      CHECK(f.array.data[2] == INFINITY);
      CHECK(f.array.data[3] == -INFINITY);
    }
  }

  TEST_CASE("npy: every dtype, both byte orders, C and Fortran order") {
    riner::test::TempDir dir;
    // Values 0..5 in a [2, 3] array; Fortran order stores columns first.
    const std::vector<float> c_order{0, 1, 2, 3, 4, 5};
    const std::vector<int> fortran_sequence{0, 3, 1, 4, 2, 5};
    struct Case {
      const char* descr;
      const char* dtype;
    };
    for (const Case& c : {Case{"<f4", "float32"}, Case{">f4", "float32"}, Case{"<f8", "float64"},
                          Case{">f8", "float64"}, Case{"<u2", "uint16"}, Case{">u2", "uint16"},
                          Case{"<i2", "int16"}, Case{">i2", "int16"}, Case{"|u1", "uint8"},
                          Case{"<i4", "int32"}, Case{">u4", "uint32"}}) {
      for (bool fortran : {false, true}) {
        CAPTURE(c.descr);
        CAPTURE(fortran);
        const bool big = c.descr[0] == '>';
        std::string data;
        for (int k = 0; k < 6; ++k) {
          const int v = fortran ? fortran_sequence[k] : k;
          const std::string d = c.dtype;
          if (d == "float32") append<float>(data, static_cast<float>(v), big);
          if (d == "float64") append<double>(data, v, big);
          if (d == "uint16") append<std::uint16_t>(data, static_cast<std::uint16_t>(v), big);
          if (d == "int16") append<std::int16_t>(data, static_cast<std::int16_t>(-v), big);
          if (d == "uint8") append<std::uint8_t>(data, static_cast<std::uint8_t>(v), big);
          if (d == "int32") append<std::int32_t>(data, -v, big);
          if (d == "uint32") append<std::uint32_t>(data, static_cast<std::uint32_t>(v), big);
        }
        const auto path = dir / "crafted.npy";
        std::filesystem::remove(path);
        riner::test::write_bytes(path, riner::test::make_npy(c.descr, fortran, {2, 3}, data));
        const riner::ArrayFile f = riner::read_array(path);
        CHECK(f.dtype == c.dtype);
        CHECK(f.array.shape == std::vector<std::size_t>{2, 3});
        const bool negated = std::string(c.dtype) == "int16" || std::string(c.dtype) == "int32";
        for (int k = 0; k < 6; ++k) CHECK(f.array.data[k] == (negated ? -c_order[k] : c_order[k]));
      }
    }
  }

  TEST_CASE("npy: Fortran order in 3D") {
    riner::test::TempDir dir;
    // shape [2, 3, 4]; value at (i, j, k) = 100 i + 10 j + k; Fortran stores i fastest.
    std::string data;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 2; ++i) append<float>(data, static_cast<float>(100 * i + 10 * j + k));
    riner::test::write_bytes(dir / "f.npy", riner::test::make_npy("<f4", true, {2, 3, 4}, data));
    const riner::ArrayFile f = riner::read_array(dir / "f.npy");
    for (std::size_t i = 0; i < 2; ++i)
      for (std::size_t j = 0; j < 3; ++j)
        for (std::size_t k = 0; k < 4; ++k) CHECK(f.array(i, j, k) == 100.0f * i + 10.0f * j + k);
  }

  TEST_CASE("nifti: integer types with scl_slope/scl_inter, float64, big-endian, voxel size") {
    riner::test::TempDir dir;
    std::string i16;
    for (int k = 0; k < 6; ++k) append<std::int16_t>(i16, static_cast<std::int16_t>(k - 2));
    // dims in file order: nx = 3, ny = 2 -> array [2, 3]
    riner::test::write_bytes(dir / "a.nii",
                             riner::test::make_nifti({3, 2}, 4, 16, 0.5f, 10.0f, i16));
    riner::ArrayFile f = riner::read_array(dir / "a.nii");
    CHECK(f.dtype == "int16");
    CHECK(f.array.shape == std::vector<std::size_t>{2, 3});
    for (int k = 0; k < 6; ++k) CHECK(f.array.data[k] == doctest::Approx((k - 2) * 0.5 + 10.0));
    // pixdim[1] = 1.0 (x), pixdim[2] = 1.5 (y): array order reverses them.
    CHECK(f.voxel_size == std::vector<double>{1.5, 1.0});

    std::string u16;
    for (int k = 0; k < 8; ++k)
      append<std::uint16_t>(u16, static_cast<std::uint16_t>(60000 + k), true);
    riner::test::write_bytes(dir / "b.nii",
                             riner::test::make_nifti({2, 2, 2}, 512, 16, 0.0f, 0.0f, u16, true));
    f = riner::read_array(dir / "b.nii");
    CHECK(f.dtype == "uint16");
    CHECK(f.array.shape == std::vector<std::size_t>{2, 2, 2});
    for (int k = 0; k < 8; ++k) CHECK(f.array.data[k] == 60000.0f + k);

    std::string u8;
    std::string f64;
    for (int k = 0; k < 4; ++k) {
      append<std::uint8_t>(u8, static_cast<std::uint8_t>(250 + k));
      append<double>(f64, 0.25 * k);
    }
    riner::test::write_bytes(dir / "c.nii", riner::test::make_nifti({4}, 2, 8, NAN, NAN, u8));
    f = riner::read_array(dir / "c.nii");
    CHECK(f.array.data == std::vector<float>{250, 251, 252, 253});
    riner::test::write_bytes(dir / "d.nii",
                             riner::test::make_nifti({2, 2, 1}, 64, 64, 1.0f, 0.0f, f64));
    f = riner::read_array(dir / "d.nii");
    CHECK(f.array.shape == std::vector<std::size_t>{2, 2});  // trailing singleton dropped
    CHECK(f.array.data == std::vector<float>{0.0f, 0.25f, 0.5f, 0.75f});
  }

  TEST_CASE("nifti: the written header states the voxel size") {
    riner::test::TempDir dir;
    const Array a = random_array({4, 6}, 3);
    riner::write_array(dir / "v.nii", a, {{0.5, 2.0}});
    const riner::ArrayFile f = riner::read_array(dir / "v.nii");
    CHECK(f.voxel_size == std::vector<double>{0.5, 2.0});
  }

  TEST_CASE("tiff and raw: the written voxel size reads back (Fiji's resolution, the sidecar)") {
    // Before: a TIFF or raw image, slice or volume said nothing of its size; Fiji measured in
    // pixels. TIFF holds the pixels per centimetre (float), so sizes come back within 1e-6.
    riner::test::TempDir dir;
    const Array image = random_array({4, 6}, 4), volume = random_array({3, 4, 6}, 5);
    riner::write_array(dir / "v.tif", image, {{0.125, 0.125}});
    riner::ArrayFile f = riner::read_array(dir / "v.tif");
    REQUIRE(f.voxel_size.size() == 2);
    CHECK(f.voxel_size[0] == doctest::Approx(0.125).epsilon(1e-6));
    CHECK(f.voxel_size[1] == doctest::Approx(0.125).epsilon(1e-6));
    CHECK(f.array.data == image.data);
    // Written into every page of a stack, whose spacing no tag holds: not claimed on reading.
    riner::write_array(dir / "s.tif", volume, {{0.02, 0.02, 0.02}});
    {
      TIFF* tif = TIFFOpen((dir / "s.tif").c_str(), "r");
      REQUIRE(tif);
      int pages_with_size = 0;
      do {
        float x = 0.0f;
        uint16_t unit = 0;
        pages_with_size += TIFFGetField(tif, TIFFTAG_XRESOLUTION, &x) &&
                           TIFFGetField(tif, TIFFTAG_RESOLUTIONUNIT, &unit) &&
                           unit == RESUNIT_CENTIMETER && std::fabs(x - 500.0f) < 1e-3f;
      } while (TIFFReadDirectory(tif));
      TIFFClose(tif);
      CHECK(pages_with_size == 3);
    }
    CHECK(riner::read_array(dir / "s.tif").voxel_size.empty());
    riner::write_array(dir / "n.tif", image);
    CHECK(riner::read_array(dir / "n.tif").voxel_size.empty());

    riner::write_array(dir / "v.raw", volume, {{0.5, 0.25, 0.25}});
    f = riner::read_array(dir / "v.raw");
    CHECK(f.voxel_size == std::vector<double>{0.5, 0.25, 0.25});
    CHECK(f.array.data == volume.data);
    riner::test::write_bytes(
        dir / "v.raw.json", R"({"dtype": "float32", "shape": [3, 4, 6], "voxel_size_mm": [1, 0]})");
    CHECK_THROWS_WITH_AS(riner::read_array(dir / "v.raw"),
                         ((dir / "v.raw.json").string() +
                          ": \"voxel_size_mm\" must be a positive size in mm per axis of \"shape\"")
                             .c_str(),
                         riner::InputError);
  }

  TEST_CASE("tiff: uint16 and uint8, compressed, single and multi-page") {
    riner::test::TempDir dir;
    write_tiff_u16(dir / "one.tif", 1, 9, 13, 16);
    riner::ArrayFile f = riner::read_array(dir / "one.tif");
    CHECK(f.dtype == "uint16");
    CHECK(f.array.shape == std::vector<std::size_t>{9, 13});
    CHECK(f.array(8, 12) == 8 * 10 + 12);
    write_tiff_u16(dir / "many.tiff", 3, 4, 5, 8);
    f = riner::read_array(dir / "many.tiff");
    CHECK(f.dtype == "uint8");
    CHECK(f.array.shape == std::vector<std::size_t>{3, 4, 5});
    CHECK(f.array(2, 3, 4) == static_cast<float>((2000 + 34) % 256));
  }

  TEST_CASE("tiff: rows from inside a compressed strip, as a slab reads them") {
    // LZW cannot start decoding at a row inside a strip: rows 3..6 of a one-strip image failed
    // with "Compression algorithm does not support random access" (every slab path).
    riner::test::TempDir dir;
    for (std::uint32_t per_strip : {0u, 4u, 1u}) {
      CAPTURE(per_strip);
      const auto path = dir / ("strips" + std::to_string(per_strip) + ".tif");
      write_tiff_u16(path, 3, 10, 12, 16, per_strip);
      for (const riner::RowRange rows : {riner::RowRange{3, 4}, riner::RowRange{9, 1},
                                         riner::RowRange{0, 10}, riner::RowRange{5, 1}}) {
        CAPTURE(rows.first);
        const riner::ArrayFile f = riner::read_array_rows(path, rows);
        REQUIRE(f.array.shape == std::vector<std::size_t>{3, rows.count, 12});
        bool same = true;
        for (std::size_t p = 0; p < 3; ++p) {
          for (std::size_t y = 0; y < rows.count; ++y) {
            for (std::size_t x = 0; x < 12; ++x) {
              same = same && f.array(p, y, x) == static_cast<float>(p * 1000 + (rows.first + y) * 10 + x);
            }
          }
        }
        CHECK(same);
      }
    }
  }

  TEST_CASE("raw: sidecar with big-endian uint16 in Fortran order and an offset") {
    riner::test::TempDir dir;
    std::string data = "HEADER";
    for (int v : {0, 3, 1, 4, 2, 5})
      append<std::uint16_t>(data, static_cast<std::uint16_t>(v), true);
    riner::test::write_bytes(dir / "scan.raw", data);
    riner::test::write_bytes(dir / "scan.raw.json",
                             R"({"dtype": "uint16", "shape": [2, 3], "byte_order": "big",
                                 "offset_bytes": 6, "order": "F"})");
    const riner::ArrayFile f = riner::read_array(dir / "scan.raw");
    CHECK(f.array.data == std::vector<float>{0, 1, 2, 3, 4, 5});
  }

  TEST_CASE("shared real data reads with the stated shapes and non-finite counts") {
    struct Expect {
      const char* path;
      std::vector<std::size_t> shape;
      std::size_t non_finite;
    };
    for (const Expect& e : {Expect{"neutron360/sino.npy", {459, 503}, 214},
                            Expect{"neutron360/sinogram_360_neutron_image.tif", {459, 503}, 0},
                            Expect{"deeplesion/slice_0.nii", {256, 256}, 0},
                            Expect{"head_volume/head_mu.npy", {93, 64, 64}, 0},
                            Expect{"savu_proj3d/tiffs/raw_00000.tiff", {135, 160}, 0}}) {
      const auto path = riner::test::shared_data(e.path);
      if (path.empty()) continue;
      CAPTURE(e.path);
      const riner::ArrayFile f = riner::read_array(path);
      CHECK(f.array.shape == e.shape);
      CHECK(f.non_finite == e.non_finite);
    }
  }
}

TEST_SUITE("image stacks") {
  TEST_CASE("natural order: digit runs compare as numbers") {
    CHECK(riner::io::natural_less("raw_2.tif", "raw_10.tif"));
    CHECK_FALSE(riner::io::natural_less("raw_10.tif", "raw_2.tif"));
    CHECK(riner::io::natural_less("raw_00009.tif", "raw_00010.tif"));
    CHECK(riner::io::natural_less("a.tif", "b.tif"));
    CHECK(riner::io::natural_less("raw_9.tif", "raw_9b.tif"));
  }

  TEST_CASE("a folder or a pattern of 2D TIFFs reads as [files, rows, cols] in natural order") {
    riner::test::TempDir dir;
    std::filesystem::create_directory(dir / "tiffs");
    for (int i : {10, 2, 1}) {
      riner::write_array(dir / "tiffs" / ("raw_" + std::to_string(i) + ".tif"),
                         Array({2, 3}, static_cast<float>(i)));
    }
    riner::write_array(dir / "tiffs" / "flat_1.tif", Array({2, 3}, 100.0f));
    const riner::ArrayFile pattern = riner::read_array(dir / "tiffs" / "raw_*.tif");
    REQUIRE(pattern.array.shape == std::vector<std::size_t>{3, 2, 3});
    CHECK(pattern.array(0, 0, 0) == 1.0f);
    CHECK(pattern.array(1, 1, 2) == 2.0f);
    CHECK(pattern.array(2, 0, 1) == 10.0f);
    const riner::ArrayFile folder = riner::read_array(dir / "tiffs");
    CHECK(folder.array.shape == std::vector<std::size_t>{4, 2, 3});  // flat_1 comes first
    CHECK(folder.array(0, 0, 0) == 100.0f);
  }

  TEST_CASE("stacks refuse empty matches and frames of another shape, naming the file") {
    riner::test::TempDir dir;
    auto message = [](const std::filesystem::path& p) -> std::string {
      try {
        riner::read_array(p);
      } catch (const riner::InputError& e) {
        return e.what();
      }
      return "accepted";
    };
    CHECK(message(dir.path()).find("is a folder without .tif/.tiff files") != std::string::npos);
    CHECK(message(dir / "raw_*.tif").find("no file matches the pattern") != std::string::npos);
    riner::write_array(dir / "raw_1.tif", Array({2, 3}, 1.0f));
    riner::write_array(dir / "raw_2.tif", Array({3, 3}, 1.0f));
    const std::string m = message(dir / "raw_*.tif");
    CHECK(m.find("raw_2.tif: is [3, 3] where raw_1.tif is [2, 3]") != std::string::npos);
    // Frames of another sample type: line integrals beside raw counts.
    riner::write_array(dir / "mixed_1.npy", Array({2, 3}, 1.0f));
    std::string counts;
    for (int k = 0; k < 6; ++k) riner::test::append<std::uint16_t>(counts, 1000);
    riner::test::write_bytes(dir / "mixed_2.npy",
                             riner::test::make_npy("<u2", false, {2, 3}, counts));
    CHECK(message(dir / "mixed_*.npy")
              .find("mixed_2.npy: holds uint16 samples where mixed_1.npy "
                    "holds float32") != std::string::npos);
  }
}
