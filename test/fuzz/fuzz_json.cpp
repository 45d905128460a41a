// libFuzzer targets for the JSON parsers: geometry (-DRINER_FUZZ_GEOMETRY) or settings.
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "riner/geometry.hpp"
#include "riner/riner_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
#ifdef RINER_FUZZ_GEOMETRY
    const riner::Geometry g = riner::Geometry::from_json(text, "fuzz");
    // A geometry that parses must survive its own round trip and a measurement check.
    const riner::Geometry again = riner::Geometry::from_json(g.to_json(), "again");
    again.check_measurement_shape(g.measurement_shape());
#else
    riner::RinerConfig c;
    c.update_from_json(text, "fuzz");
    riner::RinerConfig again;
    again.update_from_json(c.to_json(), "again");
#endif
  } catch (const riner::Error&) {
  }
  return 0;
}
