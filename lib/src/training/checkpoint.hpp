// A training checkpoint's file (Reconstructor::save_checkpoint, resume_from): the run it belongs
// to (the scan's, the settings' and the device's fingerprints), the steps' records and the
// trainer's state (Trainer::save_state).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "riner/reconstructor.hpp"

namespace riner::detail {

struct TrainingCheckpoint {
  std::uint64_t scan_fingerprint = 0;      // the readings and the geometry
  std::uint64_t settings_fingerprint = 0;  // the settings as resolved for the device
  std::string device;                      // Trainer::device_name()
  int steps = 0;
  double seconds = 0.0;
  double samples = 0.0;
  bool plateaued = false;
  std::vector<std::uint32_t> element_rays;
  std::vector<LossRecord> history;
  std::string trainer_state;
};

// 64-bit FNV-1a of `bytes`, continuing from `hash`.
std::uint64_t fingerprint(std::string_view bytes, std::uint64_t hash = 14695981039346656037ull);

// Written atomically (a temporary file, then a rename).
void write_checkpoint(const std::filesystem::path& path, const TrainingCheckpoint& checkpoint);
// InputError naming the file when it is missing, not a checkpoint, of another version, or
// truncated.
TrainingCheckpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace riner::detail
