// NumPy .npy, format versions 1.0-3.0
// (https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html).
#include <cstring>
#include <fstream>
#include <optional>
#include <regex>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/row_blocks.hpp"
#include "io/sample_type.hpp"
#include "riner/error.hpp"

namespace riner::io {

namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kMagicSize = 6;

struct NpyHeader {
  SampleType type;
  bool little_endian;
  bool fortran_order;
  std::vector<std::size_t> shape;
};

SampleType parse_kind(char kind, int bytes, const std::string& descr,
                      const std::filesystem::path& path) {
  if (kind == 'f' && bytes == 4) return SampleType::kFloat32;
  if (kind == 'f' && bytes == 8) return SampleType::kFloat64;
  if (kind == 'u' && bytes == 1) return SampleType::kUint8;
  if (kind == 'i' && bytes == 1) return SampleType::kInt8;
  if (kind == 'u' && bytes == 2) return SampleType::kUint16;
  if (kind == 'i' && bytes == 2) return SampleType::kInt16;
  if (kind == 'u' && bytes == 4) return SampleType::kUint32;
  if (kind == 'i' && bytes == 4) return SampleType::kInt32;
  throw InputError(prefix(path) + "unsupported dtype '" + descr +
                   "' (riner reads float32/64, int8/16/32, uint8/16/32)");
}

NpyHeader parse_header(const std::string& dict, const std::filesystem::path& path) {
  // At most two digits of item size: anything longer is not a dtype riner reads anyway.
  static const std::regex descr_re(R"('descr'\s*:\s*'([<>|=])([a-zA-Z])(\d{1,2})')");
  static const std::regex fortran_re(R"('fortran_order'\s*:\s*(True|False))");
  static const std::regex shape_re(R"('shape'\s*:\s*\(([^)]*)\))");
  std::smatch m;
  NpyHeader header{};
  if (!std::regex_search(dict, m, descr_re)) {
    throw InputError(prefix(path) +
                     "header has no simple 'descr' (structured dtypes are not "
                     "supported)");
  }
  const std::string descr = m[1].str() + m[2].str() + m[3].str();
  const int bytes = std::stoi(m[3].str());
  header.type = parse_kind(m[2].str()[0], bytes, descr, path);
  const char order = m[1].str()[0];
  header.little_endian = order == '<' || order == '|' || (order == '=' && host_is_little_endian());
  if (!std::regex_search(dict, m, fortran_re)) {
    throw InputError(prefix(path) + "header has no 'fortran_order'");
  }
  header.fortran_order = m[1].str() == "True";
  if (!std::regex_search(dict, m, shape_re))
    throw InputError(prefix(path) + "header has no 'shape'");
  const std::string dims = m[1].str();
  // Each entry a whole number: "(-5, 60)" read as [5, 60] before.
  std::size_t start = 0;
  while (start <= dims.size()) {
    const std::size_t comma = std::min(dims.find(',', start), dims.size());
    std::string entry = dims.substr(start, comma - start);
    entry.erase(0, entry.find_first_not_of(" \t"));
    entry.erase(entry.find_last_not_of(" \t") + 1);
    start = comma + 1;
    if (entry.empty() && comma == dims.size()) break;  // "(n,)" or "()"
    if (entry.empty() || entry.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError(prefix(path) + "header's shape (" + dims +
                       ") is not a tuple of non-negative whole numbers");
    }
    if (entry.size() > 12) throw InputError(prefix(path) + "absurd dimension " + entry);
    header.shape.push_back(std::stoull(entry));
  }
  if (header.shape.empty()) throw InputError(prefix(path) + "holds a scalar, not an array");
  return header;
}

}  // namespace

std::vector<float> fortran_to_c_order(const std::vector<float>& data,
                                      const std::vector<std::size_t>& shape) {
  const std::size_t rank = shape.size();
  std::vector<float> out(data.size());
  if (data.empty()) return out;
  // Walk the C-order output with an index counter; track the Fortran offset alongside.
  std::vector<std::size_t> index(rank, 0);
  std::vector<std::size_t> fortran_stride(rank, 1);
  for (std::size_t d = 1; d < rank; ++d) fortran_stride[d] = fortran_stride[d - 1] * shape[d - 1];
  std::size_t source = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = data[source];
    for (std::size_t d = rank; d-- > 0;) {
      if (++index[d] < shape[d]) {
        source += fortran_stride[d];
        break;
      }
      source -= (shape[d] - 1) * fortran_stride[d];
      index[d] = 0;
    }
  }
  return out;
}

namespace {

// Where the data start and how they are laid out, from the first bytes of the file.
struct NpyLayout {
  NpyHeader header;
  std::size_t data_start = 0;
};

NpyLayout parse_layout(const std::string& head, const std::filesystem::path& path,
                       std::size_t file_size) {
  if (head.size() < kMagicSize + 4 || std::memcmp(head.data(), kMagic, kMagicSize) != 0) {
    throw InputError(prefix(path) + "not a NumPy .npy file (bad magic)");
  }
  const int major = static_cast<unsigned char>(head[6]);
  std::size_t header_len = 0;
  NpyLayout layout;
  const auto* u = reinterpret_cast<const unsigned char*>(head.data());
  if (major == 1) {
    header_len = u[8] | (u[9] << 8);
    layout.data_start = 10 + header_len;
  } else if (major == 2 || major == 3) {
    if (head.size() < 12) throw InputError(prefix(path) + "truncated header");
    header_len = u[8] | (u[9] << 8) | (u[10] << 16) | (static_cast<std::size_t>(u[11]) << 24);
    layout.data_start = 12 + header_len;
  } else {
    throw InputError(prefix(path) + "unsupported .npy version " + std::to_string(major));
  }
  if (layout.data_start > file_size || layout.data_start > head.size())
    throw InputError(prefix(path) + "truncated header");
  layout.header = parse_header(head.substr(layout.data_start - header_len, header_len), path);
  return layout;
}

void check_data_size(const NpyLayout& layout, const std::filesystem::path& path,
                     std::size_t file_size) {
  const std::size_t count = element_count(path, layout.header.shape);
  const std::size_t item = sample_bytes(layout.header.type);
  const std::size_t available = file_size - layout.data_start;
  if (count > available / item || count * item != available) {
    throw InputError(prefix(path) + "header says " + shape_string(layout.header.shape) + " " +
                     sample_type_name(layout.header.type) + " (" + std::to_string(count) +
                     " values) but the file holds " + std::to_string(available) + " data bytes");
  }
}

// The header alone: the magic, the lengths and the dictionary (at most 4 GiB by the format).
NpyLayout read_layout(std::ifstream& in, const std::filesystem::path& path,
                      std::size_t file_size) {
  std::string head(std::min<std::size_t>(file_size, 12), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  if (!in) throw InputError(prefix(path) + "cannot read the header");
  std::size_t needed = head.size();
  if (head.size() >= 10 && std::memcmp(head.data(), kMagic, kMagicSize) == 0) {
    const auto* u = reinterpret_cast<const unsigned char*>(head.data());
    const int major = u[6];
    needed = major == 1 ? 10 + (u[8] | (u[9] << 8))
                        : 12 + (u[8] | (u[9] << 8) | (u[10] << 16) |
                                (static_cast<std::size_t>(u[11]) << 24));
  }
  if (needed > head.size()) {
    if (needed > file_size) throw InputError(prefix(path) + "truncated header");
    const std::size_t had = head.size();
    head.resize(needed);
    in.read(head.data() + had, static_cast<std::streamsize>(needed - had));
    if (!in) throw InputError(prefix(path) + "truncated header");
  }
  return parse_layout(head, path, file_size);
}

}  // namespace

ArrayFile read_npy(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  const NpyLayout layout = parse_layout(bytes, path, bytes.size());
  const NpyHeader& header = layout.header;
  check_data_size(layout, path, bytes.size());
  ArrayFile file;
  file.format = FileFormat::kNpy;
  file.dtype = sample_type_name(header.type);
  const std::size_t count = shape_size(header.shape);
  std::vector<float> data(count);
  const auto* u = reinterpret_cast<const unsigned char*>(bytes.data());
  file.non_finite = decode_samples(u + layout.data_start, count, header.type,
                                   header.little_endian, data.data());
  if (header.fortran_order && header.shape.size() > 1)
    data = fortran_to_c_order(data, header.shape);
  file.array = Array(header.shape, std::move(data));
  return file;
}

std::vector<std::size_t> npy_shape(const std::filesystem::path& path) {
  const std::uint64_t size = input_file_size(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(prefix(path) + "cannot be opened");
  const NpyLayout layout = read_layout(in, path, size);
  check_data_size(layout, path, size);
  return layout.header.shape;
}

std::optional<ArrayFile> read_npy_rows(const std::filesystem::path& path, RowRange rows) {
  const std::uint64_t size = input_file_size(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(prefix(path) + "cannot be opened");
  const NpyLayout layout = read_layout(in, path, size);
  const NpyHeader& header = layout.header;
  check_data_size(layout, path, size);
  // A Fortran-order stack keeps a row's values apart: read whole and cut.
  if (header.fortran_order || header.shape.size() != 3) return std::nullopt;
  check_row_range(path, header.shape, rows);
  register_input(path);
  return read_row_blocks(in, path, layout.data_start, header.shape, rows, header.type,
                         header.little_endian, FileFormat::kNpy);
}

std::string npy_header(const std::vector<std::size_t>& shape) {
  std::string dims;
  for (std::size_t d = 0; d < shape.size(); ++d) {
    dims += (d > 0 ? ", " : "") + std::to_string(shape[d]);
  }
  if (shape.size() == 1) dims += ",";  // a 1-tuple is "(n,)"
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Pad with spaces so the data starts on a 64-byte boundary; the header ends with '\n'.
  const std::size_t unpadded = kMagicSize + 4 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string out(kMagic, kMagicSize);
  out += '\x01';
  out += '\x00';
  out += static_cast<char>(dict.size() & 0xff);
  out += static_cast<char>((dict.size() >> 8) & 0xff);
  out += dict;
  return out;
}

void write_npy(const std::filesystem::path& path, const Array& array) {
  const std::string out = npy_header(array.shape);
  std::ofstream file(path, std::ios::binary);
  file.write(out.data(), static_cast<std::streamsize>(out.size()));
  std::vector<float> le(array.data);
  if (!host_is_little_endian()) {
    for (float& v : le) {
      unsigned char b[4];
      std::memcpy(b, &v, 4);
      std::swap(b[0], b[3]);
      std::swap(b[1], b[2]);
      std::memcpy(&v, b, 4);
    }
  }
  file.write(reinterpret_cast<const char*>(le.data()),
             static_cast<std::streamsize>(le.size() * sizeof(float)));
  if (!file.flush()) throw Error(prefix(path) + "write failed");
}

}  // namespace riner::io
