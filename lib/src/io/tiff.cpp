// TIFF through libtiff: each page is a 2D image; several pages stack into [pages, rows, cols].
#include <tiffio.h>

#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/row_blocks.hpp"
#include "io/sample_type.hpp"
#include "riner/error.hpp"

namespace riner::io {

namespace {

// libtiff reports through global handlers; keep the first error of this thread's current call.
thread_local std::string t_tiff_error;

void capture_error(const char* module, const char* fmt, va_list args) {
  if (!t_tiff_error.empty()) return;
  char buffer[512];
  std::vsnprintf(buffer, sizeof(buffer), fmt, args);
  (void)module;  // libtiff passes the file name, which our messages already start with
  t_tiff_error = buffer;
}

void ignore_warning(const char*, const char*, va_list) {}

void install_handlers() {
  static const bool installed = [] {
    TIFFSetErrorHandler(capture_error);
    TIFFSetWarningHandler(ignore_warning);
    return true;
  }();
  (void)installed;
}

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};
using TiffPtr = std::unique_ptr<TIFF, TiffCloser>;

SampleType page_type(TIFF* tif, const std::filesystem::path& path) {
  uint16_t bits = 0;
  uint16_t format = SAMPLEFORMAT_UINT;
  uint16_t samples = 1;
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
  if (samples != 1) {
    throw InputError(prefix(path) + "has " + std::to_string(samples) +
                     " samples per pixel; riner reads single-channel images");
  }
  if (format == SAMPLEFORMAT_IEEEFP && bits == 32) return SampleType::kFloat32;
  if (format == SAMPLEFORMAT_IEEEFP && bits == 64) return SampleType::kFloat64;
  if (format == SAMPLEFORMAT_UINT && bits == 8) return SampleType::kUint8;
  if (format == SAMPLEFORMAT_UINT && bits == 16) return SampleType::kUint16;
  if (format == SAMPLEFORMAT_UINT && bits == 32) return SampleType::kUint32;
  if (format == SAMPLEFORMAT_INT && bits == 16) return SampleType::kInt16;
  if (format == SAMPLEFORMAT_INT && bits == 32) return SampleType::kInt32;
  throw InputError(prefix(path) + "unsupported TIFF sample type (" + std::to_string(bits) +
                   " bits, format " + std::to_string(format) + ")");
}

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  std::string detail = t_tiff_error.empty() ? what : what + " (" + t_tiff_error + ")";
  throw InputError(prefix(path) + detail);
}

// Reads rows [y0, y1) of one page, cols samples each, into out (host-order bytes, as libtiff
// delivers them): the tiles or strips that hold them, decoded whole.
void read_page(TIFF* tif, std::size_t y0, std::size_t y1, std::size_t cols, std::size_t item,
               unsigned char* out, const std::filesystem::path& path) {
  if (TIFFIsTiled(tif)) {
    uint32_t tile_w = 0;
    uint32_t tile_h = 0;
    TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_w);
    TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_h);
    if (tile_w == 0 || tile_h == 0) fail(path, "tiled TIFF without tile size");
    std::vector<unsigned char> tile(TIFFTileSize(tif));
    for (std::size_t ty = y0 - y0 % tile_h; ty < y1; ty += tile_h) {
      for (uint32_t x0 = 0; x0 < cols; x0 += tile_w) {
        if (TIFFReadTile(tif, tile.data(), x0, static_cast<uint32_t>(ty), 0, 0) < 0)
          fail(path, "corrupt tile data");
        for (std::size_t y = std::max(ty, y0); y < std::min<std::size_t>(y1, ty + tile_h); ++y) {
          const std::size_t n = std::min<std::size_t>(cols - x0, tile_w);
          std::memcpy(out + ((y - y0) * cols + x0) * item, tile.data() + (y - ty) * tile_w * item,
                      n * item);
        }
      }
    }
    return;
  }
  if (static_cast<std::size_t>(TIFFScanlineSize(tif)) != cols * item) {
    fail(path, "scanline size does not match width x sample size");
  }
  // Whole strips: LZW and Deflate cannot start a strip's decoding at a row inside it (libtiff:
  // "Compression algorithm does not support random access"), and most writers put a whole
  // image in one strip.
  uint32_t rows_per_strip = 0;
  if (!TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows_per_strip) || rows_per_strip == 0) {
    fail(path, "TIFF without rows per strip");
  }
  const std::size_t per_strip = std::min<std::size_t>(rows_per_strip, y1);
  std::vector<unsigned char> strip(per_strip * cols * item);
  for (std::size_t first = y0 - y0 % per_strip; first < y1; first += per_strip) {
    const auto index = TIFFComputeStrip(tif, static_cast<uint32_t>(first), 0);
    const tmsize_t got =
        TIFFReadEncodedStrip(tif, index, strip.data(), static_cast<tmsize_t>(strip.size()));
    const std::size_t rows_here = std::min(per_strip, y1 - first);
    if (got < 0 || static_cast<std::size_t>(got) < rows_here * cols * item) {
      fail(path, "truncated or corrupt image data at row " + std::to_string(std::max(first, y0)));
    }
    for (std::size_t y = std::max(first, y0); y < first + rows_here; ++y) {
      std::memcpy(out + (y - y0) * cols * item, strip.data() + (y - first) * cols * item,
                  cols * item);
    }
  }
}

// The pixel's height and width in mm, where the page states them in pixels per centimetre (as
// riner writes them); {0, 0} otherwise. Resolutions in inches are left alone: most are a
// scanner's or an editor's 72 dpi, not the detector's pitch.
std::array<double, 2> pixel_size_mm(TIFF* tif) {
  uint16_t unit = RESUNIT_NONE;
  float x = 0.0f, y = 0.0f;
  if (!TIFFGetField(tif, TIFFTAG_RESOLUTIONUNIT, &unit) || unit != RESUNIT_CENTIMETER ||
      !TIFFGetField(tif, TIFFTAG_XRESOLUTION, &x) || !TIFFGetField(tif, TIFFTAG_YRESOLUTION, &y) ||
      !(x > 0.0f) || !(y > 0.0f) || !std::isfinite(x) || !std::isfinite(y)) {
    return {0.0, 0.0};
  }
  return {10.0 / y, 10.0 / x};
}

// Every page of the file, or only rows `rows` of each.
ArrayFile read_pages(const std::filesystem::path& path, std::optional<RowRange> wanted) {
  input_file_size(path);
  install_handlers();
  t_tiff_error.clear();
  TiffPtr tif(TIFFOpen(path.c_str(), "r"));
  if (!tif) fail(path, "not a readable TIFF file");
  register_input(path);

  ArrayFile file;
  file.format = FileFormat::kTiff;
  std::size_t rows = 0;
  std::size_t cols = 0;
  SampleType type = SampleType::kFloat32;
  std::vector<unsigned char> raw;
  std::size_t pages = 0;
  RowRange range;
  std::array<double, 2> pixel_mm{};
  do {
    uint32_t width = 0;
    uint32_t height = 0;
    if (!TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &width) ||
        !TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &height) || width == 0 || height == 0) {
      fail(path, "page " + std::to_string(pages) + " has no valid size");
    }
    const SampleType this_type = page_type(tif.get(), path);
    if (pages == 0) {
      rows = height;
      cols = width;
      type = this_type;
      pixel_mm = pixel_size_mm(tif.get());
      // Refuse sizes the file cannot possibly hold before allocating for them: uncompressed
      // data needs its bytes; compression rarely beats 1000:1.
      uint16_t compression = COMPRESSION_NONE;
      TIFFGetFieldDefaulted(tif.get(), TIFFTAG_COMPRESSION, &compression);
      const std::uint64_t file_bytes = input_file_size(path);
      const std::uint64_t limit =
          compression == COMPRESSION_NONE ? file_bytes / sample_bytes(type) : 1024 * file_bytes;
      if (shape_size({rows, cols}) > limit) {
        fail(path, "page size " + std::to_string(height) + " x " + std::to_string(width) +
                       " is absurd for a file of this size");
      }
      range = wanted ? *wanted : RowRange{0, rows};
      check_row_range(path, {1, rows, cols}, range);
    } else if (height != rows || width != cols || this_type != type) {
      fail(path, "page " + std::to_string(pages) + " differs in size or type from page 0");
    }
    const std::size_t item = sample_bytes(type);
    const std::size_t page_bytes = range.count * cols * item;
    raw.resize((pages + 1) * page_bytes);
    read_page(tif.get(), range.first, range.first + range.count, cols, item,
              raw.data() + pages * page_bytes, path);
    ++pages;
  } while (TIFFReadDirectory(tif.get()));
  if (!t_tiff_error.empty()) fail(path, "corrupt directory");

  file.dtype = sample_type_name(type);
  std::vector<std::size_t> shape = pages == 1 ? std::vector<std::size_t>{range.count, cols}
                                              : std::vector<std::size_t>{pages, range.count, cols};
  std::vector<float> data(shape_size(shape));
  file.non_finite =
      decode_samples(raw.data(), data.size(), type, host_is_little_endian(), data.data());
  file.array = Array(std::move(shape), std::move(data));
  // One page's rows and columns; a stack's spacing is stated nowhere.
  if (pages == 1 && pixel_mm[0] > 0.0) file.voxel_size = {pixel_mm[0], pixel_mm[1]};
  return file;
}

}  // namespace

ArrayFile read_tiff(const std::filesystem::path& path) { return read_pages(path, std::nullopt); }

ArrayFile read_tiff_rows(const std::filesystem::path& path, RowRange rows) {
  return read_pages(path, rows);
}

std::vector<std::size_t> tiff_shape(const std::filesystem::path& path) {
  input_file_size(path);
  install_handlers();
  t_tiff_error.clear();
  TiffPtr tif(TIFFOpen(path.c_str(), "r"));
  if (!tif) fail(path, "not a readable TIFF file");
  uint32_t width = 0;
  uint32_t height = 0;
  if (!TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &width) ||
      !TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &height) || width == 0 || height == 0) {
    fail(path, "page 0 has no valid size");
  }
  const std::size_t pages = TIFFNumberOfDirectories(tif.get());
  if (pages <= 1) return {height, width};
  return {pages, height, width};
}

struct TiffPageWriter::File {
  TiffPtr tif;
};

TiffPageWriter::TiffPageWriter(const std::filesystem::path& path, std::size_t pages,
                               std::size_t rows, std::size_t cols, double pixel_mm)
    : file_(std::make_unique<File>()),
      path_(path),
      pages_(pages),
      rows_(rows),
      cols_(cols),
      pixel_mm_(pixel_mm > 0.0 && std::isfinite(pixel_mm) ? pixel_mm : 0.0) {
  install_handlers();
  t_tiff_error.clear();
  const bool big = pages * rows * cols * sizeof(float) > (std::size_t{1} << 31);
  file_->tif.reset(TIFFOpen(path.c_str(), big ? "w8" : "w"));
  if (!file_->tif) throw Error(prefix(path) + "cannot create TIFF file");
}

TiffPageWriter::~TiffPageWriter() = default;

void TiffPageWriter::append(const float* page) {
  if (!file_->tif || written_ >= pages_) {
    throw std::logic_error(prefix(path_) + "TIFF page written past the last");
  }
  TIFF* tif = file_->tif.get();
  t_tiff_error.clear();
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<uint32_t>(cols_));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<uint32_t>(rows_));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 32);
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tif, 0));
  if (pixel_mm_ > 0.0) {
    const auto per_cm = static_cast<float>(10.0 / pixel_mm_);
    TIFFSetField(tif, TIFFTAG_XRESOLUTION, per_cm);
    TIFFSetField(tif, TIFFTAG_YRESOLUTION, per_cm);
    TIFFSetField(tif, TIFFTAG_RESOLUTIONUNIT, RESUNIT_CENTIMETER);
  }
  if (pages_ > 1) {
    TIFFSetField(tif, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
    TIFFSetField(tif, TIFFTAG_PAGENUMBER, static_cast<uint16_t>(written_),
                 static_cast<uint16_t>(pages_));
  }
  std::vector<float> row(cols_);
  for (std::size_t y = 0; y < rows_; ++y) {
    std::memcpy(row.data(), page + y * cols_, cols_ * sizeof(float));
    if (TIFFWriteScanline(tif, row.data(), static_cast<uint32_t>(y), 0) < 0) {
      throw Error(prefix(path_) + "TIFF write failed: " + t_tiff_error);
    }
  }
  if (!TIFFWriteDirectory(tif)) throw Error(prefix(path_) + "TIFF write failed");
  ++written_;
}

void TiffPageWriter::close() {
  if (written_ != pages_) {
    throw std::logic_error(prefix(path_) + std::to_string(written_) + " of " +
                           std::to_string(pages_) + " TIFF pages written");
  }
  if (file_->tif && !TIFFFlush(file_->tif.get())) throw Error(prefix(path_) + "TIFF write failed");
  file_->tif.reset();
}

void write_tiff(const std::filesystem::path& path, const Array& array, double pixel_mm) {
  if (array.rank() != 2 && array.rank() != 3) {
    throw InputError(prefix(path) + "TIFF output takes a 2D image or a 3D stack, not rank " +
                     std::to_string(array.rank()));
  }
  const std::size_t pages = array.rank() == 3 ? array.shape[0] : 1;
  const std::size_t rows = array.shape[array.rank() - 2];
  const std::size_t cols = array.shape[array.rank() - 1];
  TiffPageWriter writer(path, pages, rows, cols, pixel_mm);
  for (std::size_t p = 0; p < pages; ++p) writer.append(array.ptr() + p * rows * cols);
  writer.close();
}

}  // namespace riner::io
