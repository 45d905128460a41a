// Classical stripe removal on sinograms, the methods ring-removal users already run: Vo, Atwood
// and Drakopoulos' sorting, filtering, fitting, large-stripe and dead-stripe methods and their
// combination (the paper's "Super"; Optics Express 26, 28396, 2018), Münch et al.'s
// wavelet-Fourier filter (Optics Express 17, 8567, 2009; the paper's "WaveFFT"), and a
// normalisation of each element's mean over the views in the manner of Rivers (1998). Each works on every
// detector row's sinogram [views, columns] alone, in riner's measurement domain
// rho = -ln(I / I0): a response alpha is an offset -ln(alpha) along a column there, and the
// order-based steps (sorting, medians) are the same in either domain. Seconds where Riner takes
// minutes: a first ring-free answer, a comparison, or a start for Riner.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <optional>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/geometry.hpp"

namespace riner {

enum class DestripeMethod {
  kNormalise,  // each column's mean over the views set to its neighbours' median
  kSorting,    // Vo's algorithm 3: each column sorted, a median across columns, unsorted
  kFiltering,  // Vo's algorithm 2: the columns' low-pass part along the views by sorting
  kFitting,    // Vo's algorithm 1: a polynomial along the views per column, smoothed across
  kWavelet,    // Münch's wavelet-Fourier filter: the stripes' wavelet band high-passed along views
  kLarge,      // Vo's algorithm 5: large stripes found (algorithm 4, and whole columns only)
               // and normalised
  kDead,       // Vo's algorithm 6: dead and fluctuating elements found and interpolated
  kAll,        // dead, then large, then sorting: Vo's remove_all_stripe ("Super")
};

// "normalise", "sorting", "filtering", "fitting", "wavelet", "large", "dead", "all";
// InputError otherwise.
DestripeMethod parse_destripe_method(std::string_view name);
const char* destripe_method_name(DestripeMethod method);

struct DestripeOptions {
  DestripeMethod method = DestripeMethod::kAll;
  // Median window across columns (elements, odd) for small-to-medium stripes; 0: the
  // literature's 21, and 5 in the combination, whose large-stripe step leaves its sorting step
  // only narrow stripes. Wider for wide stripes, narrower where the object's detail is finer
  // than the window (a median across columns flattens what is narrower than half of it).
  std::size_t size = 0;
  // The window for large and dead stripes; 0: the literature's 51.
  std::size_t large_size = 0;
  // The sorting step's (sorting, filtering, all) mean of its correction over this many
  // neighbouring ranks of each sorted column (odd); 0: a sixth of the views; 1: none, Vo's
  // algorithm as published. A detector's offset moves neighbouring ranks alike, the median's
  // bias on the object's detail does not: on the ten DeepLesion slices at the paper's protocol
  // sorting 27.66 -> 29.48 dB, and 32.42 -> 34.26 on the same scans without stripes.
  std::size_t rank_window = 0;
  double snr = 3.0;    // how far above the noise a stripe must stand out to be detected
  // The Gaussian's width in frequency bins; 0: the literature's for the method. filtering: the
  // low-pass along the views (3); fitting: the low-pass across columns (10; smaller is
  // stronger); wavelet: the high-pass along the views of the stripes' band (1; larger is
  // stronger).
  double sigma = 0.0;
  int fit_order = 2;     // fitting: the polynomial's order along the views
  int levels = 0;        // wavelet: decomposition levels; 0: as many as fit, up to 4
  int wavelet_order = 9;  // wavelet: Daubechies' order (db9)
  double drop_ratio = 0.1;  // large stripes: share of each sorted column's extremes left out
  // The sorting step (sorting, filtering, all) runs on the device (kernels/stripe_sorting.cl)
  // where a column's views fit its local memory, else on the CPU, as the other steps do;
  // Engine::kReference: all on the CPU.
  Engine engine = Engine::kOpenCL;
  std::optional<Device> device;  // OpenCL engine; default Device::open()
};

struct DestripeReport {
  // [rows, columns] (2D: [columns], as alpha): each element's mean over the views of what was
  // removed (rho); exp(-removed) is the response a classical filter read off the scan, as
  // alpha.npy.
  Array removed;
  std::vector<std::size_t> dead;   // elements (row * columns + column) interpolated as dead
  std::vector<std::size_t> large;  // elements normalised as large stripes
  std::size_t size = 0;            // the windows used
  std::size_t large_size = 0;
  std::size_t rank_window = 0;     // sorting, filtering, all: the window along the ranks used
  double sigma = 0.0;              // fitting, filtering, wavelet: the width used
  int levels = 0;                  // wavelet: the levels used
  // NaN/inf readings, and absurd ones (beyond 1e20), interpolated from their neighbours first.
  std::size_t non_finite_replaced = 0;
};

// The destriped measurement, shaped as `measurement` ([views, columns] or [views, rows,
// columns] as g says). InputError for a measurement g does not describe or too few views or
// columns (8 each).
Array destripe(const Array& measurement, const Geometry& g, const DestripeOptions& options = {},
               DestripeReport* report = nullptr);

}  // namespace riner
