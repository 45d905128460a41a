#include "reconstruct_slabs.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <thread>

#include "detector_outputs.hpp"
#include "progress.hpp"
#include "rank_stop.hpp"
#include "riner/cores.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/slab_ranks.hpp"
#include "riner/slab_run.hpp"
#include "riner/volume_writer.hpp"
#include "scan_options.hpp"
#include "slab_processes.hpp"
#include "stop_signal.hpp"
#include "summary_json.hpp"

namespace riner::app {

std::string output_format(const Args& args) {
  const std::string format = args.get("format");
  if (format != "nii" && format != "npy" && format != "tif" && format != "raw" && format != "h5") {
    throw UsageError("--format must be nii, npy, tif, raw or h5");
  }
  return format;
}

SlabOptions slab_size_options(const Args& args) {
  SlabOptions options;
  if (auto v = args.maybe("slab-slices"); v && !v->empty()) {
    const long n = args.integer("slab-slices");
    if (n < 1) throw UsageError("--slab-slices must be 1 or more");
    options.slices_per_slab = static_cast<std::size_t>(n);
  }
  if (auto v = args.maybe("memory-limit"); v && !v->empty()) {
    options.memory_limit = parse_memory_size(*v);
  }
  return options;
}

int report_every(const Args& args) {
  const long n = args.integer("report-every");
  if (n < 1 || n > 100000000) throw UsageError("--report-every must be 1 or more steps");
  return static_cast<int>(n);
}

void refuse_limit_below_one_slice(const SlabOptions& asked, std::size_t one_slice) {
  if (asked.memory_limit == 0 || asked.memory_limit >= one_slice) return;
  const auto mib = [](std::size_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20); };
  throw UsageError("--memory-limit " + mib(asked.memory_limit) +
                   "M is less than a slab of one slice takes (about " + mib(one_slice) +
                   " MiB): give at least " + mib(one_slice) +
                   "M, or leave it out (three quarters of the machine's memory)");
}

namespace {

// Stopped before every slab was written (a stop after the last one changes nothing).
bool stopped_early(RankStop& stop, const SlabRun& run) {
  return stop.signal() != 0 && run.slabs_done() < run.slabs().size();
}

SlabOptions slab_options(const Args& args) {
  SlabOptions options = slab_size_options(args);
  options.resume = args.is_set("resume");
  if (auto v = args.maybe("workers"); v && !v->empty()) {
    const long n = args.integer("workers");
    if (n < 1 || n > 256) throw UsageError("--workers must be 1 to 256");
    options.workers = static_cast<int>(n);
  }
  if (args.is_set("slices-2d") && args.is_set("field-3d")) {
    throw UsageError("--slices-2d and --field-3d: choose one");
  }
  options.slices_2d = args.is_set("slices-2d");
  if (options.slices_2d && options.slices_per_slab) {
    throw UsageError("--slices-2d trains each slice alone: leave out --slab-slices");
  }
  if (!options.slices_2d && !options.slices_per_slab && !args.is_set("field-3d")) {
    const std::optional<Geometry> g = stack_geometry(args);
    options.slices_2d = g && slices_2d_by_default(*g);
  }
  return options;
}

// --processes, or 0 when riner is to choose.
int requested_processes(const Args& args) {
  if (auto v = args.maybe("processes"); v && !v->empty()) {
    const long n = args.integer("processes");
    if (n < 1 || n > 1024) throw UsageError("--processes must be 1 to 1024");
    return static_cast<int>(n);
  }
  return 0;
}

std::string bytes_string(double bytes) {
  char text[32];
  if (bytes < 1024.0 * 1024.0 * 1024.0) {
    std::snprintf(text, sizeof(text), "%.0f MiB", bytes / (1024.0 * 1024.0));
  } else {
    std::snprintf(text, sizeof(text), "%.1f GiB", bytes / (1024.0 * 1024.0 * 1024.0));
  }
  return text;
}

}  // namespace

void add_slab_options(Args& args) {
  args.option("slab-slices", "N",
              "a projection stack in slabs of up to N axial slices (evened out: 16 slices at N=5 "
              "are 4 slabs of 4), each trained alone (a cone "
              "beam's with the slices around it that its rays cross) and written as it "
              "finishes (volume/slice_NNNNN.tif, manifest.json); default: as many as "
              "--memory-limit allows",
              "")
      .option("memory-limit", "SIZE",
              "memory the slabs may take, on the host and on a GPU (8G, 512M); a volume larger "
              "than this goes by slabs; one below a slab of one slice is refused (default: three "
              "quarters of the machine's memory, nine tenths of a GPU's)",
              "")
      .option("workers", "N",
              "slabs trained at once on the device, each on its own queue (default: 8 on a "
              "GPU, 1 on a CPU, whose cores MPI ranks fill; at most as many as the slabs and "
              "--memory-limit allow); the volume is the same for any N",
              "")
      .option("processes", "N",
              "slab processes on this machine, each with its share of the cores, started by "
              "riner itself (without mpirun; default: one per two cores on a CPU device with "
              "more than two, else 1); the volume is the same for any N",
              "")
      .option("join-run", "TOKEN", "(used by riner's own slab processes)", "")
      .flag("pin",
            "pin each of riner's own slab processes (--processes) to cores of its own (the "
            "affinity mask's first share of cores, the next, ...) where the mask holds a share "
            "for each; by default they move as the system schedules them")
      .flag("slices-2d",
            "train each axial slice of a parallel-beam stack as its own 2D scan (the mean of "
            "its detector rows, the 2D defaults) instead of a slab of slices as one 3D field "
            "(the default for slices of 256 x 256 voxels or more)")
      .flag("field-3d",
            "train a parallel-beam stack in slabs of slices, each one 3D field (the default "
            "for slices under 256 x 256 voxels, and with --slab-slices)")
      .flag("resume",
            "finish a slabbed run the output folder holds: only the slabs its manifest does "
            "not list as done are trained, each from its checkpoint where it has one; on a "
            "slice, go on from the training's checkpoint (--checkpoint-minutes)");
}

bool slices_2d_by_default(const Geometry& g) {
  return g.type == GeometryType::kParallel3d && g.volume_shape[1] >= kSlices2dFromPx &&
         g.volume_shape[2] >= kSlices2dFromPx;
}

double checkpoint_seconds(const Args& args) {
  const double minutes = args.number("checkpoint-minutes");
  if (!std::isfinite(minutes) || minutes < 0.0) {
    throw UsageError("--checkpoint-minutes must be 0 (never) or more");
  }
  return 60.0 * minutes;
}

bool wants_slabs(const Args& args) {
  if (args.is_set("slices-2d") || args.is_set("field-3d")) return true;
  for (const char* name : {"slab-slices", "memory-limit", "workers", "processes", "join-run"}) {
    if (auto v = args.maybe(name); v && !v->empty()) return true;
  }
  // Left to the scan: by slabs when a volume does not fit whole (in memory, or in the kernels'
  // 32-bit indices), or when a parallel beam's slices are large enough to train each alone.
  const std::optional<Geometry> g = stack_geometry(args);
  // --resume goes on with what the folder holds: a slabbed run (its manifest), or a volume or
  // slice trained whole (its training's checkpoint, cmd_reconstruct.cpp); a 3D volume killed
  // part-way was started again by slabs, from step 0.
  if (args.is_set("resume") && g && g->is_3d()) {
    const std::filesystem::path out = args.get("out");
    if (std::filesystem::exists(out / "manifest.json")) return true;
    if (std::filesystem::exists(out / "training.checkpoint")) return false;
  }
  return g && g->is_3d() &&
         (slices_2d_by_default(*g) || whole_run_bytes(*g) > default_memory_limit() ||
          !within_piece_size(*g));
}

namespace {

// Each rank on a machine gets its own GPU, or its share of the cores (PoCL's threads are set
// before the OpenCL platform is first opened).
std::optional<Device> rank_device(const Args& args, Engine engine, const SlabRanks& ranks) {
  if (engine != Engine::kOpenCL) return std::nullopt;
  if (ranks.local_size() <= 1 || !args.get("device").empty()) return device_from(args, engine);
  // The machine's cores shared out among its ranks, but no more than this rank may use: a
  // launcher that binds each rank (srun --cpus-per-task, mpirun --bind-to core) has already
  // given it its share.
  const unsigned per_rank = machine_cores() / static_cast<unsigned>(ranks.local_size());
  const std::string share = std::to_string(std::max(1u, std::min(usable_cores(), per_rank)));
  setenv("POCL_MAX_PTHREAD_COUNT", share.c_str(), 0);
  std::vector<int> gpus;
  for (const DeviceInfo& d : list_devices()) {
    if (d.type == "GPU") gpus.push_back(d.index);
  }
  if (gpus.empty()) return Device::open("");
  return Device::open(std::to_string(gpus[ranks.local_rank() % gpus.size()]));
}

// The slabs' TIFF slices, one at a time, into one volume file.
void gather_slices(const SlabRun& run, const std::string& target) {
  const Geometry& g = run.source().geometry();
  VolumeWriter writer(target, g.volume_shape, g.voxel_mm);
  for (std::size_t k = 0; k < g.volume_shape[0]; ++k) {
    Array slice = read_array(run.slice_path(k)).array;
    slice.shape.insert(slice.shape.begin(), 1);
    writer.write(k, slice);
  }
  writer.close();
}

}  // namespace

int reconstruct_by_slabs(const Args& args, const Console& console, const RinerConfig& settings,
                         std::chrono::steady_clock::time_point started) {
  const std::string format = output_format(args);
  if (SlabRanks::launched_size() > 1 && !SlabRanks::built_with_mpi()) {
    throw InputError(
        "this riner was built without MPI: run one process, or install "
        "libopenmpi-dev and build again");
  }
  SlabOptions options = slab_options(args);
  options.checkpoint_seconds = checkpoint_seconds(args);
  // Shared with every rank once the run's token is known.
  const auto rank_stop = std::make_shared<RankStop>();
  if (options.checkpoint_seconds > 0.0) {
    catch_stop_signals();
    options.stop = [rank_stop] { return rank_stop->requested(); };
  }
  const int requested = requested_processes(args);
  const SlabRanks ranks;
  // A process riner started to share this run (slab_processes.hpp) joins like an MPI rank.
  const std::string joined = args.get("join-run");
  const bool leader = ranks.is_leader() && joined.empty();
  const bool speak = leader && !console.quiet();
  ScanRows source(source_from(args));
  const std::vector<std::string> doubts =
      leader ? source.geometry_doubts() : std::vector<std::string>{};
  if (speak) {
    for (const std::string& note : source.notes()) console.line(note);
    for (const std::string& doubt : doubts) console.line("warning: " + doubt);
  }
  if (source.centre() && speak) console.line(centre_line(*source.centre()));
  if (speak) note_missing_lines(console, source.geometry());
  if (speak) note_grid_beyond_rays(console, source.geometry());
  require_quality_grid(source.geometry());
  require_training(settings);
  refuse_limit_below_one_slice(options, slab_bytes(source.geometry(), 1));
  // Before the output folder is made, as the memory limit's refusal.
  check_slabs_within_piece_size(source.geometry(), options.slices_per_slab);
  const std::filesystem::path out = make_output_dir(args.get("out"));
  // Refused now, not after every slab is trained.
  refuse_overwriting_input(out / "volume");
  // The slices gathered into one file: for h5, npy and raw, and for nii or tif when asked for
  // (by default a slabbed run writes the slices alone; --format nii or tif wrote no volume).
  const bool gather = format == "h5" || format == "npy" || format == "raw" || args.given("format");
  if (gather) refuse_overwriting_input(out / ("volume." + format));
  const std::optional<Device> device = rank_device(args, settings.engine, ranks);
  // On a CPU the plan splits the gradient's sums by the device's threads, and a rank has only
  // its share of them: every rank plans for the whole machine, so the sums, and the volume,
  // are the same for any number of ranks.
  RinerConfig config = settings;
  if (device && device->info().type == "CPU" && config.plan.gradient_slices <= 0) {
    config.plan.gradient_slices = 2 * static_cast<int>(machine_cores());
  }
  const unsigned cores = usable_cores();
  int processes = 1;
  if (ranks.size() == 1 && joined.empty()) {
    const std::size_t limit = options.limit();
    const std::size_t one_slice = slab_bytes(source.geometry(), 1);
    const std::string type = device ? device->info().type : "CPU";
    const int by_cores = default_slab_processes(type, cores, cores);  // memory aside
    processes = requested > 0 ? requested : default_slab_processes(type, cores, limit / one_slice);
    if (requested == 0 && processes < by_cores && speak) {
      console.line("memory: " + std::to_string(processes) + " slab process(es) instead of " +
                   std::to_string(by_cores) + ", each slice's slab needs about " +
                   bytes_string(static_cast<double>(one_slice)) + " of the limit's " +
                   bytes_string(static_cast<double>(limit)));
    }
  }
  // The processes of this machine share its memory, and each gets a slab.
  options.processes = processes > 1 ? processes : ranks.local_size();
  const int threads_per_process = static_cast<int>(std::max(1u, cores / std::max(1, processes)));
  const bool pinned = processes > 1 && args.is_set("pin") &&
                      !core_groups(usable_core_ids(), processes, threads_per_process).empty();

  // The leader plans the run (or finds it to resume) before the others join it.
  std::optional<SlabRun> planned;
  std::string word;
  if (leader) {
    try {
      planned.emplace(std::move(source), config, out, options, device);
      word = "ok " + new_claim_token();
    } catch (const std::exception& e) {
      word = "error";
      ranks.share(word);
      throw;
    }
  }
  if (joined.empty()) word = ranks.share(word);
  if (word == "error") return 2;  // the leader says why
  const std::string token = joined.empty() ? word.substr(3) : joined;
  if (!leader) {
    options.join = true;
    planned.emplace(std::move(source), config, out, options, device);
  }
  SlabRun& run = *planned;
  if (ranks.size() > 1 || !joined.empty() || processes > 1) {
    rank_stop->share(out / "slabs", token);
    if (leader) RankStop::remove_others(out / "slabs", token);
  }
  const Geometry& g = run.source().geometry();
  const std::size_t done_before = run.slabs_done();
  if (speak) {
    const int at_once = run.workers() * std::max(1, options.processes);
    // The thickest slab as cut (a cone beam's are cut at the source's plane first, so they can
    // be thinner than the size the memory allows).
    std::size_t thickest = 0, trained = 0;
    for (const Slab& slab : run.slabs()) {
      thickest = std::max(thickest, slab.slices);
      trained = std::max(trained, slab.trained_slices);
    }
    char line[300];
    std::snprintf(line, sizeof(line),
                  "%zu slabs of up to %zu slices (%zu x %zu voxels; about %s each, limit %s), "
                  "%d at once%s%s",
                  run.slabs().size(), thickest, g.volume_shape[1], g.volume_shape[2],
                  bytes_string(static_cast<double>(slab_bytes(g, run.slices_per_slab()))).c_str(),
                  bytes_string(static_cast<double>(run.memory_limit())).c_str(), at_once,
                  done_before ? (", " + std::to_string(done_before) + " done before").c_str() : "",
                  ranks.size() > 1 ? (", over " + std::to_string(ranks.size()) + " ranks").c_str()
                  : processes > 1  ? (" in processes of " + std::to_string(threads_per_process) +
                                     (threads_per_process == 1 ? " thread" : " threads") +
                                     (pinned ? ", each pinned to its own cores" : ""))
                                        .c_str()
                                  : "");
    console.line(line);
    if (trained > thickest) {
      std::snprintf(line, sizeof(line),
                    "cone beam: each slab also trains the slices beside it that its rows' rays "
                    "cross, up to %zu slices in all (the rest are not written)",
                    trained);
      console.line(line);
    }
    if (run.device_bound()) {
      std::snprintf(line, sizeof(line),
                    "device memory: slabs of %zu slice(s), %d at once, each about %s of the "
                    "device's %s",
                    run.slices_per_slab(), run.workers(),
                    bytes_string(static_cast<double>(slab_device_bytes(g, run.slices_per_slab())))
                        .c_str(),
                    bytes_string(static_cast<double>(run.device_memory_limit())).c_str());
      console.line(line);
    }
    if (slab_bytes(g, run.slices_per_slab()) * static_cast<std::size_t>(at_once) >
        run.memory_limit()) {
      std::snprintf(
          line, sizeof(line),
          "note: %d slab(s) of %zu slice(s) at once need about %s, more than the limit: the "
          "run may take more memory than --memory-limit allows",
          at_once, run.slices_per_slab(),
          bytes_string(static_cast<double>(slab_bytes(g, run.slices_per_slab()) *
                                           static_cast<std::size_t>(at_once)))
              .c_str());
      console.line(line);
    }
  }
  const std::size_t total = g.volume_shape[0];
  const auto training_started = std::chrono::steady_clock::now();
  const double training_started_unix = unix_seconds();
  double slices_at_start = static_cast<double>(total);  // until a report says otherwise
  bool copies_pinned = false;  // as they were started (none on a resume with nothing left)
  try {
    // In hundredths of a slice, for a bar that moves within a slab; the status counts slices.
    Progress progress("slabs", total * 100, !speak, false);
    if (processes > 1) {
      // This process plans and gathers; its copies train (none if every slab is done).
      std::size_t slabs = 0;
      slices_at_start = run.slices_recorded(&slabs);
      if (slabs < run.slabs().size() && stop_signal() == 0) {
        SlabProcesses copies(processes, threads_per_process, {"--join-run", token, "--quiet"},
                             pinned);
        copies_pinned = copies.pinned();
        while (copies.running()) {
          if (rank_stop->requested()) {  // this process's signal, or a copy's
            copies.stop();  // each saves its slab's checkpoint and ends
            break;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(500));
          const double done = run.slices_recorded(&slabs);
          const double seconds = std::chrono::duration<double>(
                                     std::chrono::steady_clock::now() - training_started)
                                     .count();
          char status[160];
          std::snprintf(status, sizeof(status), "%zu/%zu slabs, %zu/%zu slices, %.1f slices/min",
                        slabs, run.slabs().size(), static_cast<std::size_t>(done), total,
                        seconds > 0 ? 60.0 * (done - slices_at_start) / seconds : 0.0);
          progress.update(static_cast<std::size_t>(100.0 * done), status);
        }
        if (!copies.failure().empty()) throw Error(copies.failure());
      }
      // A stopped run leaves its last line as drawn.
      if (!stopped_early(*rank_stop, run)) progress.finish();
    } else {
      run.run(
          [&](const SlabProgress& p) {
            slices_at_start = p.slices_at_start;
            const double this_run = p.slices_done - p.slices_at_start;
            char status[160];
            std::snprintf(status, sizeof(status), "%zu/%zu slabs, %zu/%zu slices, %.1f slices/min",
                          p.slabs_done, p.slabs, static_cast<std::size_t>(p.slices_done), p.slices,
                          p.seconds > 0 ? 60.0 * this_run / p.seconds : 0.0);
            progress.update(static_cast<std::size_t>(100.0 * p.slices_done), status);
          },
          [&](const Reconstructor& r, const ReconstructionResult& result,
              const std::optional<Device>& own) {
            return run_summary(r, result, check_quality(r, result, own));
          },
          report_every(args),
          ranks.size() > 1 || !joined.empty() ? claim_by_file(out, token) : SlabRun::Claim{});
      if (!stopped_early(*rank_stop, run)) progress.finish();
    }
  } catch (const std::exception& e) {
    if (ranks.size() == 1) throw;
    std::fprintf(stderr, "riner: error: rank %d: %s\n", ranks.rank(), e.what());
    ranks.abort(1);  // the other ranks would wait for this one forever
  }
  ranks.all_ok(true);  // every rank's slabs are written, or its checkpoints on a stop
  release_stop_signals();
  if (stopped_early(*rank_stop, run)) {
    const int sig = rank_stop->signal();
    if (!leader) return 128 + sig;
    std::size_t done = 0;
    run.slices_recorded(&done);
    return stopped_by_signal(std::to_string(done) + " of " + std::to_string(run.slabs().size()) +
                                 " slabs written, the checkpoints of those in training in " +
                                 (out / "slabs").string(),
                             sig);
  }
  const double training_wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - training_started).count();
  if (!leader) return 0;
  run.finish();
  RankStop::remove_others(out / "slabs", "");  // a stop that came after the last slab

  // The whole scan's outputs from the slabs' files (this run's and earlier runs').
  std::vector<std::size_t> dead;
  // Partial rings: each changing element with the detector rows it stands for (a 2D slice's
  // column stands for its slab's rows; a 3D slab's pixel for its own row). A cone beam's slabs
  // read rows their neighbours read too: each counts only the rows it maps (map_rows), so that
  // an element is listed once.
  nlohmann::json changing = nlohmann::json::array();
  std::size_t dying = 0;
  for (const Slab& s : run.slabs()) {
    const nlohmann::json& summary = run.manifest()["slabs"][s.index]["summary"];
    if (!summary.is_object() || !summary.contains("dead_elements")) continue;
    const bool by_column = run.manifest()["slabs"][s.index].value("trained_as", "") == "slice_2d";
    const auto mapped = [&](std::size_t row) {
      return row >= s.map_rows.first && row < s.map_rows.end();
    };
    for (std::size_t e : summary["dead_elements"].get<std::vector<std::size_t>>()) {
      if (!by_column) {
        if (mapped(s.rows.first + e / g.n_u)) dead.push_back(s.rows.first * g.n_u + e);
        continue;
      }
      for (std::size_t r = s.map_rows.first; r < s.map_rows.end(); ++r) {
        dead.push_back(r * g.n_u + e);
      }
    }
    for (const nlohmann::json& c : summary.value("changing_elements", nlohmann::json::array())) {
      const auto e = c["element"].get<std::size_t>();
      const std::size_t first_row = by_column ? s.map_rows.first : s.rows.first + e / g.n_u;
      if (!by_column && !mapped(first_row)) continue;
      changing.push_back({{"rows", {first_row, by_column ? s.map_rows.count : 1}},
                          {"column", by_column ? e : e % g.n_u},
                          {"dies", c["dies"]},
                          {"segments", c["segments"]}});
      dying += c["dies"].get<bool>() ? 1 : 0;
    }
  }
  std::sort(dead.begin(), dead.end());
  dead.erase(std::unique(dead.begin(), dead.end()), dead.end());
  // The readings, as a whole scan's run reports them: its slabs' non-finite readings and raw
  // projections' normalisation (the drift of the slab where the air moved most).
  std::size_t non_finite = 0;
  std::size_t starved = 0;
  float starved_floor = 0.0f;  // the largest of the slabs' floors
  std::size_t hull = 0;        // voxels in the full shadow (model/stopped_hull.hpp)
  // The field's unit (model/field_scale.hpp): the slabs' distinct factors.
  std::vector<double> field_per_mu;
  std::optional<FlatFieldReport> flat;
  for (const nlohmann::json& entry : run.manifest()["slabs"]) {
    starved += entry.value("starved_readings", std::size_t{0});
    starved_floor = std::max(starved_floor, entry.value("starved_floor", 0.0f));
    hull += entry.value("stopped_hull_voxels", std::size_t{0});
    if (entry.contains("summary") && entry["summary"].is_object()) {
      const double f = entry["summary"].value("field_per_mu", 1.0);
      if (std::find(field_per_mu.begin(), field_per_mu.end(), f) == field_per_mu.end()) {
        field_per_mu.push_back(f);
      }
    }
    const nlohmann::json readings = entry.value("readings", nlohmann::json());
    if (!readings.is_object()) continue;
    non_finite += readings.value("non_finite", std::size_t{0});
    if (!readings.contains("flat_field")) continue;
    const nlohmann::json& f = readings["flat_field"];
    if (!flat) {
      flat = FlatFieldReport{};
      flat->flat_frames = f["flat_frames"];
      flat->dark_frames = f["dark_frames"];
      flat->flat_series = f["flat_series"];
      flat->flat_change = f["flat_change"];
      flat->air_drift_sigmas = -1.0;
    }
    flat->invalid_readings += f["invalid_readings"].get<std::size_t>();
    // The slabs' rows' noise: the largest of their medians (older records: none).
    flat->dark_noise = std::max(flat->dark_noise, f.value("dark_noise", 0.0));
    flat->readings_in_dark_noise += f.value("readings_in_dark_noise", std::size_t{0});
    flat->saturated_readings +=
        f.value("saturated_readings", std::size_t{0});  // older records: none
    flat->pixels_without_beam += f["pixels_without_beam"].get<std::size_t>();
    flat->pixels += f["pixels"].get<std::size_t>();
    // null where the air read nothing finite at the scan's start or end (NaN in JSON).
    const double sigmas =
        f["air_drift_sigmas"].is_number() ? f["air_drift_sigmas"].get<double>() : -1.0;
    if (sigmas > flat->air_drift_sigmas && f["air_first"].is_number() &&
        f["air_last"].is_number()) {
      flat->air_drift_sigmas = sigmas;
      flat->air_first = f["air_first"];
      flat->air_last = f["air_last"];
    }
  }
  if (flat) {
    flat->air_drift_sigmas = std::max(0.0, flat->air_drift_sigmas);
    for (const std::string& line : flat_field_notes(*flat)) console.line(line);
  }
  note_non_finite(console, non_finite);
  note_starved_readings(console, starved, starved_floor);
  note_stopped_hull(console, hull, std::nullopt);
  // Rows a slab's training filled from the rows beside them, by the detector's numbering.
  std::vector<std::size_t> filled_rows;
  for (const Slab& s : run.slabs()) {
    const nlohmann::json& entry = run.manifest()["slabs"][s.index];
    if (!entry.contains("summary") || !entry["summary"].is_object()) continue;
    for (const auto& r : entry["summary"].value("filled_rows", nlohmann::json::array())) {
      filled_rows.push_back(s.rows.first + r.get<std::size_t>());
    }
  }
  std::sort(filled_rows.begin(), filled_rows.end());
  filled_rows.erase(std::unique(filled_rows.begin(), filled_rows.end()), filled_rows.end());
  note_filled_rows(console, filled_rows);
  // The field's unit, as a single scan's run says it (before, a slab run said nothing of it).
  std::sort(field_per_mu.begin(), field_per_mu.end());
  if (!field_per_mu.empty() && (field_per_mu.size() > 1 || field_per_mu[0] != 1.0)) {
    std::string factors;
    for (double f : field_per_mu) {
      char one[32];
      std::snprintf(one, sizeof(one), "%s%g", factors.empty() ? "" : ", ", f);
      factors += one;
    }
    console.line(
        "the readings' attenuation lies far from the usual 0.001-0.06 /mm: the slabs' "
        "fields learn it times " +
        factors + " (summary.json field_per_mu)");
  }
  // Slabs with nothing to reconstruct (a dead detector row): written as NaN, said here.
  nlohmann::json without_readings = nlohmann::json::array();
  for (const Slab& s : run.slabs()) {
    const nlohmann::json& entry = run.manifest()["slabs"][s.index];
    if (!entry.contains("no_readings")) continue;
    without_readings.push_back({{"slices", {s.first_slice, s.slices}},
                                {"rows", {s.rows.first, s.rows.count}},
                                {"reason", entry["no_readings"]}});
    const auto range = [](const char* one, const char* many, std::size_t first, std::size_t count) {
      return count == 1 ? std::string(one) + " " + std::to_string(first)
                        : std::string(many) + " " + std::to_string(first) + ".." +
                              std::to_string(first + count - 1);
    };
    console.line(range("slice", "slices", s.first_slice, s.slices) + " written as NaN: " +
                 range("detector row", "detector rows", s.rows.first, s.rows.count) +
                 " read nothing to reconstruct (" + entry["no_readings"].get<std::string>() + ")");
  }
  write_detector_outputs(out, run.alpha(), run.beta(), dead);
  std::string gathered;
  if (gather) {
    gathered = (out / ("volume." + format)).string();
    gather_slices(run, gathered);
  }
  write_png(out / "image.png", run.preview());
  write_text(out / "config.json", config.to_json());
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::size_t peak = slab_machine_peak_bytes(run.manifest()["slabs"], training_started_unix);
  double trained_seconds = 0.0;
  for (const nlohmann::json& entry : run.manifest()["slabs"]) {
    trained_seconds += entry.value("seconds", 0.0);
  }
  nlohmann::json summary = {
      {"volume", run.volume_dir().string()},
      {"volume_file", gathered.empty()
                          ? nlohmann::json(nullptr)
                          : nlohmann::json(format == "h5" ? gathered + ":/volume" : gathered)},
      {"shape", g.volume_shape},
      {"voxel_mm", g.voxel_mm},
      {"slabs", run.slabs().size()},
      {"slices_per_slab", run.slices_per_slab()},
      {"slabs_done_before", done_before},
      {"ranks", ranks.size()},
      {"workers", run.workers()},
      {"processes", processes},
      {"processes_pinned", copies_pinned},
      {"slices_2d", run.slices_2d()},
      {"memory_limit_bytes", run.memory_limit()},
      {"slab_bytes_estimated", slab_bytes(g, run.slices_per_slab())},
      {"device_memory_limit_bytes", run.device_memory_limit()},
      {"slab_device_bytes_estimated",
       run.device_memory_limit() ? slab_device_bytes(g, run.slices_per_slab()) : 0},
      {"device_bound", run.device_bound()},
      {"peak_host_bytes", peak},
      {"slab_seconds", trained_seconds},
      // This run's slices (all ranks and workers) per minute of its training.
      {"slices_per_minute",
       training_wall > 0 ? 60.0 * (static_cast<double>(total) - slices_at_start) / training_wall
                         : 0.0},
      {"training_seconds", training_wall},
      {"dead_elements", dead.size()},
      {"changing_elements", changing},
      {"slabs_without_readings", without_readings},
      {"non_finite_measurements", non_finite},
      {"starved_readings", starved},
      {"stopped_hull_voxels", hull},
      {"field_per_mu", field_per_mu},
      {"inputs", inputs_json(args)},
      {"flat_field", flat ? flat_field_json(*flat) : nlohmann::json(nullptr)},
      {"centre",
       run.source().centre() ? centre_json(*run.source().centre()) : nlohmann::json(nullptr)},
      {"geometry_doubts", doubts},
      {"wall_seconds", wall},
      {"per_slab", run.manifest()["slabs"]}};
  write_text(out / "summary.json", summary.dump(1) + "\n");
  if (!changing.empty()) {
    console.line("partial rings: " + std::to_string(changing.size() - dying) +
                 " element(s) change response part-way and " + std::to_string(dying) +
                 " die part-way, each trained with alpha and beta per segment of views "
                 "(summary.json changing_elements: rows, column, segments)");
  }
  console.line("reconstructed " + shape_string(g.volume_shape) + " in " +
               std::to_string(run.slabs().size()) + " slabs in " + format_duration(wall) + " (" +
               std::to_string(dead.size()) + " elements flagged dead) -> " +
               run.volume_dir().string());
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
