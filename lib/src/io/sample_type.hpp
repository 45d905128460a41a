// Sample types found in files, and their conversion to float32.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace riner::io {

enum class SampleType { kUint8, kInt8, kUint16, kInt16, kUint32, kInt32, kFloat32, kFloat64 };

std::size_t sample_bytes(SampleType type);
const char* sample_type_name(SampleType type);  // "float32", "uint16", ...
std::optional<SampleType> sample_type_from_name(std::string_view name);

bool host_is_little_endian();

// Converts n samples stored at `bytes` (in the given byte order) to float; returns the number
// of non-finite results.
std::size_t decode_samples(const unsigned char* bytes, std::size_t n, SampleType type,
                           bool little_endian, float* out);

}  // namespace riner::io
