#include "riner/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "riner/array.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"

namespace riner {

std::vector<std::size_t> Geometry::measurement_shape() const {
  if (is_3d()) return {n_views(), n_v, n_u};
  return {n_views(), n_u};
}

namespace {

// Sixteen turns: beyond any scan's angles in radians, short of 180 or 360 read as radians.
constexpr double kLargestAngleRad = 16.0 * 2.0 * M_PI;
// The detector's reach from the axis under this share of the grid's half width: a unit error.
constexpr double kNarrowestDetectorShare = 20.0;

// Whether the line of `ray` passes through the cylinder of radius `reach` about the axis within
// |z| <= half_height (the grid's extent; z counts from the grid's centre in detector_ray).
bool meets_grid(const Ray& ray, double reach, double half_height) {
  const Vec3& o = ray.origin;
  const Vec3& d = ray.direction;
  const double a = d.x * d.x + d.y * d.y;
  if (a <= 0.0) return std::hypot(o.x, o.y) <= reach;  // along the axis
  const double b = o.x * d.x + o.y * d.y;
  const double c = o.x * o.x + o.y * o.y - reach * reach;
  const double disc = b * b - a * c;
  if (disc < 0.0) return false;
  const double z1 = o.z + d.z * (-b - std::sqrt(disc)) / a;
  const double z2 = o.z + d.z * (-b + std::sqrt(disc)) / a;
  return std::min(z1, z2) <= half_height && std::max(z1, z2) >= -half_height;
}

}  // namespace

void Geometry::validate() const {
  auto fail = [](const std::string& what) { throw InputError(what); };
  if (n_u < 1) fail("detector.count must be >= 1");
  if (is_3d() && n_v < 1) fail("detector.count[1] must be >= 1");
  if (!is_3d() && n_v != 1) fail("a 2D geometry has one detector row");
  if (!(pitch_u > 0.0) || !(pitch_v > 0.0) || !std::isfinite(pitch_u) || !std::isfinite(pitch_v)) {
    fail("detector.pitch_mm must be finite and > 0");
  }
  if (!std::isfinite(offset_u) || !std::isfinite(offset_v))
    fail("detector.offset_px must be finite");
  if (angles.empty()) fail("angles: there must be at least one view");
  double widest = 0.0;
  for (double a : angles) {
    if (!std::isfinite(a)) fail("angles must be finite");
    widest = std::max(widest, std::fabs(a));
  }
  // Views all at one angle see the object from one side only: nothing to reconstruct (FBP
  // gave an image of streaks with only a warning).
  if (angles.size() > 1 &&
      std::all_of(angles.begin(), angles.end(), [&](double a) { return a == angles[0]; })) {
    fail("angles: all " + std::to_string(angles.size()) + " views are at one angle (" +
         std::to_string(angles[0]) + " rad): a scan turns the object");
  }
  // Degrees read as radians (a range of 180 or 360) would be 29 or 57 turns, reconstructed
  // without a word into garbage; no scan turns more than a few times.
  if (widest > kLargestAngleRad) {
    char line[240];
    std::snprintf(line, sizeof(line),
                  "the angles reach %.6g rad, %.3g turns: angles are in radians (one turn is "
                  "6.2832); were degrees given?",
                  widest, widest / (2.0 * M_PI));
    fail(line);
  }
  const std::size_t rank = is_3d() ? 3 : 2;
  if (volume_shape.size() != rank) {
    fail(std::string("volume.shape must have ") + (is_3d() ? "3" : "2") + " entries");
  }
  for (std::size_t n : volume_shape) {
    if (n < 1) fail("volume.shape entries must be >= 1");
  }
  if (!(voxel_mm > 0.0) || !std::isfinite(voxel_mm)) fail("volume.voxel_mm must be finite and > 0");
  if (!std::isfinite(grid_centre_z_mm)) fail("volume.centre_z_mm must be finite");
  if (!is_3d() && grid_centre_z_mm != 0.0) fail("volume.centre_z_mm belongs to a 3D geometry");
  // How far the grid reaches from the axis, in the axial plane.
  const double half_diagonal = 0.5 * voxel_mm *
                               std::hypot(static_cast<double>(volume_shape[rank - 1]),
                                          static_cast<double>(volume_shape[rank - 2]));
  if (is_divergent()) {
    if (!(source_origin_mm > 0.0) || !std::isfinite(source_origin_mm)) {
      fail("source_origin_mm must be finite and > 0");
    }
    if (!(origin_detector_mm > 0.0) || !std::isfinite(origin_detector_mm)) {
      fail("origin_detector_mm must be finite and > 0");
    }
    // The source circles the rotation axis; inside the grid every ray would start in the object.
    if (source_origin_mm <= half_diagonal) {
      fail("source_origin_mm (" + std::to_string(source_origin_mm) +
           ") puts the source inside the reconstruction grid (half-diagonal " +
           std::to_string(half_diagonal) + " mm)");
    }
  }
  // A grid narrower than one detector element at the axis: every voxel behind the same reading.
  const double element_at_axis =
      pitch_u * (is_divergent() ? source_origin_mm / (source_origin_mm + origin_detector_mm) : 1.0);
  const double grid_width =
      voxel_mm * static_cast<double>(std::max(volume_shape[rank - 1], volume_shape[rank - 2]));
  if (grid_width < element_at_axis) {
    char line[240];
    std::snprintf(line, sizeof(line),
                  "the grid is %.4g mm wide, narrower than one detector element at the axis "
                  "(%.4g mm): check volume.voxel_mm (in mm, like detector.pitch_mm)",
                  grid_width, element_at_axis);
    fail(line);
  }
  // A detector beside the grid reads none of it: FBP would give zeros and training nothing.
  const std::vector<double> d = column_ray_distances(*this);
  const auto [low, high] = std::minmax_element(d.begin(), d.end());
  const double nearest = *low > 0.0 ? *low : (*high < 0.0 ? -*high : 0.0);
  // A detector that covers a sliver of the grid is a unit's mistake (a pitch in metres, a voxel
  // in micrometres): FBP gave garbage, or NaN, without a word. A region of interest or a half
  // acquisition still covers far more than this share of the grid's width.
  const double reach = std::max(std::fabs(*low), std::fabs(*high));
  if (reach * kNarrowestDetectorShare < 0.5 * grid_width) {
    char line[300];
    std::snprintf(line, sizeof(line),
                  "the detector's rays reach %.4g mm from the axis, under 1/%.0f of the grid's "
                  "half width (%.4g mm): check detector.pitch_mm and volume.voxel_mm (both in mm)",
                  reach, kNarrowestDetectorShare, 0.5 * grid_width);
    fail(line);
  }
  if (nearest >= half_diagonal) {
    char line[240];
    std::snprintf(line, sizeof(line),
                  "no detector ray crosses the reconstruction grid: the rays pass %.4g mm or more "
                  "from the axis, the grid reaches %.4g mm (check detector.offset_px, pitch_mm "
                  "and volume.voxel_mm)",
                  nearest, half_diagonal);
    fail(line);
  }
  if (!is_3d()) return;
  // And some row's rays must pass the grid's height (rows offset far up, or a grid far along
  // the axis, gave FBP zeros too): through the column nearest the axis, every row.
  const auto nearest_column = static_cast<double>(
      std::min_element(d.begin(), d.end(),
                       [](double x, double y) { return std::fabs(x) < std::fabs(y); }) -
      d.begin());
  const double half_height = 0.5 * voxel_mm * static_cast<double>(volume_shape[0]);
  for (std::size_t v = 0; v < n_v; ++v) {
    const Ray ray = detector_ray(*this, 0, nearest_column, static_cast<double>(v));
    if (meets_grid(ray, half_diagonal, half_height)) return;
  }
  fail(
      "no detector row's rays cross the reconstruction grid: the rows see above or below it "
      "(check detector.offset_px's row offset, pitch_mm and volume.centre_z_mm)");
}

void Geometry::check_measurement_shape(const std::vector<std::size_t>& shape,
                                       std::string_view what) const {
  const std::vector<std::size_t> expected = measurement_shape();
  if (shape == expected) return;
  std::string message = std::string(what) + " has shape " + shape_string(shape) + " but the " +
                        geometry_type_name(type) + " geometry expects " + shape_string(expected) +
                        (is_3d() ? " [views, rows, columns]" : " [views, elements]");
  if (shape.size() == expected.size() && shape[0] != expected[0]) {
    message += ": it has " + std::to_string(shape[0]) + " views but the geometry lists " +
               std::to_string(expected[0]) + " angles";
  }
  throw InputError(message);
}

namespace {

// How far the detector's two ends lie from the axis (mm on the detector), nearer end first;
// {0, 0} when the axis is off the detector.
std::pair<double, double> detector_ends(std::size_t n, double offset, double pitch) {
  const double lo = (-0.5 - 0.5 * (static_cast<double>(n) - 1.0) + offset) * pitch;
  const double hi =
      (static_cast<double>(n) - 0.5 - 0.5 * (static_cast<double>(n) - 1.0) + offset) * pitch;
  if (!(lo < 0.0 && hi > 0.0)) return {0.0, 0.0};
  return {std::min(-lo, hi), std::max(-lo, hi)};
}

}  // namespace

double reading_count(const Geometry& g) {
  return static_cast<double>(g.n_views()) * static_cast<double>(g.n_u) *
         static_cast<double>(g.is_3d() ? g.n_v : 1);
}

double voxel_count(const Geometry& g) {
  double n = 1.0;
  for (const std::size_t d : g.volume_shape) n *= static_cast<double>(d);
  return n;
}

void check_piece_size(double readings, double voxels, const std::string& what) {
  const auto refuse = [&](double count, const char* of) {
    char line[320];
    std::snprintf(line, sizeof(line),
                  ": %.4g %s, more than the 2^31 - 1 one piece of work may hold (the kernels' "
                  "32-bit indices): a smaller piece (slabs of detector rows: riner reconstruct "
                  "and riner fbp cut them by themselves)",
                  count, of);
    throw InputError(what + line);
  };
  if (readings > kMostElementsPerPiece) refuse(readings, "readings");
  if (voxels > kMostElementsPerPiece) refuse(voxels, "voxels");
}

void check_piece_size(const Geometry& g, const std::string& what) {
  check_piece_size(reading_count(g), voxel_count(g), what);
}

bool within_piece_size(const Geometry& g) {
  return reading_count(g) <= kMostElementsPerPiece && voxel_count(g) <= kMostElementsPerPiece;
}

bool covers_full_turn(const Geometry& g) {
  const std::size_t n = g.n_views();
  if (n < 2) return false;
  std::vector<double> phase(n);
  for (std::size_t i = 0; i < n; ++i) {
    phase[i] = std::fmod(g.angles[i], 2.0 * M_PI);
    if (phase[i] < 0.0) phase[i] += 2.0 * M_PI;
  }
  std::sort(phase.begin(), phase.end());
  double largest_gap = phase.front() + 2.0 * M_PI - phase.back();
  for (std::size_t i = 1; i < n; ++i) largest_gap = std::max(largest_gap, phase[i] - phase[i - 1]);
  return largest_gap <= 3.0 * 2.0 * M_PI / static_cast<double>(n);
}

bool is_half_acquisition(const Geometry& g) {
  const auto [nearer, farther] = detector_ends(g.n_u, g.offset_u, g.pitch_u);
  return farther > 0.0 && nearer < kHalfAcquisitionShare * farther && covers_full_turn(g);
}

FieldOfView field_of_view(const Geometry& g) {
  const auto [nearer, farther] = detector_ends(g.n_u, g.offset_u, g.pitch_u);
  const double u = is_half_acquisition(g) ? farther : nearer;
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  FieldOfView f;
  f.radius_mm = g.is_divergent() ? g.source_origin_mm * u / std::hypot(u, sdd) : u;
  if (!g.is_3d()) return f;
  // The rows' outer edges above the source's plane (mm on the detector; pitch_v > 0).
  double low = detector_row_mm(g, -0.5);
  double high = detector_row_mm(g, static_cast<double>(g.n_v) - 0.5);
  if (g.is_divergent()) {
    // A height is seen whole where its nearest and farthest points both land on the rows.
    const double near = (g.source_origin_mm - f.radius_mm) / sdd;
    const double far = (g.source_origin_mm + f.radius_mm) / sdd;
    low *= low < 0.0 ? near : far;
    high *= high > 0.0 ? near : far;
  }
  f.half_height_mm = std::max(0.0, 0.5 * (high - low));
  f.centre_z_mm = 0.5 * (high + low) - g.grid_centre_z_mm;
  return f;
}

Geometry geometry_for_shape(const Geometry& g, const std::vector<std::size_t>& shape) {
  return g.type == GeometryType::kParallel2d && shape.size() == 3 && shape[1] > 1
             ? stack_of_slices(g, shape[1])
             : g;
}

Geometry stack_of_slices(const Geometry& g, std::size_t rows) {
  if (g.type != GeometryType::kParallel2d || rows == 0) {
    throw InputError("a stack of slices is made of a parallel2d geometry and one row or more");
  }
  Geometry s = g;
  s.type = GeometryType::kParallel3d;
  s.n_v = rows;
  s.pitch_v = g.voxel_mm;
  s.offset_v = 0.0;
  s.volume_shape = {rows, g.volume_shape[0], g.volume_shape[1]};
  return s;
}

Geometry axial_slice_geometry(const Geometry& g) {
  if (g.type != GeometryType::kParallel3d) {
    throw InputError(std::string("an axial slice is a 2D scan of its own only in a parallel3d "
                                 "geometry, not ") +
                     geometry_type_name(g.type));
  }
  Geometry s;
  s.type = GeometryType::kParallel2d;
  s.n_u = g.n_u;
  s.pitch_u = g.pitch_u;
  s.offset_u = g.offset_u;
  s.angles = g.angles;
  s.uniform_angles = g.uniform_angles;
  s.volume_shape = {g.volume_shape[1], g.volume_shape[2]};
  s.voxel_mm = g.voxel_mm;
  return s;
}

Geometry detector_rows_geometry(const Geometry& g, std::size_t first, std::size_t count) {
  Geometry cut = g;
  cut.n_v = count;
  // Row r of the whole detector sits at (r - (n_v-1)/2 + offset_v) pitches; keep it there.
  cut.offset_v = g.offset_v + static_cast<double>(first) +
                 (static_cast<double>(count) - 1.0) / 2.0 -
                 (static_cast<double>(g.n_v) - 1.0) / 2.0;
  return cut;
}

}  // namespace riner
