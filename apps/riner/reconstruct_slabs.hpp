// `riner reconstruct` on a projection stack by slabs of slices (riner/slab_run.hpp): asked for
// with --slab-slices, --memory-limit, --slices-2d, --field-3d or (on a stack) --resume, or chosen when a
// parallel-beam volume does not fit in memory whole or its slices are large enough to train
// each alone. Writes volume/ (one TIFF per axial slice), manifest.json, alpha.npy,
// beta.npy, detector.png, image.png (the three central planes), config.json and summary.json.
#pragma once

#include <chrono>

#include "cli_args.hpp"
#include "cli_common.hpp"
#include "riner/riner_config.hpp"
#include "riner/slab_run.hpp"

namespace riner::app {

void add_slab_options(Args& args);

// --format, checked (UsageError): nii, npy, tif, raw or h5, whole run or slabbed.
std::string output_format(const Args& args);

// --slab-slices and --memory-limit (0 where not given), as riner fbp takes them too.
SlabOptions slab_size_options(const Args& args);

// --report-every, checked: 1 or more steps (-1 and 0 were taken).
int report_every(const Args& args);

// A --memory-limit given below what a slab of one slice takes (`one_slice` bytes) cannot be kept:
// UsageError naming both, before anything is read or written. The default limit is not checked
// here (the run says so and goes on).
void refuse_limit_below_one_slice(const SlabOptions& asked, std::size_t one_slice);

// A parallel-beam stack whose slices are at least this wide trains each slice alone in 2D by
// default: on 256² slices that is 10-15 dB above slabs of 3D fields at the same or less time
// (docs/history/RESULTS.md, "a slab as one field or each slice in 2D"); on smaller ones
// (savu_proj3d's 160²) the 3D field is what was measured, and a 2D slice's 24 000 steps cost the
// most there.
constexpr std::size_t kSlices2dFromPx = 256;
bool slices_2d_by_default(const Geometry& g);

// --checkpoint-minutes in seconds (0: never; UsageError below 0): a slice's training, or each
// slab's, saves its state that often (Reconstructor::save_checkpoint).
double checkpoint_seconds(const Args& args);

// Whether this run goes by slabs (it reads the geometry and the data's header, no data).
bool wants_slabs(const Args& args);

int reconstruct_by_slabs(const Args& args, const Console& console, const RinerConfig& config,
                         std::chrono::steady_clock::time_point started);

}  // namespace riner::app
