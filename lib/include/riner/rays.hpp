// Rays of a scan geometry and their clipping to the reconstruction region: the one place that
// simulation, FBP/FDK and Riner's sampler get their rays from (kernels/ray_geometry.cl is the
// device copy of the same formulas, cross-checked against this one).
#pragma once

#include <cstddef>

#include <vector>

#include "riner/geometry.hpp"

namespace riner {

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

// origin + t * direction, direction of unit length, t in mm. 2D rays have z = 0.
// Fan/cone rays start at the source; parallel rays at their closest point to the rotation axis.
struct Ray {
  Vec3 origin;
  Vec3 direction;
};

// A view's angle as its cosine and sine, for loops over many rays or points per view: the
// overloads that take it give the same numbers as those that take the view, without a sin and
// cos per call.
struct ViewRotation {
  double c = 1.0;
  double s = 0.0;
  static ViewRotation of(const Geometry& g, std::size_t view);
};

// The ray to detector element (u, v) at `view`. u and v are element indices and may be
// fractional (positions inside an element); v is ignored in 2D.
Ray detector_ray(const Geometry& g, std::size_t view, double u, double v = 0.0);
Ray detector_ray(const Geometry& g, const ViewRotation& rotation, double u, double v = 0.0);

// Signed distance from the rotation axis, in the axial plane, of each detector column's ray at
// view 0 (through the detector's middle row in 3D): a ring about the axis projects the same at
// d and -d, and a ray at d has its conjugate at -d.
std::vector<double> column_ray_distances(const Geometry& g);

// How many times farther from the axis the grid reaches (half its wider axial side) than the
// detector's rays do (the farthest column's ray, to its element's edge): about 1 for a grid
// fitted to the field of view, and far above it when a length is in another unit.
double grid_beyond_rays(const Geometry& g);

// Where detector row v (fractional: an element's edges at v -+ 0.5) sits above the source's
// plane, in mm on the detector (3D; before any grid_centre_z_mm).
double detector_row_mm(const Geometry& g, double v);

// Where detector element (u, v) sits in the world at `view` (its centre for integer indices).
Vec3 detector_position(const Geometry& g, std::size_t view, double u, double v = 0.0);
Vec3 detector_position(const Geometry& g, const ViewRotation& rotation, double u, double v = 0.0);

// Where the ray through world point p lands at `view`: fractional element indices (u, v) (the
// inverse of detector_position along the ray; v = 0 in 2D), and the magnification there
// (detector mm per mm at p across the ray; 1 for parallel beams). Undefined for a point at or
// behind a fan/cone source.
struct DetectorPoint {
  double u = 0.0;
  double v = 0.0;
  double magnification = 1.0;
};
DetectorPoint project_to_detector(const Geometry& g, std::size_t view, const Vec3& p);
DetectorPoint project_to_detector(const Geometry& g, const ViewRotation& rotation, const Vec3& p);

// Parameter interval [enter, exit] of a ray inside a region; empty when it misses.
struct Segment {
  double enter = 0.0;
  double exit = 0.0;
  bool empty() const { return !(exit > enter); }
  double length() const { return empty() ? 0.0 : exit - enter; }
};

// The reconstruction box: |x| <= n_x p / 2, |y| <= n_y p / 2 (and |z| <= n_z p / 2 in 3D).
Segment clip_to_box(const Geometry& g, const Ray& ray);

// The inscribed disk (2D) or cylinder (3D, clipped to the box in z), radius min(n_x, n_y) p / 2:
// the region every view sees in a full scan.
Segment clip_to_cylinder(const Geometry& g, const Ray& ray);

// World coordinates of the centre of voxel (k, i[, l]) = (column, row[, slice]).
Vec3 voxel_centre(const Geometry& g, double column, double row, double slice = 0.0);

}  // namespace riner
