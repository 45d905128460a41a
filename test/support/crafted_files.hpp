// Builders for test files in every format, byte by byte, so readers are checked against files
// riner did not write itself (other dtypes, byte orders, layouts) and against broken ones.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace riner::test {

// Appends the bytes of a value in the given byte order.
template <typename T>
void append(std::string& out, T value, bool big_endian = false) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// A .npy file (version 1.0) with the given header fields and raw data bytes.
inline std::string make_npy(const std::string& descr, bool fortran,
                            const std::vector<std::size_t>& shape, const std::string& data) {
  std::string dims;
  for (std::size_t i = 0; i < shape.size(); ++i) dims += (i ? ", " : "") + std::to_string(shape[i]);
  if (shape.size() == 1) dims += ",";
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") +
                     ", 'shape': (" + dims + "), }";
  dict.append((64 - (10 + dict.size() + 1) % 64) % 64, ' ');
  dict += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01';
  out += '\x00';
  append<std::uint16_t>(out, static_cast<std::uint16_t>(dict.size()));
  return out + dict + data;
}

// A single-file NIfTI-1 image: dims in file order (x fastest), datatype code, scaling.
inline std::string make_nifti(const std::vector<int>& dims, std::int16_t datatype,
                              std::int16_t bitpix, float slope, float inter,
                              const std::string& data, bool big_endian = false) {
  std::string h;
  append<std::int32_t>(h, 348, big_endian);
  h.append(36, '\0');  // up to dim at 40
  append<std::int16_t>(h, static_cast<std::int16_t>(dims.size()), big_endian);
  for (int d = 0; d < 7; ++d) {
    append<std::int16_t>(
        h, static_cast<std::int16_t>(d < static_cast<int>(dims.size()) ? dims[d] : 1), big_endian);
  }
  h.append(12, '\0');                             // intent_p1..3 (56..67)
  append<std::int16_t>(h, 0, big_endian);         // intent_code 68
  append<std::int16_t>(h, datatype, big_endian);  // 70
  append<std::int16_t>(h, bitpix, big_endian);    // 72
  append<std::int16_t>(h, 0, big_endian);         // slice_start 74
  for (int d = 0; d < 8; ++d) append<float>(h, d == 0 ? 1.0f : 0.5f * (d + 1), big_endian);
  append<float>(h, 352.0f, big_endian);  // vox_offset 108
  append<float>(h, slope, big_endian);   // 112
  append<float>(h, inter, big_endian);   // 116
  h.resize(344, '\0');
  h += std::string("n+1\0", 4);
  h.append(4, '\0');  // extension flag
  return h + data;
}

}  // namespace riner::test
