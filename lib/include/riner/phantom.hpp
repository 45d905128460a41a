// Analytic phantoms made of ellipses/ellipsoids and rectangles/cuboids: exact values anywhere,
// exact line integrals along any ray (the oracle the projector is tested against), and
// supersampled rasters.
#pragma once

#include <array>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/rays.hpp"

namespace riner {

struct Ellipsoid {
  Vec3 centre;                                                // mm
  Vec3 semi_axes;                                             // mm; z ignored for 2D use
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // world -> local, row-major
  double value = 0.0;                                         // added inside (1/mm)
};

struct Cuboid {
  Vec3 centre;                                                // mm
  Vec3 half_sizes;                                            // mm; z ignored for 2D use
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // world -> local, row-major
  double value = 0.0;                                         // added inside (1/mm)
};

struct Phantom {
  std::vector<Ellipsoid> ellipsoids;
  std::vector<Cuboid> cuboids;

  double value_at(const Vec3& p) const;
  // Exact integral of the phantom along the whole line (mm x 1/mm).
  double line_integral(const Ray& ray) const;
};

// The modified Shepp-Logan head (Toft's contrast), scaled so that its outer ellipse spans
// 0.95 x the smaller half-width of the geometry's grid (and 0.95 x its half-height in 3D);
// values in "head units" (skull 1.0, brain 0.2) times mu_scale (1/mm). The default scale 0.1
// makes the brain water-like, 0.02 / mm.
Phantom shepp_logan(const Geometry& g, double mu_scale = 0.1);

// A faint square sample with sharp corners (issue 29: what the air carving cut off a real
// neutron scan): a square of 0.6 x the grid's smaller width, turned by 20 degrees, whose
// thickest projection is about 0.4 (neutron-like contrast), a dense line inside it (13 x the
// square's mu), a denser disc, a fainter one and a hole. In 3D a square prism of 0.6 x the
// grid's height.
Phantom faint_square(const Geometry& g);

// Real concentric structure (issue 32: a ring about the axis that is object, not artifact): a
// water-like disc (0.02 / mm, radius 0.39 x the grid's smaller width) holding a tube whose wall
// (0.045 / mm, radii 0.234-0.258 x the width, 6 px at 256) is centred on the rotation axis,
// filled with 0.018 / mm, and four off-centre discs. In 3D cylinders along z (0.6 x the
// grid's height).
Phantom tube_wall(const Geometry& g);
// Its wall: the inner and outer radius (mm) and the value there.
struct TubeWallShape {
  double inner_mm = 0.0;
  double outer_mm = 0.0;
  double wall = 0.045;
  double inside = 0.018;
  double water = 0.02;
};
TubeWallShape tube_wall_shape(const Geometry& g);

// Voxel averages over supersample^d points per voxel, on the geometry's grid.
Array rasterize(const Phantom& phantom, const Geometry& g, int supersample = 4);

// Exact line integrals of every detector ray of the geometry, as a measurement array.
Array exact_projections(const Phantom& phantom, const Geometry& g);

}  // namespace riner
