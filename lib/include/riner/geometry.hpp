// The scan geometry: one convention for the whole product (docs/guide/scans.md, "Geometry
// convention"). Units are millimetres and radians; rotation is about the z axis through the origin,
// which is the centre of the reconstruction grid.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace riner {

enum class GeometryType { kParallel2d, kFan2d, kCone3d, kParallel3d };

const char* geometry_type_name(GeometryType type);

// The uniform angle form of the scan contract: count views from start over range (endpoint
// excluded, so 360 views over 2*pi never repeat a view).
struct UniformAngles {
  std::size_t count = 0;
  double start_rad = 0.0;
  double range_rad = 0.0;
};

struct Geometry {
  GeometryType type = GeometryType::kParallel2d;

  // Detector: u runs along the row, v along the rotation axis (3D only).
  std::size_t n_u = 0;
  std::size_t n_v = 1;
  double pitch_u = 1.0;
  double pitch_v = 1.0;
  double offset_u = 0.0;  // in elements; the centre-of-rotation offset
  double offset_v = 0.0;

  // Fan and cone beam only.
  double source_origin_mm = 0.0;
  double origin_detector_mm = 0.0;

  std::vector<double> angles;                   // one per view, radians
  std::optional<UniformAngles> uniform_angles;  // set when the file used the uniform form

  // Reconstruction grid: [n_y, n_x] in 2D, [n_z, n_y, n_x] in 3D; isotropic voxels.
  std::vector<std::size_t> volume_shape;
  double voxel_mm = 1.0;
  // 3D only: the height of the grid's centre on the axis above the source's plane (the plane
  // of the detector's centre ray; 0: the grid is centred there). A cone-beam slab's grid sits
  // at its own height, and the rays, not the grid, move by as much.
  double grid_centre_z_mm = 0.0;

  bool is_3d() const { return type == GeometryType::kCone3d || type == GeometryType::kParallel3d; }
  bool is_divergent() const {
    return type == GeometryType::kFan2d || type == GeometryType::kCone3d;
  }
  std::size_t n_views() const { return angles.size(); }

  // Shape of the measurement array: [views, n_u] in 2D, [views, n_v, n_u] in 3D.
  std::vector<std::size_t> measurement_shape() const;

  // Throws InputError naming the first bad field.
  void validate() const;

  // Throws InputError if a measurement array of this shape does not belong to this geometry.
  void check_measurement_shape(const std::vector<std::size_t>& shape,
                               std::string_view what = "measurement") const;

  // Parses the scan-contract JSON; `source` names the file in error messages.
  static Geometry from_json(std::string_view json_text, std::string_view source = "geometry");
  static Geometry load(const std::filesystem::path& path);
  std::string to_json() const;
  void save(const std::filesystem::path& path) const;
};

// The most readings, and the most voxels, that one piece of work may hold (a slab, or a scan
// trained or filtered whole): the kernels index both with 32-bit signed integers. Slabs are cut
// within it (slab_plan.hpp).
inline constexpr double kMostElementsPerPiece = 2147483647.0;  // 2^31 - 1
// The readings (views x rows x columns) and the voxels of g, in double (no overflow).
double reading_count(const Geometry& g);
double voxel_count(const Geometry& g);
// InputError "<what>: N readings (or voxels), more than the 2^31 - 1 ..." where the readings or
// the voxels one piece of work holds exceed kMostElementsPerPiece; the Geometry form: all of g's.
void check_piece_size(double readings, double voxels, const std::string& what);
void check_piece_size(const Geometry& g, const std::string& what);
// Whether all of g's readings and voxels fit one piece of work (check_piece_size passes).
bool within_piece_size(const Geometry& g);

// Whether the views go all the way round: no gap between neighbouring angles (mod 2 pi) of more
// than three mean steps.
bool covers_full_turn(const Geometry& g);

// Half acquisition: a full turn with the axis near one end of the detector (its nearer end
// under this share of the farther end's reach from the axis, the axis on the detector). Every
// line through the field is then measured from one side of the axis or the other.
constexpr double kHalfAcquisitionShare = 0.8;
bool is_half_acquisition(const Geometry& g);

// The cylinder (disc in 2D) around the axis that the scan sees whole: its radius from the
// detector's nearer end (a half acquisition's: from its farther end; zero when the axis is off
// the detector), and in 3D its heights in the grid's frame, from the detector's first and last
// rows at the magnification that sees least of them (zero half height when no height is seen
// whole).
struct FieldOfView {
  double radius_mm = 0.0;
  double half_height_mm = 0.0;
  double centre_z_mm = 0.0;
};
FieldOfView field_of_view(const Geometry& g);

// The geometry of detector rows [first, first + count) of g's (3D) detector: the same rows in the
// same place (offset_v moves with the first row), the volume unchanged.
Geometry detector_rows_geometry(const Geometry& g, std::size_t first, std::size_t count);

// One axial slice of a parallel3d geometry on its own: the parallel2d scan of the slice (a
// detector row's rays stay in the slice at its height), the same columns, views and grid.
Geometry axial_slice_geometry(const Geometry& g);

// A parallel2d geometry repeated over `rows` detector rows: the parallel3d stack whose slices,
// a voxel apart, are each a row's 2D scan (axial_slice_geometry gives the 2D one back).
Geometry stack_of_slices(const Geometry& g, std::size_t rows);

// The geometry a measurement of `shape` is read under: a stack of rows under a parallel2d
// geometry ([views, rows, columns]; tooth.h5 beside its 2D geometry.json) as stack_of_slices of
// it, one slice per row; a stack of one row, and any other, as it is (one row is a 2D scan:
// fit_geometry_to_measurement in riner/scan.hpp drops its axis).
Geometry geometry_for_shape(const Geometry& g, const std::vector<std::size_t>& shape);

// Uniform angles start + range * i / count, i = 0..count-1.
std::vector<double> uniform_angles(const UniformAngles& spec);

}  // namespace riner
