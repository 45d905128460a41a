// What identifies the data a scan's name reads, cheaply: its files' sizes and a hash of up to
// 16 blocks of 64 KiB spread over each (a resumed run's scan must hold the same data, wherever
// it is now; a scan of terabytes cannot be hashed whole at every start). Not a checksum: a
// change confined to the unsampled bytes of a file that keeps its size goes unseen.
#pragma once

#include <cstdint>
#include <string>

namespace riner::io {

struct DataFingerprint {
  std::uint64_t bytes = 0;  // over every file
  std::uint64_t files = 0;
  std::uint64_t hash = 0;  // FNV-1a over each file's size and sampled blocks, in order
};

// A file, a folder or pattern of TIFFs, or an HDF5 dataset's file ("scan.h5:/entry/data").
// InputError for a name that reads nothing.
DataFingerprint data_fingerprint(const std::string& name);

}  // namespace riner::io
