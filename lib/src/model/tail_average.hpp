// Tail averaging (Polyak-Ruppert): the result is made from the mean of the parameters over the
// last steps of training instead of the last step's alone. With noisy readings, each step of
// the L1 data term moves the parameters by about the learning rate whatever the batch, so the
// last iterate carries the last batches' noise, and the finest levels draw it as isolated
// specks (docs/history/RESULTS.md, issue 13). Training itself is unchanged: the engines keep a
// running sum of snapshots beside the parameters. A run stopped early (a plateau, a callback)
// averages the snapshots it took; steps past the planned ones give the last step's parameters
// again.
#pragma once

namespace riner::model {

struct TailAverage {
  static constexpr int kEvery = 10;  // steps between snapshots

  int steps = 0;  // averaged over the last `steps` planned steps; 0: the last iterate
  int total = 0;  // steps planned

  // Whether the parameters after step `step` (0-based) are a snapshot: in the tail, every
  // kEvery steps counted back from the last planned step, so that step is always one.
  bool takes(int step) const {
    return steps > 0 && step < total && step >= total - steps && (total - 1 - step) % kEvery == 0;
  }

  // The snapshots the result is the mean of once `done` steps have run: those taken so far, and
  // none (the last step's parameters) once training has gone past the planned steps.
  int snapshots(int done) const {
    if (done > total) return 0;
    int n = 0;
    for (int s = total - steps; s < done; ++s) n += s >= 0 && takes(s);
    return n;
  }
};

}  // namespace riner::model
