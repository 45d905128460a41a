#include "riner/slab_run.hpp"

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>

#include "io/data_fingerprint.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/log.hpp"
#include "riner/volume_writer.hpp"

namespace riner {

namespace {

// host:pid, unique among the processes of a run at one time.
std::string this_process_name() {
  char host[256] = {};
  if (gethostname(host, sizeof(host) - 1) != 0) host[0] = '\0';
  return std::string(host) + ":" + std::to_string(static_cast<long>(getpid()));
}

constexpr int kManifestVersion = 1;

// What a manifest must match to be resumed: the data, its geometry, the settings and the cut.
nlohmann::json identity(const ScanRows& source, const RinerConfig& config,
                        std::size_t slices_per_slab, bool slices_2d) {
  nlohmann::json id = {
      {"scan", std::filesystem::absolute(source.what()).lexically_normal().string()},
      {"shape", source.shape()},
      {"geometry", nlohmann::json::parse(source.geometry().to_json())},
      {"config", nlohmann::json::parse(config.to_json())},
      {"slices_per_slab", slices_per_slab}};
  if (slices_2d) id["slices_2d"] = true;  // absent otherwise, as in earlier runs' manifests
  // The data itself: a resumed run reads the same bytes wherever the files are now.
  const ScanSource& files = source.files();
  nlohmann::json data = nlohmann::json::object();
  for (const auto& [key, name] :
       {std::pair{"scan", &files.path}, std::pair{"flat", &files.flat},
        std::pair{"dark", &files.dark}, std::pair{"flat_after", &files.flat_after}}) {
    if (name->empty()) continue;
    const io::DataFingerprint f = io::data_fingerprint(*name);
    char hash[24];
    std::snprintf(hash, sizeof(hash), "%016llx", static_cast<unsigned long long>(f.hash));
    data[key] = {{"bytes", f.bytes}, {"files", f.files}, {"sampled_hash", hash}};
  }
  id["data"] = data;
  return id;
}

// What the slab's readings were, for the whole run's report: the non-finite readings of the
// rows it maps (a cone beam's slabs read their neighbours' rows too), and raw projections'
// normalisation (its counts scaled to the rows it maps).
nlohmann::json readings_record(const Scan& scan, const Slab& slab, const FlatFieldReport& flat) {
  const std::size_t n_u = scan.geometry.n_u, rows = slab.rows.count;
  const std::size_t first = slab.map_rows.first - slab.rows.first;
  std::size_t non_finite = 0;
  for (std::size_t v = 0; v < scan.geometry.n_views(); ++v) {
    const float* line = scan.measurement.ptr() + (v * rows + first) * n_u;
    for (std::size_t i = 0; i < slab.map_rows.count * n_u; ++i) {
      non_finite += std::isfinite(line[i]) ? 0 : 1;
    }
  }
  nlohmann::json out = {{"non_finite", non_finite}};
  if (flat.flat_frames == 0) return out;
  const double share = static_cast<double>(slab.map_rows.count) / static_cast<double>(rows);
  const auto scaled = [&](std::size_t n) {
    return static_cast<std::size_t>(std::lround(share * static_cast<double>(n)));
  };
  const auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  out["flat_field"] = {{"flat_frames", flat.flat_frames},
                       {"dark_frames", flat.dark_frames},
                       {"invalid_readings", scaled(flat.invalid_readings)},
                       {"dark_noise", flat.dark_noise},
                       {"readings_in_dark_noise", scaled(flat.readings_in_dark_noise)},
                       {"saturated_readings", scaled(flat.saturated_readings)},
                       {"pixels_without_beam", scaled(flat.pixels_without_beam)},
                       {"pixels", scaled(flat.pixels)},
                       {"flat_series", flat.flat_series},
                       {"flat_change", flat.flat_change},
                       {"air_first", number(flat.air_first)},
                       {"air_last", number(flat.air_last)},
                       {"air_drift_sigmas", number(flat.air_drift_sigmas)}};
  return out;
}

// A one-slice slab's scan as the slice's own 2D scan: the mean of its detector rows (of the
// finite readings; NaN where a column reads none).
Scan slice_scan(const Scan& slab) {
  const Geometry& g = slab.geometry;
  const std::size_t views = g.n_views(), rows = g.n_v, n_u = g.n_u;
  Scan s;
  s.geometry = axial_slice_geometry(g);
  s.measurement = Array({views, n_u});
  for (std::size_t a = 0; a < views; ++a) {
    for (std::size_t u = 0; u < n_u; ++u) {
      double sum = 0.0;
      int n = 0;
      for (std::size_t r = 0; r < rows; ++r) {
        const float v = slab.measurement.data[(a * rows + r) * n_u + u];
        if (std::isfinite(v)) sum += v, ++n;
      }
      const float mean = n ? static_cast<float>(sum / n) : NAN;
      s.measurement.data[a * n_u + u] = mean;
      s.non_finite += !std::isfinite(mean);
    }
  }
  return s;
}

// A per-column map of a slice trained in 2D, for each of its slab's rows.
Array on_rows(const Array& columns, std::size_t rows) {
  Array map({rows, columns.size()});
  for (std::size_t r = 0; r < rows; ++r) {
    std::copy(columns.data.begin(), columns.data.end(),
              map.data.begin() + static_cast<std::ptrdiff_t>(r * columns.size()));
  }
  return map;
}

std::string numbered(const char* pattern, std::size_t n) {
  char name[64];
  std::snprintf(name, sizeof(name), pattern, n);
  return name;
}

}  // namespace

std::size_t SlabOptions::device_limit(const DeviceInfo& device) const {
  if (device.type == "CPU" || device.global_mem_bytes == 0) return 0;
  const auto own = static_cast<std::size_t>(0.9 * static_cast<double>(device.global_mem_bytes));
  return memory_limit ? std::min(memory_limit, own) : own;
}

SlabRun::SlabRun(ScanRows source, RinerConfig config, std::filesystem::path out,
                 SlabOptions options, std::optional<Device> device)
    : source_(std::move(source)),
      config_(std::move(config)),
      out_(std::move(out)),
      device_(std::move(device)) {
  config_.validate();
  // The CLI's options are checked where they are read; a library caller's here.
  if (options.memory_limit != 0 && options.memory_limit < (std::size_t{1} << 20)) {
    throw InputError("slab options: a memory limit of " + std::to_string(options.memory_limit) +
                     " bytes holds no slab (1 MiB at least; 0: the machine's)");
  }
  if (options.workers < 0 || options.processes < 1 || !(options.checkpoint_seconds >= 0.0) ||
      !std::isfinite(options.checkpoint_seconds)) {
    throw InputError(
        "slab options: workers must be 0 (the device's) or more, processes 1 or "
        "more, checkpoint seconds 0 (none) or more");
  }
  if (std::filesystem::exists(out_) && !std::filesystem::is_directory(out_)) {
    throw InputError(out_.string() + ": is a file; a slabbed run writes into a folder");
  }
  const Geometry& g = source_.geometry();
  memory_limit_ = options.limit();
  const int wanted_workers = options.workers > 0 ? options.workers
                             : device_           ? concurrent_trainings(device_->info()).trainings
                                                 : 1;
  const int processes = std::max(1, options.processes);
  if (device_) device_memory_limit_ = options.device_limit(device_->info());
  const SlabMemory memory{memory_limit_, device_memory_limit_,
                          device_memory_limit_ ? device_->info().max_alloc_bytes : 0};
  slices_2d_ = options.slices_2d;
  checkpoint_seconds_ = options.checkpoint_seconds;
  stop_ = options.stop;
  if (slices_2d_) (void)axial_slice_geometry(g);  // InputError now, not in the first slab
  SlabSizing sizing = size_slabs(g, memory, wanted_workers, processes,
                                 slices_2d_ ? 1 : options.slices_per_slab);
  slices_per_slab_ = sizing.slices_per_slab;
  const std::filesystem::path path = out_ / "manifest.json";
  join_ = options.join;
  if (!join_) {
    std::filesystem::create_directories(out_);
    lock_ = FolderLock(out_);  // before the manifest is read: another live run may write it
  }
  const bool held_run = std::filesystem::exists(path);
  if (join_ && !held_run) {
    throw InputError(path.string() + ": no run to join (the leader writes it first)");
  }
  // Slabs with no manifest to check them against (the manifest removed, as "remove it to run
  // again" was read): their records were trusted, a volume of other settings, or two, taken
  // for this run's (a fuzz audit's).
  if (!held_run && !join_) {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(out_ / "slabs", error)) {
      if (entry.path().filename().string().rfind("slab_", 0) == 0) {
        throw InputError(out_.string() +
                         " holds a slabbed run's slabs (slabs/) but no manifest.json to check "
                         "them against: choose another output folder, or remove that folder to "
                         "run again");
      }
    }
  }
  // A mistyped folder would otherwise start the whole scan again without a word.
  if (options.resume && !held_run && !join_) {
    warn("--resume: " + out_.string() + " holds no slabbed run (manifest.json): starting one");
  }
  if (held_run) {
    if (!options.resume && !join_) {
      // A finished run's manifest records every slab done: "pass --resume to finish it" misled.
      bool finished = false;
      try {
        std::ifstream in(path);
        const nlohmann::json held = nlohmann::json::parse(in);
        const nlohmann::json& slabs = held.at("slabs");
        finished = slabs.is_array() && !slabs.empty() &&
                   std::all_of(slabs.begin(), slabs.end(), [](const nlohmann::json& slab) {
                     return slab.is_object() && slab.value("done", false);
                   });
      } catch (const nlohmann::json::exception&) {
      }
      throw InputError(out_.string() +
                       (finished ? " holds a finished slabbed run (manifest.json): choose another "
                                   "output folder, or remove that folder to run again"
                                 : " holds a slabbed run (manifest.json): pass --resume to finish "
                                   "it, or choose another output folder"));
    }
    try {
      // Not read_text: that marks the file an input, and this run rewrites it.
      std::ifstream in(path);
      manifest_ = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(path.string() + ": unreadable manifest (" + e.what() + ")");
    }
    if (!manifest_.is_object() || manifest_.value("version", 0) != kManifestVersion ||
        !manifest_.contains("run") || !manifest_.contains("slabs") ||
        !manifest_["slabs"].is_array() || !manifest_["run"].is_object()) {
      throw InputError(path.string() + ": not a riner slab manifest");
    }
    // A resumed run keeps its slabs unless told otherwise (another machine's memory would cut
    // the volume elsewhere).
    const nlohmann::json& held_slices = manifest_["run"]["slices_per_slab"];
    if (!options.slices_per_slab && !slices_2d_ && held_slices.is_number_unsigned()) {
      slices_per_slab_ = std::min(held_slices.get<std::size_t>(), g.volume_shape[0]);
      sizing = size_slabs(g, memory, wanted_workers, processes, slices_per_slab_);
    }
  }
  slabs_ = plan_slabs(g, slices_per_slab_);
  workers_ = sizing.workers;
  device_bound_ = sizing.device_bound;
  if (device_) {
    std::string why;
    workers_ = usable_trainings(device_->info(), workers_, &why);
    if (!why.empty()) warn(why);
  }
  const nlohmann::json wanted = identity(source_, config_, slices_per_slab_, slices_2d_);
  if (held_run) {
    // A run of before the data's fingerprint names its scan by path alone.
    const bool by_path = !manifest_["run"].contains("data");
    for (const char* key :
         {"scan", "data", "shape", "geometry", "config", "slices_per_slab", "slices_2d"}) {
      if (std::string(key) == (by_path ? "data" : "scan")) continue;
      if (manifest_["run"].value(key, nlohmann::json()) != wanted.value(key, nlohmann::json())) {
        const std::string what = std::string(key) == "data"
                                     ? "data (the scan's or a flat or dark field's files differ "
                                       "in size or in sampled bytes)"
                                     : key;
        throw InputError(path.string() + ": the run there has another " + what +
                         " than this one; resume it with the same scan and settings, or choose "
                         "another output folder");
      }
    }
  }
  // What a killed run's writes left half-done (a SIGKILL mid-write) goes; the slabs' records
  // and checkpoints stand on their own.
  if (held_run && !join_) {
    for (const std::filesystem::path& folder : {out_, out_ / "slabs", volume_dir()}) {
      remove_stale_temporaries(folder);
    }
  }
  // The plan; done-ness is in the slabs' records.
  manifest_ = {{"version", kManifestVersion}, {"run", wanted}, {"slabs", nlohmann::json::array()}};
  for (const Slab& s : slabs_) {
    manifest_["slabs"].push_back({{"index", s.index},
                                  {"first_slice", s.first_slice},
                                  {"slices", s.slices},
                                  {"rows", {s.rows.first, s.rows.count}},
                                  {"done", false}});
    // A cone beam's: the slices around it its rays cross, and the rows it maps.
    if (s.trained_slices != s.slices) {
      manifest_["slabs"].back()["trained_slices"] = {s.trained_first, s.trained_slices};
    }
    if (!(s.map_rows == s.rows)) {
      manifest_["slabs"].back()["map_rows"] = {s.map_rows.first, s.map_rows.count};
    }
  }
  std::filesystem::create_directories(volume_dir());
  std::filesystem::create_directories(out_ / "slabs");
  if (held_run && !join_) forget_damaged_slabs();
  if (!join_) write_manifest();
}

std::filesystem::path SlabRun::slice_path(std::size_t slice) const {
  return VolumeWriter::slice_file(volume_dir(), slice);
}

std::filesystem::path SlabRun::slab_file(const Slab& slab, const std::string& what) const {
  return out_ / "slabs" / (numbered("slab_%04zu_", slab.index) + what + ".npy");
}

bool SlabRun::stopping() const { return stop_ && stop_(); }

std::filesystem::path SlabRun::slab_checkpoint(const Slab& slab) const {
  return out_ / "slabs" / numbered("slab_%04zu.checkpoint", slab.index);
}

void SlabRun::resume_slab(Reconstructor& r, const std::filesystem::path& checkpoint) const {
  if (!std::filesystem::exists(checkpoint)) return;
  // The run's settings and scan were checked against the manifest; a checkpoint that does not
  // fit (a kill mid-write leaves the last whole one, so damage is from elsewhere) costs only
  // the slab's training so far.
  try {
    r.resume_from(checkpoint);
  } catch (const InputError& e) {
    warn(std::string(e.what()) + ": the slab trains from the start");
  }
}

std::filesystem::path SlabRun::slab_record(const Slab& slab) const {
  return out_ / "slabs" / numbered("slab_%04zu.json", slab.index);
}

std::vector<std::filesystem::path> SlabRun::slab_outputs(const Slab& slab) const {
  std::vector<std::filesystem::path> files;
  for (std::size_t k = 0; k < slab.slices; ++k) files.push_back(slice_path(slab.first_slice + k));
  for (const char* what : {"alpha", "beta", "coronal", "sagittal"}) {
    files.push_back(slab_file(slab, what));
  }
  return files;
}

bool SlabRun::is_done(const Slab& slab) const {
  if (!std::filesystem::exists(slab_record(slab))) return false;
  // The record is written last; the files are there unless someone removed them since.
  const std::vector<std::filesystem::path> files = slab_outputs(slab);
  return std::all_of(files.begin(), files.end(),
                     [](const std::filesystem::path& f) { return std::filesystem::exists(f); });
}

namespace {

// The size of each of `files` by its path relative to `out`, as a record keeps them (null for
// one that is not there).
nlohmann::json file_sizes(const std::vector<std::filesystem::path>& files,
                          const std::filesystem::path& out) {
  nlohmann::json sizes = nlohmann::json::object();
  for (const std::filesystem::path& f : files) {
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(f, error);
    sizes[f.lexically_relative(out).generic_string()] =
        error ? nlohmann::json(nullptr) : nlohmann::json(size);
  }
  return sizes;
}

}  // namespace

std::size_t SlabRun::forget_damaged_slabs() const {
  std::size_t forgotten = 0;
  for (const Slab& slab : slabs_) {
    if (!is_done(slab)) continue;
    nlohmann::json record;
    try {
      std::ifstream in(slab_record(slab));
      record = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception&) {
      continue;  // finish() names an unreadable record
    }
    // Records of before the sizes were kept have none to check.
    if (!record.is_object() || !record.contains("file_sizes")) continue;
    const nlohmann::json& held = record["file_sizes"];
    std::string damaged;
    const nlohmann::json now = file_sizes(slab_outputs(slab), out_);
    for (const auto& [name, size] : now.items()) {
      if (size.is_null() || !held.contains(name) || held[name] != size) {
        damaged = name;
        break;
      }
    }
    if (damaged.empty()) continue;
    warn(out_.string() + ": " + damaged + " is not the size slab " + std::to_string(slab.index) +
         "'s record gives (truncated or replaced since it was written): the slab trains again");
    std::filesystem::remove(slab_record(slab));
    ++forgotten;
  }
  return forgotten;
}

double SlabRun::slices_recorded(std::size_t* slabs) const {
  double slices = 0.0;
  std::size_t n = 0;
  for (const Slab& s : slabs_) {
    if (std::filesystem::exists(slab_record(s))) {
      slices += static_cast<double>(s.slices);
      ++n;
    }
  }
  if (slabs) *slabs = n;
  return slices;
}

std::size_t SlabRun::slabs_done() const {
  std::size_t n = 0;
  for (const Slab& s : slabs_) n += is_done(s);
  return n;
}

void SlabRun::write_manifest() const {
  write_text(out_ / "manifest.json", manifest_.dump(1) + "\n");
}

void SlabRun::run(const std::function<void(const SlabProgress&)>& progress,
                  const Summarise& summarise, int report_every, const Claim& claim) {
  const auto started = std::chrono::steady_clock::now();
  const Geometry& g = source_.geometry();
  std::vector<const Slab*> pending;
  for (const Slab& slab : slabs_) {
    if (!is_done(slab)) pending.push_back(&slab);
  }
  // One report at a time: the slices done are those with a record on disk (any process's)
  // plus this process's slabs in training, counted by their steps.
  std::mutex report_mutex;
  std::vector<double> in_training(static_cast<std::size_t>(workers_), 0.0);
  SlabProgress shared;
  shared.slabs = slabs_.size();
  shared.slices = g.volume_shape[0];
  double recorded = slices_recorded(&shared.slabs_done);
  shared.slices_at_start = recorded;
  auto report = [&](const Slab& slab, int worker, double fraction, int step, int steps,
                    bool finished, bool recount) {
    if (!progress) return;
    std::lock_guard<std::mutex> lock(report_mutex);
    if (recount) recorded = slices_recorded(&shared.slabs_done);
    in_training[static_cast<std::size_t>(worker)] = finished ? 0.0 : fraction * slab.slices;
    SlabProgress p = shared;
    p.slab = &slab;
    p.step = step;
    p.steps = steps;
    p.slab_finished = finished;
    p.slices_done = recorded;
    for (double f : in_training) p.slices_done += f;
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    progress(p);
  };
  std::mutex read_mutex;  // the readers (HDF5's above all) are not thread-safe
  run_concurrently(pending.size(), workers_, device_,
                   [&](std::size_t index, int worker, const std::optional<Device>& device) {
                     const Slab& slab = *pending[index];
                     if (stopping()) return;
                     if (claim && !claim(slab)) return;
                     const auto slab_started = std::chrono::steady_clock::now();
                     Scan scan;
                     FlatFieldReport flat;
                     try {
                       std::lock_guard<std::mutex> lock(read_mutex);
                       scan = source_.read(slab.rows, &flat);
                     } catch (const NoReadingsError& e) {
                       write_empty_slab(slab, e.what());
                       report(slab, worker, 1.0, 0, 0, true, true);
                       return;
                     }
                     const nlohmann::json readings = readings_record(scan, slab, flat);
                     scan.geometry = slab_geometry(g, slab);
                     if (slices_2d_) scan = slice_scan(scan);
                     Reconstructor r(std::move(scan), config_, device);
                     const std::filesystem::path checkpoint = slab_checkpoint(slab);
                     resume_slab(r, checkpoint);
                     const int steps = r.config().training.steps;
                     int reports = 0;
                     CheckpointSaver saver(r, checkpoint, checkpoint_seconds_);
                     bool stopped = false;
                     r.run(
                         [&](const TrainingProgress& t) {
                           // Other processes' records, now and then (a stat per slab).
                           report(slab, worker, static_cast<double>(t.step) / std::max(1, t.total),
                                  t.step, steps, false, ++reports % 10 == 0);
                           stopped = t.step < t.total && stopping();
                           saver.after_report(t, stopped);
                           return !stopped;
                         },
                         report_every);
                     if (stopped) return;  // its checkpoint, not a half-trained slab
                     write_slab(slab, r, summarise, device, slab_started, readings);
                     saver.discard();  // the slab's record stands for it now
                     report(slab, worker, 1.0, steps, steps, true, true);
                   });
}

void SlabRun::write_slab(const Slab& slab, const Reconstructor& r, const Summarise& summarise,
                         const std::optional<Device>& device,
                         std::chrono::steady_clock::time_point started,
                         const nlohmann::json& readings) const {
  const Geometry& g = source_.geometry();
  const ReconstructionResult result = r.result();
  Array image = result.image;
  Array alpha = result.alpha;
  Array beta = r.trained_beta();
  mark_dead_elements(r.dead_elements(), alpha, beta);  // as SlabRun::alpha() and beta() give them
  if (slices_2d_) {
    image.shape.insert(image.shape.begin(), 1);
    alpha = on_rows(alpha, slab.rows.count);
    beta = on_rows(beta, slab.rows.count);
  }
  alpha.shape = {slab.rows.count, g.n_u};
  beta.shape = {slab.rows.count, g.n_u};
  // A cone beam's slab: its own slices of those it trained, its own rows of those it read.
  if (slab.trained_slices != slab.slices) {
    image = first_axis_range(image, slab.first_slice - slab.trained_first, slab.slices);
  }
  if (!(slab.map_rows == slab.rows)) {
    alpha = first_axis_range(alpha, slab.map_rows.first - slab.rows.first, slab.map_rows.count);
    beta = first_axis_range(beta, slab.map_rows.first - slab.rows.first, slab.map_rows.count);
  }
  for (std::size_t k = 0; k < slab.slices; ++k) {
    write_array(slice_path(slab.first_slice + k), axial_slice(image, k),
                {{g.voxel_mm, g.voxel_mm}});
  }
  write_array(slab_file(slab, "alpha"), alpha);
  write_array(slab_file(slab, "beta"), beta);
  write_array(slab_file(slab, "coronal"), coronal_plane(image, image.shape[1] / 2));
  write_array(slab_file(slab, "sagittal"), sagittal_plane(image, image.shape[2] / 2));

  nlohmann::json entry = manifest_["slabs"][slab.index];
  const TrainingStats stats = r.stats();
  entry["done"] = true;
  entry["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  entry["steps"] = stats.steps;
  entry["peak_host_bytes"] = stats.peak_host_bytes;  // this process's, so far
  // Which process trained it, and when it finished: a run's memory on a machine is the sum of
  // its processes' peaks (slab_machine_peak_bytes).
  entry["process"] = this_process_name();
  entry["finished_unix"] = unix_seconds();
  entry["device"] = stats.device;
  entry["dead_elements"] = r.dead_elements().size();
  entry["starved_readings"] =
      stats.starved_readings;  // +inf kept as bounds (model/starved_readings.hpp)
  entry["starved_floor"] = stats.starved_floor;
  entry["stopped_hull_voxels"] = result.stopped_hull_voxels;  // model/stopped_hull.hpp: unknown
  // A slice trained in 2D names its dead elements by column, for every row of the slab.
  entry["trained_as"] = slices_2d_ ? "slice_2d" : "field_3d";
  entry["summary"] = summarise ? summarise(r, result, device) : nlohmann::json(nullptr);
  entry["readings"] = readings;
  entry["file_sizes"] = file_sizes(slab_outputs(slab), out_);  // checked on --resume
  write_text(slab_record(slab), entry.dump(1) + "\n");  // last: the slab is done
}

void SlabRun::write_empty_slab(const Slab& slab, const std::string& why) const {
  const Geometry& g = source_.geometry();
  const std::size_t ny = g.volume_shape[1], nx = g.volume_shape[2];
  for (std::size_t k = 0; k < slab.slices; ++k) {
    write_array(slice_path(slab.first_slice + k), Array({ny, nx}, NAN), {{g.voxel_mm, g.voxel_mm}});
  }
  write_array(slab_file(slab, "alpha"), Array({slab.map_rows.count, g.n_u}, NAN));
  write_array(slab_file(slab, "beta"), Array({slab.map_rows.count, g.n_u}, 0.0f));
  write_array(slab_file(slab, "coronal"), Array({slab.slices, nx}, NAN));
  write_array(slab_file(slab, "sagittal"), Array({slab.slices, ny}, NAN));
  nlohmann::json entry = manifest_["slabs"][slab.index];
  entry["done"] = true;
  entry["seconds"] = 0.0;
  entry["steps"] = 0;
  entry["process"] = this_process_name();
  entry["finished_unix"] = unix_seconds();
  entry["no_readings"] = why;
  entry["summary"] = nullptr;
  entry["file_sizes"] = file_sizes(slab_outputs(slab), out_);
  write_text(slab_record(slab), entry.dump(1) + "\n");
}

void SlabRun::finish() {
  for (const Slab& slab : slabs_) {
    if (!is_done(slab)) {
      throw InputError("slab " + std::to_string(slab.index) + " (slices " +
                       std::to_string(slab.first_slice) + ".." +
                       std::to_string(slab.first_slice + slab.slices) +
                       ") is not done: run again with --resume");
    }
    std::ifstream in(slab_record(slab));
    try {
      manifest_["slabs"][slab.index] = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(slab_record(slab).string() + ": unreadable (" + e.what() + ")");
    }
  }
  if (join_) return;
  write_manifest();
  // The ranks' claims (this run's and a killed run's) have served their purpose.
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(out_ / "slabs", error)) {
    if (entry.path().extension() == ".claim") std::filesystem::remove(entry.path(), error);
  }
}

Array SlabRun::detector_map(const std::string& what) const {
  const Geometry& g = source_.geometry();
  Array map({g.n_v, g.n_u}, NAN);
  for (const Slab& slab : slabs_) {
    const Array part = read_array(slab_file(slab, what)).array;
    if (part.shape != std::vector<std::size_t>{slab.map_rows.count, g.n_u}) {
      throw InputError(slab_file(slab, what).string() + ": is " + shape_string(part.shape) +
                       "; the slab's rows are " + std::to_string(slab.map_rows.count) + " x " +
                       std::to_string(g.n_u));
    }
    std::copy(part.data.begin(), part.data.end(),
              map.data.begin() + static_cast<std::ptrdiff_t>(slab.map_rows.first * g.n_u));
  }
  return map;
}

Array SlabRun::alpha() const { return detector_map("alpha"); }
Array SlabRun::beta() const { return detector_map("beta"); }

Array SlabRun::preview() const {
  const Geometry& g = source_.geometry();
  const std::size_t nz = g.volume_shape[0], ny = g.volume_shape[1], nx = g.volume_shape[2];
  Array coronal({nz, nx}), sagittal({nz, ny});
  for (const Slab& slab : slabs_) {
    const Array c = read_array(slab_file(slab, "coronal")).array;
    const Array s = read_array(slab_file(slab, "sagittal")).array;
    if (c.size() != slab.slices * nx || s.size() != slab.slices * ny) {
      throw InputError(slab_file(slab, "coronal").string() + ": does not match the slab");
    }
    std::copy(c.data.begin(), c.data.end(),
              coronal.data.begin() + static_cast<std::ptrdiff_t>(slab.first_slice * nx));
    std::copy(s.data.begin(), s.data.end(),
              sagittal.data.begin() + static_cast<std::ptrdiff_t>(slab.first_slice * ny));
  }
  const Array axial = read_array(slice_path(nz / 2)).array;
  return preview_panel(axial, coronal, sagittal);
}

double unix_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::size_t slab_machine_peak_bytes(const nlohmann::json& slabs, double since_unix) {
  std::map<std::string, std::size_t> process_peak;
  std::size_t largest = 0;
  for (const nlohmann::json& entry : slabs) {
    const std::size_t peak = entry.value("peak_host_bytes", std::size_t{0});
    largest = std::max(largest, peak);
    const std::string process = entry.value("process", std::string());
    if (process.empty() || entry.value("finished_unix", 0.0) < since_unix) continue;
    std::size_t& p = process_peak[process];
    p = std::max(p, peak);
  }
  if (process_peak.empty()) return largest;
  std::map<std::string, std::size_t> host_sum;
  for (const auto& [process, peak] : process_peak) {
    host_sum[process.substr(0, process.rfind(':'))] += peak;
  }
  std::size_t busiest = 0;
  for (const auto& [host, sum] : host_sum) busiest = std::max(busiest, sum);
  return busiest;
}

}  // namespace riner
