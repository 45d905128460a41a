// Shared by the fuzz targets: the input written to a per-process scratch file (the readers
// take paths), and the rule that bad input may only ever raise riner::Error.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "riner/error.hpp"
#include "riner/log.hpp"

namespace riner::fuzz {

inline std::filesystem::path scratch(const std::string& name) {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("riner_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    riner::set_warning_handler([](std::string_view) {});
    return d;
  }();
  return dir / name;
}

inline void write(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace riner::fuzz
