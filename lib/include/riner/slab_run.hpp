// A whole scan through riner slab by slab (riner/slab_plan.hpp): each slab's detector rows are
// read alone (riner/scan_source.hpp's ScanRows), trained as one 3D field, and written as it
// finishes into a folder of axial slices (volume/slice_NNNNN.tif, each written whole under a
// temporary name and renamed), with the slab's alpha, beta and preview planes under slabs/ and
// last its record, slabs/slab_NNNN.json: a slab is done when its record is there. manifest.json
// holds the run (scan, geometry, settings, slab size) and, after finish(), every record. A run
// killed at any moment and started again with `resume` redoes only the slabs without a record:
// none is lost, doubled or half-written. Every slab trains with the same seed, so a slab's
// result does not depend on which run or process trained it: several processes (MPI ranks,
// riner/slab_ranks.hpp) share one run by claiming slabs.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "riner/concurrent_trainings.hpp"
#include "riner/device.hpp"
#include "riner/folder_lock.hpp"
#include "riner/reconstructor.hpp"
#include "riner/riner_config.hpp"
#include "riner/scan_source.hpp"
#include "riner/slab_plan.hpp"

namespace riner {

struct SlabOptions {
  std::size_t slices_per_slab = 0;  // 0: as many as memory_limit allows
  std::size_t memory_limit = 0;     // bytes; 0: default_memory_limit()
  bool resume = false;              // finish a run the output folder holds
  // A process joining the run another (the leader, MPI rank 0) has just planned in the same
  // folder: it reads the manifest and never writes it.
  bool join = false;
  // Slabs trained at once on the device (riner/concurrent_trainings.hpp), each worker on its
  // own queue; 0: concurrent_trainings() of the device, as many as the slabs and the memory
  // limit allow (the workers share it). The volume does not depend on it.
  int workers = 0;
  // Each axial slice trained as its own 2D scan (parallel beam: a row's rays stay in its
  // slice): slabs of one slice, each the mean of its detector rows, at the 2D defaults (steps
  // from the slice's rays), instead of a slab of slices as one 3D field.
  bool slices_2d = false;
  // Processes of this machine training the run at once (MPI ranks on it, or the CLI's own
  // slab processes), each `workers` slabs: they share the memory limit, and each gets a slab.
  int processes = 1;
  // Seconds of a slab's training between saves of its state (slabs/slab_NNNN.checkpoint,
  // Reconstructor::save_checkpoint), from which a resumed run goes on; 0: none.
  double checkpoint_seconds = 0.0;
  // Asked between a slab's steps and before each slab: true saves the checkpoint of every slab
  // in training (with checkpoint_seconds > 0) and ends run() without writing them (a signal
  // to stop, say); empty: never.
  std::function<bool()> stop;

  // memory_limit, or default_memory_limit() when it is 0.
  std::size_t limit() const { return memory_limit ? memory_limit : default_memory_limit(); }
  // What the slabs on `device` may take of its own memory: 0 for a device that works in host
  // memory (a CPU: limit() covers it); else nine tenths of what it has, and at most
  // memory_limit when that is set.
  std::size_t device_limit(const DeviceInfo& device) const;
};

struct SlabProgress {
  const Slab* slab = nullptr;  // the slab training now
  std::size_t slabs = 0;       // in the scan
  std::size_t slabs_done = 0;  // finished, this run and earlier ones
  std::size_t slices = 0;      // in the volume
  double slices_done = 0.0;    // finished, counting the slab in training by its steps
  double slices_at_start = 0.0;     // finished when this run began (its speed leaves them out)
  double seconds = 0.0;             // this run's so far
  int step = 0;                     // of the slab in training
  int steps = 0;
  bool slab_finished = false;  // called once more as each slab is written
};

class SlabRun {
 public:
  // Plans the slabs and reads the output folder's manifest. InputError when the folder holds
  // another run's manifest (another scan, geometry, settings or slab size), or any run's
  // without `resume` (nothing is overwritten unasked).
  SlabRun(ScanRows source, RinerConfig config, std::filesystem::path out, SlabOptions options,
          std::optional<Device> device = std::nullopt);

  const std::vector<Slab>& slabs() const { return slabs_; }
  std::size_t slices_per_slab() const { return slices_per_slab_; }
  std::size_t memory_limit() const { return memory_limit_; }
  // The device's memory the slabs may take (SlabOptions::device_limit); 0: none of its own.
  std::size_t device_memory_limit() const { return device_memory_limit_; }
  // Whether the device's memory, not the host's, cut the slabs' size or the workers.
  bool device_bound() const { return device_bound_; }
  int workers() const { return workers_; }
  bool slices_2d() const { return slices_2d_; }
  std::size_t slabs_done() const;
  // Slices whose slab has its record (any process's, this run's or earlier runs'), and in
  // `slabs` (when given) how many slabs that is: what progress counts as done.
  double slices_recorded(std::size_t* slabs = nullptr) const;
  const ScanRows& source() const { return source_; }

  // Per slab, after it is trained: what to record in its manifest entry (the quality report,
  // say), computed on the device the slab trained on; may be empty.
  using Summarise = std::function<nlohmann::json(const Reconstructor&, const ReconstructionResult&,
                                                 const std::optional<Device>&)>;
  // Trains and writes every slab not yet done, in order, that `claim` gives this process (all
  // of them when it is empty; a claim must be given to one process only), workers() at once.
  // `progress` every `report_every` steps of each slab and once as each slab is written, from
  // one thread at a time; its counts include the other workers' slabs in training and other
  // processes' slabs as their records appear.
  using Claim = std::function<bool(const Slab&)>;
  void run(const std::function<void(const SlabProgress&)>& progress = {},
           const Summarise& summarise = {}, int report_every = 50, const Claim& claim = {});

  // Once every slab is done (after run(), and after the other processes' runs): gathers the
  // records into the manifest and, unless joined, writes it. InputError naming the first slab
  // without a record.
  void finish();
  // After finish(): the whole detector's alpha and beta [rows, columns] from the slabs' (NaN
  // where no slab reads a row), the three central planes as riner/io.hpp's preview_panel draws
  // them, and the manifest with each slab's record.
  Array alpha() const;
  Array beta() const;
  Array preview() const;
  const nlohmann::json& manifest() const { return manifest_; }
  std::filesystem::path slab_record(const Slab& slab) const;

  std::filesystem::path slice_path(std::size_t slice) const;
  std::filesystem::path volume_dir() const { return out_ / "volume"; }

 private:
  std::filesystem::path slab_file(const Slab& slab, const std::string& what) const;
  // Every file a done slab leaves (its slices, detector maps and preview planes).
  std::vector<std::filesystem::path> slab_outputs(const Slab& slab) const;
  bool is_done(const Slab& slab) const;
  // Drops the record of each done slab a file of which is not the size the record gives (a
  // file truncated or replaced since): the slab trains again. Returns how many.
  std::size_t forget_damaged_slabs() const;
  bool stopping() const;  // SlabOptions::stop
  // Its training's checkpoint (SlabOptions::checkpoint_seconds), and going on from it.
  std::filesystem::path slab_checkpoint(const Slab& slab) const;
  void resume_slab(Reconstructor& r, const std::filesystem::path& checkpoint) const;
  // The slab's slices, alpha, beta and preview planes, then its record.
  // `readings`: what its readings were (non-finite ones, raw projections' normalisation).
  void write_slab(const Slab& slab, const Reconstructor& r, const Summarise& summarise,
                  const std::optional<Device>& device,
                  std::chrono::steady_clock::time_point started,
                  const nlohmann::json& readings) const;
  // A slab whose readings hold nothing (a dead detector row): NaN slices and alpha, beta 0,
  // and a record saying why, so that the rest of the scan goes on.
  void write_empty_slab(const Slab& slab, const std::string& why) const;
  void write_manifest() const;
  Array detector_map(const std::string& what) const;

  ScanRows source_;
  RinerConfig config_;
  std::filesystem::path out_;
  std::optional<Device> device_;
  std::size_t memory_limit_ = 0;
  std::size_t device_memory_limit_ = 0;
  bool device_bound_ = false;
  std::size_t slices_per_slab_ = 0;
  int workers_ = 1;
  bool slices_2d_ = false;
  double checkpoint_seconds_ = 0.0;
  std::function<bool()> stop_;
  std::vector<Slab> slabs_;
  nlohmann::json manifest_;
  bool join_ = false;
  FolderLock lock_;  // the leader's, for the run's life (joined processes share it)
};

// Seconds since the Unix epoch (the slab records' finished_unix).
double unix_seconds();

// A slabbed run's host memory on its busiest machine, from the manifest's slab records: over
// the records finished at or after `since_unix` (this invocation's), each process's largest
// peak_host_bytes, summed over the processes of each host (they train at the same time);
// the largest record's when none finished since (every slab was done before, or records
// written before riner named their process).
std::size_t slab_machine_peak_bytes(const nlohmann::json& slabs, double since_unix);

}  // namespace riner
