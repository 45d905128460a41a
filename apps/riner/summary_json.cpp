#include "summary_json.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "riner/error.hpp"
#include "riner/execution_plan.hpp"
#include "riner/fbp.hpp"

namespace riner::app {

namespace {

// training.warm_start: what the classical start did; null for a cold start.
nlohmann::json warm_start_json(const std::optional<WarmStartStats>& w) {
  if (!w) return nullptr;
  return {{"method", w->method},
          {"fit_steps", w->fit_steps},
          {"fit_pixels", w->fit_pixels},
          {"fit_residual_per_mm", w->fit_residual},
          {"mean_abs_log_alpha", w->mean_abs_log_alpha},
          {"seconds", w->seconds}};
}

// Axial slices of a volume the quality report measures, spread over it.
constexpr std::size_t kQualitySlices = 16;

nlohmann::json ring_summary(const std::optional<RingCorrection>& rings) {
  if (!rings) return {{"applied", false}};
  double largest = 0.0;
  for (double v : rings->profile) largest = std::max(largest, std::fabs(v));
  nlohmann::json out{{"applied", rings->applied},
                     {"measured_radii", rings->measured_radii},
                     {"mean_response_change", rings->mean_response_change},
                     {"radius_step_mm", rings->radius_step_mm},
                     {"largest_ring_per_mm", largest}};
  // The detector-response correction's evidence (null: no odd structure at all).
  if (rings->even_to_odd != 0.0) {
    out["even_to_odd"] = std::isfinite(rings->even_to_odd) ? nlohmann::json(rings->even_to_odd)
                                                           : nlohmann::json(nullptr);
  }
  // The radial-gradient and response corrections' scale, and the radii they left to the mirror
  // step's objects.
  if (rings->scale_px > 0.0) {
    out["scale_px"] = rings->scale_px;
    out["radii_kept_for_objects"] = rings->radii_kept_for_objects;
  }
  // The mirror correction's evidence.
  if (rings->elements_moved != 0 || rings->largest_even_sigmas != 0.0 ||
      rings->even_sigmas_needed != 0.0) {
    out["elements_moved"] = rings->elements_moved;
    out["largest_even_sigmas"] = rings->largest_even_sigmas;
    out["even_sigmas_needed"] = rings->even_sigmas_needed;
  }
  return out;
}

nlohmann::json volume_ring_summary(const std::optional<VolumeRingCorrection>& rings) {
  if (!rings) return nullptr;
  return {{"slices_corrected", rings->slices},
          {"air_applied", rings->air_applied},
          {"gradient_applied", rings->gradient_applied},
          {"response_applied", rings->response_applied},
          {"gradient_after_response_applied", rings->gradient_after_response_applied},
          {"mirror_applied", rings->mirror_applied},
          {"mean_response_change", rings->mean_response_change},
          {"note", rings->note}};
}

}  // namespace

nlohmann::json quality_summary(const QualityCheck& check) {
  const QualityReport& q = check.image;
  nlohmann::json out = {{"fbp_noise_per_mm", q.noise},
                        {"ring_index", q.ring_index},
                        {"fbp_ring_index", q.fbp_ring_index},
                        {"specks_per_10k_pixels", q.specks_per_10k},
                        {"fbp_specks_per_10k_pixels", q.fbp_specks_per_10k},
                        {"edge_strength_per_mm", q.edge_strength},
                        {"fbp_edge_strength_per_mm", q.fbp_edge_strength},
                        {"edge_scale_px", q.edge_scale_px},
                        {"lost_object",
                         {{"share", q.lost.share},
                          {"pixels", q.lost.pixels},
                          {"arc_share", q.lost.arc_share},
                          {"arc_pixels", q.lost.arc_pixels},
                          {"fbp_noise_per_mm", q.lost.fbp_noise}}},
                        {"slices_measured", check.slices},
                        {"volume_slices", check.volume_slices},
                        {"centre", nullptr}};
  // Measured on a 2D image (a classical filter's too, whose console note it backs), not on a
  // volume's slices; the field's own only where there is a field.
  if (check.field || (check.volume_slices == 0 && q.centre.fbp_noise > 0.0)) {
    out["centre"] = {{"radius_px", q.centre.radius_px},
                     {"largest_broad_deviation_from_fbp_per_mm", q.centre.deviation},
                     {"at_px", q.centre.at_px},
                     {"fbp_profile_noise_per_mm", q.centre.fbp_noise},
                     {"fbp_noise_sigmas", q.centre.sigmas},
                     {"field_fbp_noise_sigmas",
                      check.field ? nlohmann::json(check.field->sigmas) : nlohmann::json()}};
  }
  return out;
}

void require_quality_grid(const Geometry& g) {
  const std::size_t rank = g.volume_shape.size();
  const std::size_t ny = g.volume_shape[rank - 2];
  const std::size_t nx = g.volume_shape[rank - 1];
  if (ny < kQualitySmallestSide || nx < kQualitySmallestSide) {
    throw InputError("the grid's slices are " + std::to_string(ny) + " x " + std::to_string(nx) +
                     " pixels: the quality report against FBP needs at least " +
                     std::to_string(kQualitySmallestSide) + " x " +
                     std::to_string(kQualitySmallestSide) + " (volume.shape)");
  }
}

void require_memory(const Geometry& g) {
  // Far below what a run takes per voxel and per reading (the image, the field, the ring
  // corrections, the quality check's FBP; the readings, their rays and weights): a bound that
  // refuses only what cannot fit at all.
  constexpr double kBytesPerVoxel = 32.0;
  constexpr double kBytesPerReading = 16.0;
  const double voxels = static_cast<double>(shape_size(g.volume_shape));
  const double readings = static_cast<double>(g.n_views()) * static_cast<double>(g.n_u) *
                          static_cast<double>(g.is_3d() ? g.n_v : 1);
  const double needed = kBytesPerVoxel * voxels + kBytesPerReading * readings;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return;
  const double memory = static_cast<double>(pages) * static_cast<double>(page);
  if (needed > memory) {
    char line[300];
    std::snprintf(line, sizeof(line),
                  "the grid %s and %.3g readings need at least %.1f GiB, more than the "
                  "machine's %.1f GiB: a smaller grid (volume.shape, volume.voxel_mm), or a "
                  "stack by slabs",
                  shape_string(g.volume_shape).c_str(), readings, needed / 1073741824.0,
                  memory / 1073741824.0);
    throw InputError(line);
  }
}

void require_training(const RinerConfig& c) {
  if (c.training.steps == 0 && c.training.warm_start == "off") {
    throw InputError(
        "training.steps is 0 and there is no warm start: the image would be the untrained "
        "field's noise; give 1 or more steps (-1: the scan's)");
  }
}

QualityCheck check_quality(const Reconstructor& r, const ReconstructionResult& result,
                           const std::optional<Device>& device) {
  FbpOptions options;
  // A metal's edges read at the floor outweigh the image's own in the edge measure: a review's
  // fan beam with two pins was called blurred (15% of FBP's edges, where it had 200%).
  options.stopped_beam_at_floor = false;
  options.engine = r.config().engine;
  options.device = device;
  const Geometry& g = r.scan().geometry;
  if (!g.is_3d()) {
    const Array fbp_image = fbp(r.scan(), options);
    QualityCheck check{quality_against_fbp(result.image, fbp_image, field_radius_px(g)), {}, {}, 0};
    check.field = centre_deviation(result.field_image, fbp_image);
    return check;
  }
  // The measures are per slice: a spread of them tells as much as the whole volume, and the
  // FDK of all of it would cost more than the set-up of training (docs/history/RESULTS.md, issue
  // 14).
  options.slices = SliceSelection::spread(g.volume_shape[0], kQualitySlices);
  const std::vector<std::size_t> slices = options.slices.slices(g.volume_shape[0]);
  Array image({slices.size(), g.volume_shape[1], g.volume_shape[2]});
  auto into = image.data.begin();
  for (std::size_t z : slices) {
    const Array slice = axial_slice(result.image, z);
    into = std::copy(slice.data.begin(), slice.data.end(), into);
  }
  return {quality_against_fbp(image, fbp(r.scan(), options), field_radius_px(g)),
          {},
          slices,
          g.volume_shape[0]};
}

nlohmann::json run_summary(const Reconstructor& r, const ReconstructionResult& result,
                           const QualityCheck& quality) {
  const TrainingStats stats = r.stats();
  const std::vector<DeadElement> dead_report = r.dead_element_report();
  std::vector<std::size_t> dead;
  for (const DeadElement& d : dead_report) dead.push_back(d.element);
  const std::vector<LossRecord> history = r.history();
  const nlohmann::json gradient_again = ring_summary(result.gradient_after_response_rings);
  return {
      {"shape", result.image.shape},
      {"steps", stats.steps},
      {"steps_planned", stats.steps_planned},
      {"rays_per_step", stats.rays_per_step},
      {"draws_per_ray_planned", stats.draws_per_ray_planned},
      {"samples_per_voxel_planned", stats.samples_per_voxel_planned},
      {"stopped_on_plateau", stats.stopped_on_plateau},
      // The step --resume went on from (a checkpoint), null for a run in one go.
      {"resumed_at_step",
       stats.resumed_at_step > 0 ? nlohmann::json(stats.resumed_at_step) : nlohmann::json(nullptr)},
      {"seconds", stats.seconds},
      {"samples", stats.samples},
      {"samples_per_second", stats.seconds > 0 ? stats.samples / stats.seconds : 0.0},
      {"parameters", stats.parameters},
      {"non_finite_measurements", stats.non_finite},
      {"starved_readings", stats.starved_readings},
      {"starved_floor", stats.starved_floor},
      {"filled_rows", stats.filled_rows},
      {"field_per_mu", stats.field_per_mu},
      {"dead_elements", dead},
      {"dead_element_reasons", dead_elements_json(dead_report)},
      {"changing_elements", changing_elements_json(r.changing_elements())},
      {"engine", stats.engine},
      {"device", stats.device},
      {"plan", stats.plan ? nlohmann::json::parse(stats.plan->to_json()) : nlohmann::json()},
      {"skip_air",
       {{"applied", stats.air_skipped},
        {"grid_fraction_sampled", stats.inside_fraction},
        {"grid_fraction_skipped", stats.air_skipped ? 1.0 - stats.inside_fraction : 0.0},
        {"samples_kept_fraction", stats.samples_kept_fraction},
        {"noise_sigma", stats.noise},
        {"outlier_views", stats.air_outlier_views},
        {"fbp_check",
         {{"bin", stats.air_fbp_bin},
          {"noise_per_mm", stats.air_fbp_noise},
          {"voxels_kept", stats.air_kept_by_fbp}}},
        {"skipped_rays", stats.skipped_rays},
        {"skipped_ray_largest_excess", stats.skipped_ray_excess},
        {"skipped_ray_largest_sigmas", stats.skipped_ray_sigmas},
        {"skipped_ray_threshold_sigmas", stats.skipped_ray_threshold},
        {"skipped_rays_above_threshold", stats.skipped_rays_above},
        {"skipped_rays_above_threshold_near_object", stats.skipped_rays_near},
        {"note", r.config().training.skip_air ? stats.air_note : "off (training.skip_air)"}}},
      {"alpha_rate", {{"scale", stats.alpha_rate}, {"stripe_rms", stats.stripe_rms}}},
      {"alpha_model",
       {{"model", alpha_model_name(stats.alpha_model)},
        {"setting", alpha_model_name(r.config().training.alpha_model)},
        {"factor_evidence", stats.alpha_factor_explained >= 0.0
                                ? nlohmann::json(stats.alpha_factor_explained)
                                : nlohmann::json()}}},
      {"level_warmup",
       {{"steps", stats.level_warmup_steps}, {"relative_noise", stats.relative_noise}}},
      {"tail_average",
       {{"steps", stats.tail_average_steps}, {"snapshots", stats.tail_average_snapshots}}},
      {"lr_decay", {{"smooth", stats.lr_decay_smooth}, {"voxels_per_ray", stats.voxels_per_ray}}},
      {"warm_start", warm_start_json(stats.warm_start)},
      {"coverage",
       {{"rays", stats.coverage.rays},
        {"rays_per_element_fewest", stats.coverage.fewest},
        {"rays_per_element_median", stats.coverage.median},
        {"rays_per_element_most", stats.coverage.most},
        {"elements_under_10_rays", stats.coverage.elements_under_10}}},
      {"memory",
       {{"peak_host_mb", static_cast<double>(stats.peak_host_bytes) / 1048576.0},
        {"peak_device_buffers_mb", static_cast<double>(stats.peak_device_bytes) / 1048576.0}}},
      {"quality", quality_summary(quality)},
      {"air_ring_correction", ring_summary(result.air_rings)},
      {"gradient_ring_correction", ring_summary(result.gradient_rings)},
      {"response_ring_correction", ring_summary(result.response_rings)},
      {"gradient_after_response_ring_correction", gradient_again},
      {"gradient_after_detail_ring_correction", ring_summary(result.gradient_after_detail_rings)},
      {"mirror_ring_correction", ring_summary(result.mirror_rings)},
      {"slice_ring_corrections", volume_ring_summary(result.volume_rings)},
      {"residual_detail",
       {{"applied", result.residual_detail.applied},
        {"consistent_share", result.residual_detail.consistent_share},
        {"mean_gain", result.residual_detail.mean_gain},
        {"rms_added", result.residual_detail.rms_added},
        {"misfit_before", result.residual_detail.misfit_before},
        {"misfit_after", result.residual_detail.misfit_after},
        {"min_fall", result.residual_detail.min_fall},
        {"held_out_views", result.residual_detail.held_out_views},
        {"seconds", result.residual_detail.seconds},
        {"note", result.residual_detail.note}}},
      {"stopped_hull",
       {{"voxels", result.stopped_hull_voxels}, {"mean", result.stopped_hull_mean}}},
      {"final_loss", history.empty() ? 0.0 : history.back().data_loss}};
}

nlohmann::json dead_elements_json(const std::vector<DeadElement>& dead) {
  nlohmann::json out = nlohmann::json::array();
  for (const DeadElement& d : dead) {
    out.push_back({{"element", d.element},
                   {"reason", d.reason},
                   {"beta", d.beta},
                   {"invalid_readings", d.invalid_readings}});
  }
  return out;
}

nlohmann::json changing_elements_json(const std::vector<ChangingElement>& changing) {
  nlohmann::json out = nlohmann::json::array();
  for (const ChangingElement& c : changing) {
    nlohmann::json segments = nlohmann::json::array();
    for (const ResponseSegment& s : c.segments) {
      segments.push_back(
          {{"first_view", s.first_view}, {"views", s.views}, {"alpha", s.alpha}, {"beta", s.beta}});
    }
    out.push_back({{"element", c.element}, {"dies", c.dies}, {"segments", segments}});
  }
  return out;
}

nlohmann::json centre_json(const CentreEstimate& e) {
  auto maybe = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"offset_px", e.offset_px},
          {"axis_column", e.axis_column},
          {"method", e.method},
          {"half_acquisition", e.half_acquisition},
          {"sinogram_offset_px", maybe(e.sinogram_offset_px)},
          {"view_pairs_offset_px", maybe(e.pairs_offset_px)},
          {"spread_px", e.spread_px},
          {"view_pairs", e.pairs},
          {"rows", e.rows}};
}

nlohmann::json fbp_report_json(const FbpReport& r) {
  return {{"non_finite_replaced", r.non_finite_replaced},
          {"stopped_beam_readings", r.stopped_beam_readings},
          {"stopped_beam_floor", r.stopped_beam_floor},
          {"short_scan", r.short_scan},
          {"parker_weighted", r.parker_weighted},
          {"half_acquisition_overlap_mm", r.half_acquisition_overlap_mm}};
}

nlohmann::json flat_field_json(const FlatFieldReport& r) {
  return {{"flat_frames", r.flat_frames},
          {"dark_frames", r.dark_frames},
          {"invalid_readings", r.invalid_readings},
          {"dark_noise", r.dark_noise},
          {"readings_in_dark_noise", r.readings_in_dark_noise},
          {"saturated_readings", r.saturated_readings},
          {"pixels_without_beam", r.pixels_without_beam},
          {"flat_series", r.flat_series},
          {"flat_change", r.flat_change},
          {"air_first", std::isfinite(r.air_first) ? nlohmann::json(r.air_first) : nullptr},
          {"air_last", std::isfinite(r.air_last) ? nlohmann::json(r.air_last) : nullptr},
          {"air_drift_sigmas", r.air_drift_sigmas},
          {"air_drifts", air_drifts(r)}};
}

nlohmann::json device_json(const DeviceInfo& d) {
  return {{"index", d.index},
          {"platform", d.platform},
          {"platform_version", d.platform_version},
          {"name", d.name},
          {"vendor", d.vendor},
          {"type", d.type},
          {"version", d.version},
          {"driver_version", d.driver_version},
          {"opencl_c_version", d.opencl_c_version},
          {"compute_units", d.compute_units},
          {"max_clock_mhz", d.max_clock_mhz},
          {"max_work_group_size", d.max_work_group_size},
          {"local_mem_bytes", d.local_mem_bytes},
          {"local_mem_is_global", d.local_mem_is_global},
          {"global_mem_bytes", d.global_mem_bytes},
          {"max_alloc_bytes", d.max_alloc_bytes},
          {"fp64", d.fp64},
          {"preferred_vector_width_float", d.preferred_vector_width_float},
          {"native_vector_width_float", d.native_vector_width_float},
          {"preferred_vector_width_int", d.preferred_vector_width_int},
          {"native_vector_width_int", d.native_vector_width_int},
          {"fp32_global_atomic_add", d.fp32_global_atomic_add},
          {"training_plan", nlohmann::json::parse(choose_execution_plan(d).to_json())}};
}

std::optional<CentreEstimate> check_geometry_centre(const Scan& scan, std::string& note) {
  note.clear();
  const Geometry& g = scan.geometry;
  if (!centre_search_covers(g)) {
    note =
        "the rotation axis lies outside the detector's central half and the views cover "
        "less than a full turn: the centre finders search the central half only, so the "
        "geometry's offset is not checked";
    return std::nullopt;
  }
  std::optional<CentreEstimate> e;
  try {
    e = estimate_centre(scan);
  } catch (const InputError&) {
    return std::nullopt;  // no half-turn, no view pair: nothing to check against
  }
  if (std::fabs(e->offset_px - g.offset_u) > kCentreDoubtPx) {
    char line[300];
    std::snprintf(line, sizeof(line),
                  "the scan's own %s the rotation axis at offset %.2f px, the geometry at "
                  "%.2f: a wrong axis doubles edges and leaves arcs (pass --offset-px auto, or "
                  "check the geometry)",
                  e->method.rfind("conjugate rays", 0) == 0 ? "conjugate rays put"
                  : e->method.rfind("view pairs", 0) == 0   ? "view pairs put"
                                                            : "sinogram puts",
                  e->offset_px, g.offset_u);
    note = line;
  }
  return e;
}

}  // namespace riner::app
