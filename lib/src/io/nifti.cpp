// NIfTI-1 single-file (.nii) images
// (https://nifti.nimh.nih.gov/nifti-1/documentation/nifti1fields). The file's first axis (x) runs
// fastest, so the array shape is the file's dims reversed: dim = [nx, ny, nz] becomes an array [nz,
// ny, nx].
#include <cmath>
#include <cstring>
#include <fstream>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/row_blocks.hpp"
#include "io/sample_type.hpp"
#include "riner/error.hpp"

namespace riner::io {

namespace {

constexpr std::size_t kHeaderSize = 348;
constexpr std::size_t kDataOffset = 352;  // header + 4-byte extension flag

template <typename T>
T field(const std::string& bytes, std::size_t offset, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, bytes.data() + offset, sizeof(T));
  if (swap) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  T value;
  std::memcpy(&value, b, sizeof(T));
  return value;
}

template <typename T>
void put(std::string& bytes, std::size_t offset, T value) {
  static_assert(sizeof(T) <= 8);
  std::memcpy(bytes.data() + offset, &value, sizeof(T));  // written in host order, little here
}

SampleType nifti_type(int code, const std::filesystem::path& path) {
  switch (code) {
    case 2:
      return SampleType::kUint8;
    case 4:
      return SampleType::kInt16;
    case 8:
      return SampleType::kInt32;
    case 16:
      return SampleType::kFloat32;
    case 64:
      return SampleType::kFloat64;
    case 256:
      return SampleType::kInt8;
    case 512:
      return SampleType::kUint16;
    case 768:
      return SampleType::kUint32;
    default:
      throw InputError(prefix(path) + "unsupported NIfTI datatype code " + std::to_string(code));
  }
}

}  // namespace

namespace {

// What the header says about the data: byte order, shape (x fastest, as stored), spacing.
struct NiftiHeader {
  bool swap = false;
  std::vector<std::size_t> dims;
  std::vector<double> spacing;
};

NiftiHeader read_header(const std::string& bytes, const std::filesystem::path& path) {
  if (bytes.size() < kHeaderSize) {
    throw InputError(prefix(path) + "too short for a NIfTI-1 header (" +
                     std::to_string(bytes.size()) + " bytes)");
  }
  NiftiHeader h;
  if (field<std::int32_t>(bytes, 0, false) != 348) {
    if (field<std::int32_t>(bytes, 0, true) != 348) {
      throw InputError(prefix(path) + "not a NIfTI-1 file (sizeof_hdr is not 348)");
    }
    h.swap = true;
  }
  if (std::memcmp(bytes.data() + 344, "n+1", 4) != 0) {
    if (std::memcmp(bytes.data() + 344, "ni1", 4) == 0) {
      throw InputError(prefix(path) + "is a .hdr/.img pair header; riner reads single-file .nii");
    }
    throw InputError(prefix(path) + "not a NIfTI-1 file (bad magic)");
  }
  const int ndim = field<std::int16_t>(bytes, 40, h.swap);
  if (ndim < 1 || ndim > 7) {
    throw InputError(prefix(path) + "dim[0] = " + std::to_string(ndim) + " is not in 1..7");
  }
  for (int d = 1; d <= ndim; ++d) {
    const int n = field<std::int16_t>(bytes, 40 + 2 * d, h.swap);
    if (n < 1) {
      throw InputError(prefix(path) + "dim[" + std::to_string(d) + "] = " + std::to_string(n) +
                       " is not positive");
    }
    h.dims.push_back(static_cast<std::size_t>(n));
    h.spacing.push_back(std::fabs(field<float>(bytes, 76 + 4 * d, h.swap)));
  }
  // Trailing singleton axes (a 2D slice stored as nx x ny x 1) carry no information.
  while (h.dims.size() > 1 && h.dims.back() == 1) {
    h.dims.pop_back();
    h.spacing.pop_back();
  }
  return h;
}

}  // namespace

namespace {

// A single-file NIfTI's layout from its header bytes (the first 352 at least), checked against
// the file's size: where the data starts, its shape in array order, type and scaling.
struct NiftiLayout {
  NiftiHeader header;
  std::vector<std::size_t> shape;  // array order (the header's dims reversed)
  SampleType type = SampleType::kFloat32;
  std::size_t data_start = kDataOffset;
  float slope = 0.0f, inter = 0.0f;
};

NiftiLayout layout_of(const std::string& head, const std::filesystem::path& path,
                      std::uint64_t size) {
  NiftiLayout l;
  l.header = read_header(head, path);
  const bool swap = l.header.swap;
  l.shape.assign(l.header.dims.rbegin(), l.header.dims.rend());
  l.type = nifti_type(field<std::int16_t>(head, 70, swap), path);
  // Single-file images put the data after the header; 0 is a common writer's shorthand.
  const float vox_offset = field<float>(head, 108, swap);
  if (!(vox_offset >= static_cast<float>(kDataOffset)) || vox_offset > size) {
    if (vox_offset != 0.0f) {
      throw InputError(prefix(path) + "vox_offset " + std::to_string(vox_offset) +
                       " is outside the file");
    }
  } else {
    l.data_start = static_cast<std::size_t>(vox_offset);
  }
  if (l.data_start > size) {  // vox_offset 0 defaults to 352, past a 348..351-byte file
    throw InputError(prefix(path) + "ends at byte " + std::to_string(size) +
                     ", before its data starts at byte " + std::to_string(l.data_start));
  }
  const std::uint64_t available = size - l.data_start;
  if (element_count(path, l.shape) > available / sample_bytes(l.type)) {
    throw InputError(prefix(path) + "header says " + shape_string(l.shape) + " " +
                     sample_type_name(l.type) + " but the file holds only " +
                     std::to_string(available) + " data bytes");
  }
  l.slope = field<float>(head, 112, swap);
  l.inter = field<float>(head, 116, swap);
  return l;
}

// The file's first bytes, as many as a header takes.
NiftiLayout read_layout(const std::filesystem::path& path, std::uint64_t size,
                        std::ifstream& in) {
  std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(size, kDataOffset)), '\0');
  if (!in.read(head.data(), static_cast<std::streamsize>(head.size()))) {
    throw InputError(prefix(path) + "cannot be read");
  }
  return layout_of(head, path, size);
}

// The header's scaling applied to decoded samples (a zero or absent slope means the stored
// values are the values, per the standard), their non-finite count, and the voxel size.
void finish(ArrayFile& file, const NiftiLayout& l) {
  if (std::isfinite(l.slope) && l.slope != 0.0f) {
    const float offset = std::isfinite(l.inter) ? l.inter : 0.0f;
    for (float& v : file.array.data) v = v * l.slope + offset;
  }
  file.non_finite = 0;
  for (float v : file.array.data) file.non_finite += !std::isfinite(v);
  file.voxel_size.assign(l.header.spacing.rbegin(), l.header.spacing.rend());
  for (double& v : file.voxel_size) {
    if (!(v > 0.0) || !std::isfinite(v)) v = 1.0;
  }
}

}  // namespace

std::vector<std::size_t> nifti_shape(const std::filesystem::path& path) {
  const std::uint64_t size = input_file_size(path);
  std::ifstream in(path, std::ios::binary);
  return read_layout(path, size, in).shape;
}

std::optional<ArrayFile> read_nifti_rows(const std::filesystem::path& path, RowRange rows) {
  const std::uint64_t size = input_file_size(path);
  std::ifstream in(path, std::ios::binary);
  const NiftiLayout l = read_layout(path, size, in);
  if (l.shape.size() != 3) return std::nullopt;
  check_row_range(path, l.shape, rows);
  register_input(path);
  ArrayFile file = read_row_blocks(in, path, l.data_start, l.shape, rows, l.type,
                                   host_is_little_endian() != l.header.swap, FileFormat::kNifti);
  finish(file, l);
  return file;
}

ArrayFile read_nifti(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  const NiftiLayout l = layout_of(bytes, path, bytes.size());
  ArrayFile file;
  file.format = FileFormat::kNifti;
  file.dtype = sample_type_name(l.type);
  const std::size_t count = shape_size(l.shape);
  std::vector<float> data(count);
  decode_samples(reinterpret_cast<const unsigned char*>(bytes.data()) + l.data_start, count,
                 l.type, host_is_little_endian() != l.header.swap, data.data());
  file.array = Array(l.shape, std::move(data));
  finish(file, l);
  return file;
}

std::string nifti_header(const std::filesystem::path& path, const std::vector<std::size_t>& shape,
                         const std::vector<double>& voxel_size) {
  if (shape.size() < 1 || shape.size() > 7) {
    throw InputError(prefix(path) + "NIfTI holds 1 to 7 dimensions, not " +
                     std::to_string(shape.size()));
  }
  for (std::size_t d : shape) {
    if (d > 32767) {
      throw InputError(prefix(path) + "dimension " + std::to_string(d) +
                       " exceeds NIfTI-1's limit of 32767");
    }
  }
  if (!host_is_little_endian()) throw Error("NIfTI writing assumes a little-endian host");
  std::string header(kDataOffset, '\0');
  put<std::int32_t>(header, 0, 348);
  header[38] = 'r';
  const std::size_t rank = shape.size();
  put<std::int16_t>(header, 40, static_cast<std::int16_t>(rank));
  for (std::size_t d = 0; d < 7; ++d) {
    const std::size_t n = d < rank ? shape[rank - 1 - d] : 1;
    put<std::int16_t>(header, 42 + 2 * d, static_cast<std::int16_t>(n));
  }
  put<std::int16_t>(header, 70, 16);  // float32
  put<std::int16_t>(header, 72, 32);
  put<float>(header, 76, 1.0f);  // qfac
  for (std::size_t d = 0; d < 7; ++d) {
    const double v = d < rank && voxel_size.size() == rank ? voxel_size[rank - 1 - d] : 1.0;
    put<float>(header, 80 + 4 * d, static_cast<float>(v));
  }
  put<float>(header, 108, static_cast<float>(kDataOffset));
  put<float>(header, 112, 1.0f);
  header[123] = 2;  // xyzt_units: millimetres
  std::memcpy(header.data() + 148, "riner", 5);
  std::memcpy(header.data() + 344, "n+1", 4);
  return header;
}

void write_nifti(const std::filesystem::path& path, const Array& array,
                 const std::vector<double>& voxel_size) {
  const std::string header = nifti_header(path, array.shape, voxel_size);
  std::ofstream file(path, std::ios::binary);
  file.write(header.data(), static_cast<std::streamsize>(header.size()));
  file.write(reinterpret_cast<const char*>(array.ptr()),
             static_cast<std::streamsize>(array.size() * sizeof(float)));
  if (!file.flush()) throw Error(prefix(path) + "write failed");
}

}  // namespace riner::io
