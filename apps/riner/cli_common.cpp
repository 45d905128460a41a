#include "cli_common.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/rays.hpp"
#include "riner/simulate.hpp"

namespace riner::app {

void add_engine_flags(Args& args) {
  args.option("engine", "NAME", "opencl, or reference (the CPU twin of every kernel)", "opencl");
  args.option("device", "SEL", "OpenCL device: index or name substring (see riner devices)", "");
}

Engine engine_from(const Args& args) { return parse_engine(args.get("engine")); }

std::optional<Device> device_from(const Args& args, Engine engine) {
  if (engine != Engine::kOpenCL) return std::nullopt;
  return Device::open(args.get("device"));
}

std::filesystem::path make_output_dir(const std::string& path) {
  refuse_overwriting_input(path);  // a stack's folder
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (!std::filesystem::is_directory(path)) {
    throw InputError(path + ": cannot create the output folder" +
                     (error ? " (" + error.message() + ")" : std::string()));
  }
  // A file made and removed: a folder the process may not write into fails here, not after
  // an hour of training.
  const std::filesystem::path probe =
      std::filesystem::path(path) / (".riner-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0 && errno == EEXIST) return path;  // another machine's rank of that pid: writable
  if (fd < 0) {
    throw InputError(path + ": cannot write into the output folder (" + std::strerror(errno) +
                     ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return path;
}

void refuse_outputs_over_inputs(const std::filesystem::path& out,
                                const std::vector<std::string>& names) {
  for (const std::string& name : names) refuse_overwriting_input(out / name);
}

void clear_previous_outputs(const std::filesystem::path& out,
                            const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    refuse_overwriting_input(out / name);
    std::error_code error;
    std::filesystem::remove(out / name, error);
    if (error) {
      throw Error((out / name).string() + ": cannot remove an earlier run's output (" +
                  error.message() + ")");
    }
  }
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

Geometry geometry_from(const std::string& name_or_path) {
  if (is_preset_geometry(name_or_path)) return preset_geometry(name_or_path);
  return Geometry::load(name_or_path);
}

void Console::line(const std::string& text) const {
  if (quiet_) return;
  std::fprintf(json_ ? stderr : stdout, "%s\n", text.c_str());
}

void Console::summary(const nlohmann::json& json) const {
  if (json_) std::printf("%s\n", json.dump(1).c_str());
}

nlohmann::json metrics_json(double psnr, double ssim, double mae, double rmse, double data_range) {
  return {
      {"psnr_db", psnr}, {"ssim", ssim}, {"mae", mae}, {"rmse", rmse}, {"data_range", data_range}};
}

std::vector<std::string> split_commas(const std::string& list) {
  std::vector<std::string> items;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    items.push_back(list.substr(begin, end - begin));
    begin = end + 1;
  }
  return items;
}

void print_quality_doubts(Console& console, const QualityReport& q) {
  char line[200];
  if (q.centre.sigmas > 1.0) {
    std::snprintf(line, sizeof(line),
                  "note: near the rotation axis the image departs from FBP's broad profile by "
                  "%.1f times FBP's own noise there (a disc or dip rings can hide)",
                  q.centre.sigmas);
    console.line(line);
  }
  if (q.specks_per_10k > q.fbp_specks_per_10k) {
    std::snprintf(line, sizeof(line),
                  "note: %.1f isolated specks per 10^4 pixels against FBP's %.1f", q.specks_per_10k,
                  q.fbp_specks_per_10k);
    console.line(line);
  }
  if (q.lost.share > kLostObjectShare) {
    std::snprintf(line, sizeof(line),
                  "note: %.2f%% of the field (%zu pixels) shows air where FBP clearly sees "
                  "object: look there before trusting the image",
                  100.0 * q.lost.share, q.lost.pixels);
    console.line(line);
  }
  if (q.edge_strength < kSoftEdgeRatio * q.fbp_edge_strength) {
    std::snprintf(line, sizeof(line),
                  "note: edges at %.0f%% of FBP's strength (99th percentile of the gradient "
                  "after a %.0f-px Gaussian): the image may be blurred",
                  100.0 * q.edge_strength / q.fbp_edge_strength, q.edge_scale_px);
    console.line(line);
  }
}


namespace {

// The share of a detector's elements found as large stripes beyond which the console doubts it.
constexpr double kLargeStripeShareNoted = 0.1;

}  // namespace

void note_large_stripes(Console& console, const DestripeReport& report) {
  const std::size_t elements = report.removed.size();
  if (static_cast<double>(report.large.size()) <= kLargeStripeShareNoted * static_cast<double>(elements)) {
    return;
  }
  char line[400];
  std::snprintf(line, sizeof(line),
                "note: %zu of %zu elements (%.0f%%) were found as large stripes, more than a "
                "detector has: the object's structure read as stripes, replaced by smoothed "
                "values; check the image (riner destripe --reconstruct reports lost object), or "
                "use the method sorting, filtering or normalise",
                report.large.size(), elements,
                100.0 * static_cast<double>(report.large.size()) / static_cast<double>(elements));
  console.line(line);
}

void note_filled_rows(const Console& console, const std::vector<std::size_t>& rows) {
  if (rows.empty()) return;
  std::string list;
  for (std::size_t i = 0; i < rows.size() && i < 8; ++i)
    list += (i ? ", " : "") + std::to_string(rows[i]);
  if (rows.size() > 8) list += ", ... (" + std::to_string(rows.size()) + " rows)";
  console.line("note: detector row" + std::string(rows.size() > 1 ? "s " : " ") + list +
               " read nothing in any view: trained on the line between the rows beside them, as "
               "FBP fills them; the slices only they see are interpolated, not measured");
}

void note_grid_beyond_rays(const Console& console, const Geometry& g) {
  const double ratio = grid_beyond_rays(g);
  if (!(ratio > kGridBeyondRaysNoted)) return;
  char line[320];
  std::snprintf(line, sizeof(line),
                "note: the grid reaches %.3g times as far from the axis as the detector's rays: "
                "its outer part is seen by no ray (check volume.voxel_mm and volume.shape, in mm "
                "like detector.pitch_mm)",
                ratio);
  console.line(line);
}

void note_object_beyond_detector(const Console& console, const Scan& scan) {
  if (is_half_acquisition(scan.geometry)) return;  // one end under the object by design
  const double share = edge_reading_share(scan.measurement);
  if (!(share > kEdgeShareNoted)) return;
  char line[320];
  std::snprintf(line, sizeof(line),
                "note: the object reaches the detector's ends (they read %.0f%% of each view's "
                "largest reading): it is wider than the field of view, so FBP's image cups and "
                "what lies outside it is not measured",
                100.0 * share);
  console.line(line);
}

void note_missing_lines(const Console& console, const Geometry& g) {
  if (!views_miss_lines(g)) return;
  console.line(
      "warning: the views miss part of the circle (a parallel beam's half turn, a fan's half "
      "turn plus the fan): the field along the lines never measured rests on no reading");
}

void note_unphysical_readings(const Console& console, const Scan& scan) {
  const double largest = median_view_largest(scan.measurement, scan.geometry.n_views());
  if (!(largest > kMostLineIntegral)) return;
  char line[320];
  std::snprintf(line, sizeof(line),
                "note: the views' largest readings are about %.3g, beyond any detector's -ln(I/I0) "
                "(under %.0f): readings stored scaled (x1000, as integers) should be divided back "
                "first, or the detector's responses cannot be learnt",
                largest, kMostLineIntegral);
  console.line(line);
}

void note_starved_readings(const Console& console, std::size_t count, float floor) {
  if (count == 0) return;
  char line[320];
  std::snprintf(line, sizeof(line),
                "of the readings not finite, %zu of +inf (no light) are a beam the object stopped "
                "(metal?): trained as at least %.4g, the largest finite reading of nine views in "
                "ten, not as 0 "
                "(summary.json starved_readings)",
                count, static_cast<double>(floor));
  console.line(line);
}

void note_stopped_hull(const Console& console, std::size_t voxels, std::optional<double> mean) {
  if (voxels == 0) return;
  char left[160] = " (summary.json stopped_hull_voxels)";
  if (mean) {
    std::snprintf(left, sizeof(left),
                  "; the image shows what training left there, %.3g on average (summary.json "
                  "stopped_hull)",
                  *mean);
  }
  console.line("note: " + std::to_string(voxels) +
               " voxels lie in the full shadow of what stopped the beam (their rays read no "
               "light in nearly every view): the readings say only that their rays are dense, "
               "not whether they hold a solid metal's middle or a hollow one's contents" +
               left);
}

void note_non_finite(const Console& console, std::size_t non_finite) {
  if (non_finite == 0) return;
  console.line(std::to_string(non_finite) +
               " measurements are NaN, infinite or corrupt (dead elements?): the unread ones count "
               "as 0 and their elements' beta learns to switch them off (an element that reads "
               "nothing starts off)");
}

}  // namespace riner::app
