#include "training/checkpoint.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <span>
#include <system_error>
#include <utility>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "training/checkpoint_bytes.hpp"

namespace riner::detail {

namespace {

constexpr char kMagic[8] = {'R', 'I', 'N', 'E', 'R', 'C', 'K', 'P'};
// The format's version: a checkpoint of another one is refused rather than misread. Version 2
// ends with a checksum of the bytes before it (a kill mid-write cannot damage a checkpoint, its
// writes being atomic, but a disk or a copy can, and a resumed training would go on from
// garbage without a word); version 1, without it, is still read.
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kUnsummedVersion = 1;

}  // namespace

std::uint64_t fingerprint(std::string_view bytes, std::uint64_t hash) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

void write_checkpoint(const std::filesystem::path& path, const TrainingCheckpoint& c) {
  ByteWriter out;
  for (const char m : kMagic) out.put(m);
  out.put(kVersion);
  out.put(c.scan_fingerprint);
  out.put(c.settings_fingerprint);
  out.put_string(c.device);
  out.put<std::int32_t>(c.steps);
  out.put(c.seconds);
  out.put(c.samples);
  out.put<std::uint8_t>(c.plateaued ? 1 : 0);
  out.put_array(std::span<const std::uint32_t>(c.element_rays));
  out.put_array(std::span<const LossRecord>(c.history));
  out.put_string(c.trainer_state);
  out.put(fingerprint(out.bytes()));
  write_text(path, out.bytes());
}

TrainingCheckpoint read_checkpoint(const std::filesystem::path& path) {
  // Not io::read_file_bytes: that marks the file as an input, and the run that resumes from a
  // checkpoint writes the next one in its place.
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot read the checkpoint");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const std::string what = path.string();
  ByteReader header(bytes, what);
  for (const char m : kMagic) {
    if (bytes.size() < sizeof(kMagic) || header.get<char>() != m) {
      throw InputError(what + ": not a riner training checkpoint");
    }
  }
  const auto version = header.get<std::uint32_t>();
  if (version != kVersion && version != kUnsummedVersion) {
    throw InputError(what + ": a checkpoint of format " + std::to_string(version) +
                     ", this riner reads " + std::to_string(kUnsummedVersion) + " and " +
                     std::to_string(kVersion));
  }
  std::string_view body = bytes;
  if (version == kVersion) {
    std::uint64_t sum = 0;
    if (body.size() < sizeof(kMagic) + sizeof(version) + sizeof(sum)) {
      throw InputError(what + ": truncated or corrupt");
    }
    body.remove_suffix(sizeof(sum));
    std::memcpy(&sum, bytes.data() + body.size(), sizeof(sum));
    if (fingerprint(body) != sum) {
      throw InputError(what + ": truncated or corrupt (its checksum does not match its bytes)");
    }
  }
  ByteReader in(body, what);
  in.get<std::array<char, sizeof(kMagic)>>();
  in.get<std::uint32_t>();
  TrainingCheckpoint c;
  c.scan_fingerprint = in.get<std::uint64_t>();
  c.settings_fingerprint = in.get<std::uint64_t>();
  c.device = in.get_string();
  c.steps = in.get<std::int32_t>();
  c.seconds = in.get<double>();
  c.samples = in.get<double>();
  c.plateaued = in.get<std::uint8_t>() != 0;
  c.element_rays = in.get_array<std::uint32_t>();
  c.history = in.get_array<LossRecord>();
  c.trainer_state = in.get_string();
  if (!in.at_end() || c.steps < 0 || c.history.size() > static_cast<std::size_t>(c.steps)) {
    throw InputError(what + ": truncated or corrupt");
  }
  return c;
}

}  // namespace riner::detail

namespace riner {

CheckpointSaver::CheckpointSaver(Reconstructor& reconstructor, std::filesystem::path path,
                                 double seconds)
    : reconstructor_(reconstructor),
      path_(std::move(path)),
      seconds_(seconds),
      saved_at_(reconstructor.stats().seconds) {}

void CheckpointSaver::after_report(const TrainingProgress& p, bool stopping) {
  if (seconds_ <= 0.0 || p.step >= p.total) return;
  if (!stopping && p.seconds - saved_at_ < seconds_) return;
  reconstructor_.save_checkpoint(path_);
  saved_at_ = p.seconds;
}

void CheckpointSaver::discard() const {
  std::error_code ignored;  // a file already gone is what was wanted
  std::filesystem::remove(path_, ignored);
}

}  // namespace riner
