// Uses riner's public API only: writes and reads an array, parses a geometry, opens a device.
#include <cstdio>

#include "riner/device.hpp"
#include "riner/geometry.hpp"
#include "riner/io.hpp"
#include "riner/version.hpp"

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const std::filesystem::path out = std::filesystem::path(argv[1]) / "consumer.npy";
  riner::Array a({2, 3}, 1.5f);
  riner::write_array(out, a);
  const riner::ArrayFile f = riner::read_array(out);
  const riner::Geometry g = riner::Geometry::from_json(R"({"type": "parallel2d",
      "detector": {"count": 3, "pitch_mm": 1.0}, "angles": {"count": 2, "range_rad": 3.14},
      "volume": {"shape": [3, 3], "voxel_mm": 1.0}})");
  g.check_measurement_shape(f.array.shape);
  const riner::Device device = riner::Device::open();
  std::printf("riner %s consumer ok on %s\n", RINER_VERSION, device.info().name.c_str());
  return f.array.data == a.data ? 0 : 1;
}
