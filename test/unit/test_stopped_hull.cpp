// The metal's full shadow (model/stopped_hull.hpp): voxels whose rays read no light in nearly
// every view, whose values the readings do not hold: found and counted, not changed.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "model/stopped_hull.hpp"
#include "riner/rays.hpp"
#include "support/geometries.hpp"

TEST_SUITE("stopped_hull") {
  TEST_CASE("a metal's middle, read only by bounds, is found; the image is left as it was") {
    // A disc of radius 4 mm at (5, -3): rays within 3.5 of its centre read no light (+inf), its
    // edge rays near the floor (9), the rest the body (1). The image's rim reads 2, its middle
    // -0.2 (a review's disc behind noisy darks: -0.15 under a rim of 1.8).
    const riner::Geometry g = riner::test::small_parallel2d();
    const riner::Vec3 centre{5.0, -3.0, 0.0};
    riner::Array readings({g.n_views(), g.n_u}, 1.0f);
    for (std::size_t v = 0; v < g.n_views(); ++v) {
      const double at = riner::project_to_detector(g, v, centre).u;
      for (std::size_t u = 0; u < g.n_u; ++u) {
        const double d = std::fabs(static_cast<double>(u) - at);
        if (d < 3.5)
          readings(v, u) = std::numeric_limits<float>::infinity();
        else if (d < 4.5)
          readings(v, u) = 9.0f;
      }
    }
    const std::size_t ny = g.volume_shape[0], nx = g.volume_shape[1];
    riner::Array image({ny, nx}, 0.02f);
    for (std::size_t y = 0; y < ny; ++y) {
      for (std::size_t x = 0; x < nx; ++x) {
        const riner::Vec3 p =
            riner::voxel_centre(g, static_cast<double>(x), static_cast<double>(y));
        const double r = std::hypot(p.x - centre.x, p.y - centre.y);
        if (r < 4.0) image(y, x) = r < 2.5 ? -0.2f : 2.0f;
      }
    }
    const riner::model::StoppedHull hull =
        riner::model::find_stopped_hull(image, readings, g, 9.0f);
    CHECK(hull.voxels > 20);  // the disc's middle, about pi 3^2
    CHECK(hull.voxels < 60);  // and not its whole 50 voxels and more beyond
    // The middle's -0.2 and some of the rim's 2.0: between them.
    CHECK(hull.mean > -0.2);
    CHECK(hull.mean < 2.0);
    // No bound, no hull.
    riner::Array lit = readings;
    for (float& x : lit.data) {
      if (std::isinf(x)) x = 12.0f;
    }
    CHECK(riner::model::find_stopped_hull(image, lit, g, 9.0f).voxels == 0);
  }
}
