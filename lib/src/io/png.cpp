// 8-bit PNG output through libpng (previews and plots; riner never reads PNG).
#include <png.h>

#include <csetjmp>
#include <cstdio>

#include "io/file_access.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner::io {

namespace {

// libpng reports errors by longjmp; this C-style function holds no objects with destructors
// between setjmp and the calls that may jump, so nothing leaks.
bool write_png_rows(const char* filename, const unsigned char* pixels, std::size_t rows,
                    std::size_t cols, int color_type, int channels) {
  std::FILE* fp = std::fopen(filename, "wb");
  if (fp == nullptr) return false;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  bool ok = false;
  if (png != nullptr && info != nullptr && setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, fp);
    png_set_IHDR(png, info, static_cast<png_uint_32>(cols), static_cast<png_uint_32>(rows), 8,
                 color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (std::size_t y = 0; y < rows; ++y) {
      png_write_row(png, const_cast<png_bytep>(pixels + y * cols * channels));
    }
    png_write_end(png, nullptr);
    ok = true;
  }
  png_destroy_write_struct(&png, &info);
  ok = (std::fclose(fp) == 0) && ok;
  return ok;
}

}  // namespace

void write_png_gray8(const std::filesystem::path& path, const std::vector<unsigned char>& pixels,
                     std::size_t rows, std::size_t cols) {
  if (!write_png_rows(path.c_str(), pixels.data(), rows, cols, PNG_COLOR_TYPE_GRAY, 1)) {
    throw Error(prefix(path) + "PNG write failed");
  }
}

void write_png_rgb8(const std::filesystem::path& path, const std::vector<unsigned char>& pixels,
                    std::size_t rows, std::size_t cols) {
  if (!write_png_rows(path.c_str(), pixels.data(), rows, cols, PNG_COLOR_TYPE_RGB, 3)) {
    throw Error(prefix(path) + "PNG write failed");
  }
}

}  // namespace riner::io
