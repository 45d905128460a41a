// libFuzzer targets for the array readers; which one is chosen at compile time
// (-DRINER_FUZZ_EXTENSION=".npy" etc.). Any exception other than riner::Error, any crash, leak
// or sanitizer report is a finding.
#include <cstdint>

#include "fuzz_support.hpp"
#include "riner/io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = riner::fuzz::scratch(std::string("input") + RINER_FUZZ_EXTENSION);
#ifdef RINER_FUZZ_RAW
  // Raw files need a sidecar: the input's first line is the sidecar JSON, the rest the data.
  std::size_t split = 0;
  while (split < size && data[split] != '\n') ++split;
  auto sidecar = path;
  sidecar += ".json";
  riner::fuzz::write(sidecar, data, split);
  riner::fuzz::write(path, data + std::min(size, split + 1), size - std::min(size, split + 1));
#else
  riner::fuzz::write(path, data, size);
#endif
  try {
    const riner::ArrayFile file = riner::read_array(path);
    volatile float sink = file.array.size() > 0 ? file.array.data[file.array.size() - 1] : 0.0f;
    (void)sink;
  } catch (const riner::Error&) {
  }
  return 0;
}
