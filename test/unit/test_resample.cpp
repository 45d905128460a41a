// resample_to_grid: trilinear interpolation reproduces linear functions exactly, the grid and
// the image share their centre, and the grid beyond the image reads 0.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/resample.hpp"
#include "riner/simulate.hpp"

namespace {

// mm from the centre of index i on an axis of n voxels of `spacing`.
double centred_mm(std::size_t i, std::size_t n, double spacing) {
  return (static_cast<double>(i) - 0.5 * (static_cast<double>(n) - 1.0)) * spacing;
}

double ramp(double z, double y, double x) { return 1.0 + 0.01 * x - 0.02 * y + 0.03 * z; }

}  // namespace

TEST_SUITE("resample") {
  TEST_CASE("an anisotropic volume onto the parallel3d grid: linear values exact, 0 outside") {
    const riner::Geometry g = riner::preset_geometry("parallel3d");  // 100 x 256 x 256, 1 mm
    const std::vector<double> spacing{1.5, 3.2, 3.2};                // the shared head volume's
    riner::Array volume({93, 64, 64});
    for (std::size_t z = 0; z < 93; ++z)
      for (std::size_t y = 0; y < 64; ++y)
        for (std::size_t x = 0; x < 64; ++x)
          volume.data[(z * 64 + y) * 64 + x] = static_cast<float>(
              ramp(centred_mm(z, 93, 1.5), centred_mm(y, 64, 3.2), centred_mm(x, 64, 3.2)));
    const riner::Array out = riner::resample_to_grid(volume, spacing, g);
    REQUIRE(out.shape == g.volume_shape);
    const double half_x = 0.5 * 63 * 3.2;  // the outermost voxel centres
    std::size_t inside = 0, outside = 0;
    for (std::size_t k = 0; k < 100; k += 3) {
      for (std::size_t i = 0; i < 256; i += 5) {
        for (std::size_t j = 0; j < 256; j += 5) {
          const double z = centred_mm(k, 100, 1.0), y = centred_mm(i, 256, 1.0),
                       x = centred_mm(j, 256, 1.0);
          const float v = out.data[(k * 256 + i) * 256 + j];
          if (std::fabs(x) <= half_x && std::fabs(y) <= half_x) {
            ++inside;
            CHECK(v == doctest::Approx(ramp(z, y, x)).epsilon(1e-5));
          } else if (std::fabs(x) > half_x + 1.6 || std::fabs(y) > half_x + 1.6) {
            ++outside;
            CHECK(v == 0.0f);
          }
        }
      }
    }
    CHECK(inside > 1000);
    CHECK(outside > 1000);
  }

  TEST_CASE("an image already on the grid comes back unchanged") {
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");  // 256 x 256, 1 mm
    riner::Array image({256, 256});
    for (std::size_t p = 0; p < image.size(); ++p) image.data[p] = static_cast<float>(p % 97);
    CHECK(riner::resample_to_grid(image, {1.0, 1.0}, g).data == image.data);
  }

  TEST_CASE("bad inputs") {
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    CHECK_THROWS_WITH_AS(riner::resample_to_grid(riner::Array({4, 4, 4}), {1, 1, 1}, g),
                         "resample: a 3D image for a 2D grid", riner::InputError);
    CHECK_THROWS_WITH_AS(riner::resample_to_grid(riner::Array({4, 4}), {1}, g),
                         "resample: 1 spacings for a 2D image", riner::InputError);
    CHECK_THROWS_WITH_AS(riner::resample_to_grid(riner::Array({4, 4}), {1, NAN}, g),
                         "resample: spacings must be > 0", riner::InputError);
  }
}
