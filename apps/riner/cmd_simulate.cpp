// riner simulate: a ring-corrupted scan from a phantom or an image, by the paper's protocol.
#include <cmath>
#include <cstdio>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/phantom.hpp"
#include "riner/resample.hpp"
#include "riner/simulate.hpp"

namespace riner::app {

namespace {

// --phantom-spacing-mm: "" (the image is on the grid), "file" (the file's voxel size) or
// numbers, one per axis in array order (z,y,x).
std::vector<double> phantom_spacing(const Args& args, const ArrayFile& file) {
  const std::string text = args.get("phantom-spacing-mm");
  if (text.empty()) return {};
  if (text == "file") {
    if (file.voxel_size.size() != file.array.rank()) {
      throw InputError(args.get("phantom") + " stores no voxel size; give --phantom-spacing-mm");
    }
    return file.voxel_size;
  }
  std::vector<double> spacing;
  for (const std::string& item : split_commas(text)) {
    try {
      std::size_t used = 0;
      spacing.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--phantom-spacing-mm takes numbers separated by commas, or 'file'");
    }
  }
  return spacing;
}

Array load_ground_truth(const Args& args, const Geometry& g, Console& console) {
  ArrayFile file = read_array(args.get("phantom"));
  const std::vector<double> spacing = phantom_spacing(args, file);
  if (!spacing.empty()) {
    file.array = resample_to_grid(file.array, spacing, g);
    console.line("resampled " + args.get("phantom") + " onto the geometry's " +
                 shape_string(g.volume_shape) + " grid");
  } else if (file.array.shape != g.volume_shape) {
    throw InputError(args.get("phantom") + " has shape " + shape_string(file.array.shape) +
                     " but the geometry's grid is " + shape_string(g.volume_shape) +
                     " (--phantom-spacing-mm resamples it)");
  } else {
    for (double s : file.voxel_size) {
      if (std::fabs(s - g.voxel_mm) > 1e-3 * g.voxel_mm) {
        console.line(
            "note: the image's voxel size differs from the geometry's voxel_mm; the "
            "geometry's is used (--phantom-spacing-mm file resamples it)");
        break;
      }
    }
  }
  if (file.non_finite > 0) throw InputError(args.get("phantom") + " holds NaN or infinite values");
  const std::string unit = args.get("mu-unit");
  if (unit != "mm" && unit != "cm") throw UsageError("--mu-unit must be mm or cm");
  if (unit == "cm") {
    for (float& v : file.array.data) v *= 0.1f;  // 1/cm -> 1/mm
  }
  return std::move(file.array);
}

RingModel model_from(const Args& args) {
  RingModel m;
  m.seed = static_cast<std::uint64_t>(args.integer("seed"));
  m.photons = args.number("photons");
  m.nonideal_fraction = args.number("nonideal-fraction");
  m.alpha_min = args.number("alpha-min");
  m.alpha_max = args.number("alpha-max");
  const long dead = args.integer("dead");
  const long rows = args.integer("dead-rows");
  const long columns = args.integer("dead-columns");
  if (dead < 0 || rows < 0 || columns < 0) throw UsageError("dead counts must be >= 0");
  m.dead_elements = static_cast<std::size_t>(dead);
  m.dead_rows = static_cast<std::size_t>(rows);
  m.dead_columns = static_cast<std::size_t>(columns);
  const long partial = args.integer("partial");
  const long partial_dead = args.integer("partial-dead");
  if (partial < 0 || partial_dead < 0) throw UsageError("partial counts must be >= 0");
  m.partial_elements = static_cast<std::size_t>(partial);
  m.partial_dead_elements = static_cast<std::size_t>(partial_dead);
  const std::string pattern = args.get("response-pattern");
  if (pattern == "rows-x-columns") {
    m.pattern = ResponsePattern::kRowsTimesColumns;
  } else if (pattern != "per-element") {
    throw UsageError("--response-pattern must be per-element or rows-x-columns");
  }
  m.validate();
  return m;
}

}  // namespace

int run_simulate(int argc, char** argv, int first) {
  Args args("simulate",
            "Simulates a ring-corrupted scan (METHOD.md §4): per-element responses alpha "
            "(a fraction non-ideal, some dead), Poisson noise at I0 photons, rho = -ln(I / I0). "
            "Writes sino.npy (corrupted), sino_clean.npy (exact, noise-free), "
            "ground_truth.nii, alpha.npy (0 = dead), geometry.json, PNG previews and "
            "simulation.json into the output folder.");
  args.option("phantom", "NAME|FILE",
              "shepp-logan, faint-square (a faint square with sharp corners and a dense line), "
              "tube-wall (a tube whose wall is centred on the axis: object rings), or an "
              "image/volume file on the grid",
              "shepp-logan")
      .option("phantom-spacing-mm", "Z,Y,X|file",
              "resample the image onto the geometry's grid from this voxel size (mm per axis, "
              "array order; 'file': the file's own); default: the image is on the grid",
              "")
      .option("geometry", "PRESET|FILE",
              "fan2d-paper, cone3d-paper, parallel3d, or a geometry JSON", "fan2d-paper")
      .option("out", "DIR", "output folder (created if missing)")
      .option("seed", "N", "random seed (responses and noise)", "0")
      .option("mu-unit", "mm|cm", "unit of the image's values (DeepLesion: cm)", "mm")
      .option("mu-scale", "MU", "Shepp-Logan: 1/mm per head unit (brain = 0.2 units)", "0.1")
      .option("photons", "I0", "incident photons per ray; 0 disables noise", "1e7")
      .option("nonideal-fraction", "F", "fraction of elements with alpha ~ U[min, max]", "0.75")
      .option("alpha-min", "A", "smallest non-ideal response", "0.75")
      .option("alpha-max", "A", "largest non-ideal response", "1.25")
      .option("response-pattern", "P",
              "per-element, or rows-x-columns (3D: alpha = row factor x column factor, each "
              "~ U[sqrt(min), sqrt(max)])",
              "per-element")
      .option("dead", "N", "dead elements (alpha = 0)", "2")
      .option("dead-rows", "N", "3D: whole dead detector rows", "0")
      .option("dead-columns", "N", "3D: whole dead detector columns", "0")
      .option("partial", "N",
              "elements (pixels) whose response changes part-way (partial rings; alpha.npy is "
              "then per view)",
              "0")
      .option("partial-dead", "N", "elements (pixels) that die part-way", "0")
      .option("supersample", "S", "built-in phantoms' raster: S^d points averaged per voxel", "4")
      .option("projector", "NAME", "exact (analytic, built-in phantoms only) or joseph", "exact");
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  // Checked for a built-in phantom too, where it is not used (xyz passed without a word).
  if (args.get("mu-unit") != "mm" && args.get("mu-unit") != "cm") {
    throw UsageError("--mu-unit must be mm or cm");
  }
  const Geometry g = geometry_from(args.get("geometry"));
  const RingModel model = model_from(args);
  const Engine engine = engine_from(args);
  const std::filesystem::path out = make_output_dir(args.get("out"));
  const std::string phantom_name = args.get("phantom");
  const bool phantom = phantom_name == "shepp-logan" || phantom_name == "faint-square" ||
                       phantom_name == "tube-wall";
  std::string projector_name = args.get("projector");
  if (projector_name != "exact" && projector_name != "joseph") {
    throw UsageError("--projector must be exact or joseph");
  }
  if (!phantom) projector_name = "joseph";  // an image has no analytic projections

  SimulatedScan sim;
  sim.scan.geometry = g;
  if (phantom) {
    const Phantom p = phantom_name == "shepp-logan"    ? shepp_logan(g, args.number("mu-scale"))
                      : phantom_name == "faint-square" ? faint_square(g)
                                                       : tube_wall(g);
    sim.ground_truth = rasterize(p, g, static_cast<int>(args.integer("supersample")));
    if (projector_name == "exact") sim.clean = exact_projections(p, g);
  } else {
    sim.ground_truth = load_ground_truth(args, g, console);
  }
  if (projector_name == "joseph") {
    const Projector projector(g, engine, device_from(args, engine));
    sim.clean = projector.project(sim.ground_truth);
  }
  const std::vector<std::string> outputs = {
      "sino.npy",      "sino_clean.npy",   "alpha.npy", "ground_truth.nii",
      "geometry.json", "ground_truth.png", "sino.png",  "simulation.json"};
  refuse_outputs_over_inputs(out, outputs);
  sim.alpha = draw_responses(g, model);
  sim.scan.measurement = corrupt_measurement(sim.clean, sim.alpha, model);
  const ArrayStats stats = compute_stats(sim.scan.measurement);
  const double max_line = compute_stats(sim.clean).max;

  clear_previous_outputs(out, outputs);
  write_array(out / "sino.npy", sim.scan.measurement);
  write_array(out / "sino_clean.npy", sim.clean);
  write_array(out / "alpha.npy", sim.alpha);
  write_array(out / "ground_truth.nii", sim.ground_truth,
              {std::vector<double>(g.volume_shape.size(), g.voxel_mm)});
  g.save(out / "geometry.json");
  write_png(out / "ground_truth.png", sim.ground_truth);
  write_png(out / "sino.png", sim.scan.measurement);

  const std::size_t elements = g.n_u * (g.is_3d() ? g.n_v : 1);
  const std::vector<std::size_t> dead = dead_in_every_view(sim.alpha, elements);
  nlohmann::json summary = {{"phantom", args.get("phantom")},
                            {"geometry", geometry_type_name(g.type)},
                            {"measurement_shape", sim.scan.measurement.shape},
                            {"projector", projector_name},
                            {"seed", model.seed},
                            {"photons", model.photons},
                            {"nonideal_fraction", model.nonideal_fraction},
                            {"alpha_range", {model.alpha_min, model.alpha_max}},
                            {"response_pattern", args.get("response-pattern")},
                            {"dead_elements", dead},
                            {"partial_elements", model.partial_elements},
                            {"dead_part_way", dead_part_way(sim.alpha, elements)},
                            {"non_finite_measurements", stats.non_finite()},
                            {"max_line_integral", max_line},
                            {"out", out.string()}};
  write_text(out / "simulation.json", summary.dump(1) + "\n");
  console.line("simulated " + std::string(geometry_type_name(g.type)) + " scan " +
               shape_string(sim.scan.measurement.shape) + ", " + std::to_string(dead.size()) +
               " dead elements, " + std::to_string(stats.non_finite()) +
               " non-finite measurements -> " + out.string());
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
