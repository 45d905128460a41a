// What works on a scan without training: FBP, simulation, the centre of rotation, flat-field
// normalisation, array files and image metrics. Every call releases the GIL while riner works.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "numpy_arrays.hpp"
#include "python_wording.hpp"
#include "riner/centre.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/flat_field.hpp"
#include "riner/geometry_doubts.hpp"
#include "riner/io.hpp"
#include "riner/log.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/scan_source.hpp"
#include "riner/simulate.hpp"
#include "stopped_beam_note.hpp"
#include "summary_json.hpp"

namespace riner::python {

Scan scan_from(const py::handle& measurement, const std::string& geometry_json) {
  Scan scan{to_array(measurement, "sino"), Geometry::from_json(geometry_json, "geometry"), 0};
  scan.non_finite = compute_stats(scan.measurement).non_finite();
  fit_geometry_to_measurement(scan);  // as the CLI reads a stack of rows beside a 2D geometry
  check_scan(scan, "sino");
  return scan;
}

namespace {

// What the readings say against the geometry (riner/geometry_doubts.hpp), each a UserWarning
// through the module's warning handler, as the command line warns.
void warn_geometry_doubts(const Scan& scan) {
  std::vector<std::string> doubts;
  {
    py::gil_scoped_release release;
    doubts = geometry_doubts(scan);
  }
  for (const std::string& doubt : doubts) warn(doubt);  // the module's handler: UserWarning
}

// The image and what FBP did (the keys of `riner fbp --json`'s), as JSON.
py::tuple fbp_of(const py::handle& measurement, const std::string& geometry_json,
                 const std::string& filter, const std::string& engine, const std::string& device,
                 bool fill_stopped_beam) {
  const Scan scan = scan_from(measurement, geometry_json);
  warn_geometry_doubts(scan);
  FbpOptions options;
  options.filter = parse_fbp_filter(filter);
  options.stopped_beam_at_floor = !fill_stopped_beam;
  options.engine = parse_engine(engine);
  Array image;
  FbpReport report;
  {
    py::gil_scoped_release release;
    options.device = device_for(options.engine, device);
    image = fbp(scan, options, &report);
  }
  if (report.stopped_beam_readings > 0) {
    warn(python_wording(
        app::stopped_beam_note(report.stopped_beam_readings, report.stopped_beam_floor)));
  }
  nlohmann::json done = app::fbp_report_json(report);
  done["filter"] = fbp_filter_name(options.filter);
  return py::make_tuple(to_numpy(std::move(image)), done.dump());
}

// Classical stripe removal (riner/destripe.hpp): the destriped measurement and a report.
py::dict destripe_of(const py::handle& measurement, const std::string& geometry_json,
                     const std::string& method, std::size_t size, std::size_t large_size,
                     std::size_t rank_window, double snr, double sigma, int fit_order, int levels,
                     int wavelet_order, const std::string& engine, const std::string& device) {
  const Scan scan = scan_from(measurement, geometry_json);
  warn_geometry_doubts(scan);
  DestripeOptions options;
  options.engine = parse_engine(engine);
  options.method = parse_destripe_method(method);
  options.size = size;
  options.large_size = large_size;
  options.rank_window = rank_window;
  options.snr = snr;
  options.sigma = sigma;
  options.fit_order = fit_order;
  options.levels = levels;
  options.wavelet_order = wavelet_order;
  DestripeReport report;
  Array out;
  {
    py::gil_scoped_release release;
    options.device = device_for(options.engine, device);
    out = destripe(scan.measurement, scan.geometry, options, &report);
  }
  py::dict result;
  result["sino"] = to_numpy(std::move(out));
  result["stripes"] = to_numpy(std::move(report.removed));
  result["dead_elements"] = report.dead;
  result["large_stripe_elements"] = report.large;
  result["size"] = report.size;
  result["large_size"] = report.large_size;
  result["rank_window"] = report.rank_window;
  result["sigma"] = report.sigma;
  result["wavelet_levels"] = report.levels;
  result["non_finite_replaced"] = report.non_finite_replaced;
  return result;
}

// The protocol of METHOD.md §4 on `image` (mu in 1/mm on the geometry's grid), or on the
// built-in Shepp-Logan phantom when image is None (then with exact projections unless
// projector is "joseph").
py::dict simulate_scan(const py::object& image, const std::string& geometry_json, double mu_scale,
                       const RingModel& model, std::string projector, const std::string& engine,
                       const std::string& device) {
  const Geometry g = Geometry::from_json(geometry_json, "geometry");
  model.validate();
  if (projector != "exact" && projector != "joseph") {
    throw InputError("projector must be exact or joseph (got '" + projector + "')");
  }
  SimulatedScan sim;
  const bool phantom = image.is_none();
  if (!phantom) {
    projector = "joseph";  // an image has no analytic projections
    sim.ground_truth = to_array(image, "image");
    if (sim.ground_truth.shape != g.volume_shape) {
      throw InputError("image has shape " + shape_string(sim.ground_truth.shape) +
                       " but the geometry's grid is " + shape_string(g.volume_shape));
    }
    if (compute_stats(sim.ground_truth).non_finite() > 0) {
      throw InputError("image holds NaN or infinite values");
    }
  }
  const Engine e = parse_engine(engine);
  {
    py::gil_scoped_release release;
    if (phantom) {
      const Phantom p = shepp_logan(g, mu_scale);
      sim.ground_truth = rasterize(p, g);
      if (projector == "exact") sim.clean = exact_projections(p, g);
    }
    if (projector == "joseph") {
      const Projector forward(g, e, device_for(e, device));
      sim.clean = forward.project(sim.ground_truth);
    }
  }
  // With the GIL: its warning (photons starved: is mu_unit right?) is a Python warning.
  sim.alpha = draw_responses(g, model);
  sim.scan.measurement = corrupt_measurement(sim.clean, sim.alpha, model);
  py::dict out;
  out["sino"] = to_numpy(std::move(sim.scan.measurement));
  out["clean"] = to_numpy(std::move(sim.clean));
  out["alpha"] = to_numpy(std::move(sim.alpha));
  out["ground_truth"] = to_numpy(std::move(sim.ground_truth));
  return out;
}

}  // namespace

void bind_scan_functions(py::module_& m) {
  m.def("fbp", &fbp_of);
  m.def("destripe", &destripe_of);
  m.def("simulate",
        [](const py::object& image, const std::string& geometry_json, double mu_scale,
           std::uint64_t seed, double photons, double nonideal_fraction, double alpha_min,
           double alpha_max, std::size_t dead, std::size_t dead_rows, std::size_t dead_columns,
           const std::string& projector, const std::string& engine, const std::string& device,
           const std::string& response_pattern, std::size_t partial, std::size_t partial_dead) {
          RingModel model;
          if (response_pattern == "rows-x-columns") {
            model.pattern = ResponsePattern::kRowsTimesColumns;
          } else if (response_pattern != "per-element") {
            throw InputError("response_pattern must be per-element or rows-x-columns (got \"" +
                             response_pattern + "\")");
          }
          model.seed = seed;
          model.photons = photons;
          model.nonideal_fraction = nonideal_fraction;
          model.alpha_min = alpha_min;
          model.alpha_max = alpha_max;
          model.dead_elements = dead;
          model.dead_rows = dead_rows;
          model.dead_columns = dead_columns;
          model.partial_elements = partial;
          model.partial_dead_elements = partial_dead;
          return simulate_scan(image, geometry_json, mu_scale, model, projector, engine, device);
        });
  m.def("center", [](const py::handle& measurement, const std::string& geometry_json) {
    const Scan scan = scan_from(measurement, geometry_json);
    CentreEstimate estimate;
    {
      py::gil_scoped_release release;
      estimate = estimate_centre(scan);
    }
    return app::centre_json(estimate).dump();
  });
  // Raw intensities, flats and darks (None: D = 0) -> rho and the report's JSON.
  // flats_after (None: one series): flats taken after the scan, each view's flat interpolated.
  m.def("flat_field", [](const py::handle& raw, const py::handle& flats, const py::object& darks,
                         const py::object& flats_after) {
    const Array projections = to_array(raw, "projections");
    const Array flat = to_array(flats, "flat");
    const Array dark = darks.is_none() ? Array() : to_array(darks, "dark");
    const Array after = flats_after.is_none() ? Array() : to_array(flats_after, "flat_after");
    FlatFieldReport report;
    Array rho;
    {
      py::gil_scoped_release release;
      const FlatStack stack = flats_before_after(flat, after, projections.shape);
      rho = flat_field_normalise(projections, stack.frames, dark, &report, stack.positions);
    }
    return py::make_tuple(to_numpy(std::move(rho)),
                          python_wording(app::flat_field_json(report).dump()));
  });
  // A scan as the CLI's SCAN options name it -> (measurement, geometry JSON, notes JSON).
  m.def("load_scan", [](const std::string& path, const std::string& geometry,
                        const std::string& flat, const std::string& dark,
                        std::optional<std::size_t> row, const std::string& offset_px,
                        const std::string& flat_after) {
    LoadedScan loaded;
    {
      py::gil_scoped_release release;
      const InputScope read_only;
      loaded = load_scan_source({path, geometry, flat, dark, row, offset_px, flat_after});
    }
    const nlohmann::json notes = {
        {"flat_field",
         loaded.flat_field ? app::flat_field_json(*loaded.flat_field) : nlohmann::json(nullptr)},
        {"centre", loaded.centre ? app::centre_json(*loaded.centre) : nlohmann::json(nullptr)},
        {"geometry_doubts", loaded.geometry_doubts}};
    return py::make_tuple(to_numpy(std::move(loaded.scan.measurement)),
                          loaded.scan.geometry.to_json(), python_wording(notes.dump()));
  });
  m.def("read_array", [](const std::string& path) {
    ArrayFile file;
    {
      py::gil_scoped_release release;
      const InputScope read_only;  // a later write_array of the same path is the user's
      file = read_array(path);
    }
    return py::make_tuple(to_numpy(std::move(file.array)), file.voxel_size, file.dtype);
  });
  m.def("write_array", [](const std::string& path, const py::handle& array,
                          const std::vector<double>& voxel_size) {
    const Array data = to_array(array, "array");
    py::gil_scoped_release release;
    write_array(path, data, {voxel_size});
  });
  m.def("compare", [](const py::handle& image, const py::handle& reference, bool circle) {
    const Array a = to_array(image, "image");
    const Array b = to_array(reference, "reference");
    const Array mask = circle ? circle_mask(b.shape) : Array();
    const ImageMetrics metrics = compare_images(a, b, circle ? &mask : nullptr);
    py::dict out;
    out["psnr"] = metrics.psnr;
    out["psnr_db"] = metrics.psnr;  // the CLI's `compare --json` key
    out["ssim"] = metrics.ssim;
    out["mae"] = metrics.mae;
    out["rmse"] = metrics.rmse;
    out["data_range"] = metrics.data_range;
    out["edge_ratio"] = metrics.edge_ratio;
    out["pixels"] = metrics.pixels;
    return out;
  });
}

}  // namespace riner::python
