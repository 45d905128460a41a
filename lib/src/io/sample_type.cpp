#include "io/sample_type.hpp"

#include <cmath>
#include <cstring>

namespace riner::io {

namespace {

template <typename T>
T load(const unsigned char* p, bool swap) {
  unsigned char buf[sizeof(T)];
  if (swap) {
    for (std::size_t i = 0; i < sizeof(T); ++i) buf[i] = p[sizeof(T) - 1 - i];
  } else {
    std::memcpy(buf, p, sizeof(T));
  }
  T value;
  std::memcpy(&value, buf, sizeof(T));
  return value;
}

template <typename T>
std::size_t decode(const unsigned char* bytes, std::size_t n, bool swap, float* out) {
  std::size_t non_finite = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float v = static_cast<float>(load<T>(bytes + i * sizeof(T), swap));
    non_finite += !std::isfinite(v);
    out[i] = v;
  }
  return non_finite;
}

}  // namespace

std::size_t sample_bytes(SampleType type) {
  switch (type) {
    case SampleType::kUint8:
    case SampleType::kInt8:
      return 1;
    case SampleType::kUint16:
    case SampleType::kInt16:
      return 2;
    case SampleType::kUint32:
    case SampleType::kInt32:
    case SampleType::kFloat32:
      return 4;
    case SampleType::kFloat64:
      return 8;
  }
  return 0;
}

const char* sample_type_name(SampleType type) {
  switch (type) {
    case SampleType::kUint8:
      return "uint8";
    case SampleType::kInt8:
      return "int8";
    case SampleType::kUint16:
      return "uint16";
    case SampleType::kInt16:
      return "int16";
    case SampleType::kUint32:
      return "uint32";
    case SampleType::kInt32:
      return "int32";
    case SampleType::kFloat32:
      return "float32";
    case SampleType::kFloat64:
      return "float64";
  }
  return "unknown";
}

std::optional<SampleType> sample_type_from_name(std::string_view name) {
  for (SampleType t :
       {SampleType::kUint8, SampleType::kInt8, SampleType::kUint16, SampleType::kInt16,
        SampleType::kUint32, SampleType::kInt32, SampleType::kFloat32, SampleType::kFloat64}) {
    if (name == sample_type_name(t)) return t;
  }
  return std::nullopt;
}

bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

std::size_t decode_samples(const unsigned char* bytes, std::size_t n, SampleType type,
                           bool little_endian, float* out) {
  const bool swap = little_endian != host_is_little_endian();
  switch (type) {
    case SampleType::kUint8:
      return decode<std::uint8_t>(bytes, n, swap, out);
    case SampleType::kInt8:
      return decode<std::int8_t>(bytes, n, swap, out);
    case SampleType::kUint16:
      return decode<std::uint16_t>(bytes, n, swap, out);
    case SampleType::kInt16:
      return decode<std::int16_t>(bytes, n, swap, out);
    case SampleType::kUint32:
      return decode<std::uint32_t>(bytes, n, swap, out);
    case SampleType::kInt32:
      return decode<std::int32_t>(bytes, n, swap, out);
    case SampleType::kFloat32:
      return decode<float>(bytes, n, swap, out);
    case SampleType::kFloat64:
      return decode<double>(bytes, n, swap, out);
  }
  return 0;
}

}  // namespace riner::io
