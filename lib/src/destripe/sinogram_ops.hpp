// The steps Vo's stripe-removal methods are built from, on one sinogram [views][columns] held
// as a row-major vector of doubles.
#pragma once

#include <cstddef>
#include <vector>

namespace riner::stripes {

struct Sinogram {
  std::size_t views = 0;
  std::size_t columns = 0;
  std::vector<double> values;  // [views][columns]
  double& at(std::size_t v, std::size_t c) { return values[v * columns + c]; }
  double at(std::size_t v, std::size_t c) const { return values[v * columns + c]; }
};

// Index i in [-n, 2n) mirrored into [0, n) (scipy's 'reflect': d c b a | a b c d | d c b a).
std::size_t reflect(long i, std::size_t n);

// Each column sorted over the views: sorted values and, for each, the view it came from.
struct SortedColumns {
  Sinogram sorted;
  std::vector<std::size_t> view;  // [rank][column]
};
SortedColumns sort_columns(const Sinogram& s);
// Values at rank k of column c put back at the view they came from.
Sinogram unsort_columns(const Sinogram& sorted, const std::vector<std::size_t>& view);

// Median over `size` (odd) neighbouring columns within each view row, mirrored at the edges
// (scipy's 'reflect': d c b a | a b c d | d c b a).
Sinogram median_across_columns(const Sinogram& s, std::size_t size);
std::vector<double> median_filter(const std::vector<double>& values, std::size_t size);

// `sorted` plus its correction (filtered - sorted) averaged, column by column, over the `window`
// (odd) ranks around each rank, the window cut at the column's first and last ranks.
Sinogram smooth_along_ranks(const Sinogram& sorted, const Sinogram& filtered, std::size_t window);

// Vo's algorithm 4: the elements of `values` (about 1 or 0 where there is no stripe) that stand
// out of the noise of their sorted profile by `snr`, then grown by one on each side.
// Where `allowed` is given, only its elements may stand out (before the growth).
std::vector<bool> detect_stripes(const std::vector<double>& values, double snr,
                                 const std::vector<bool>* allowed = nullptr);

// Masked columns replaced, view by view, by linear interpolation between the nearest unmasked
// columns (held constant beyond the last): column c becomes (1 - weight) left + weight right;
// weight < 0 for the columns kept (all of them when none or every one is masked).
struct ColumnInterpolation {
  std::vector<std::size_t> left, right;
  std::vector<double> weight;
};
ColumnInterpolation interpolation_plan(const std::vector<bool>& mask);
void interpolate_columns(Sinogram& s, const ColumnInterpolation& plan);

// `s` in the top-left corner of a views x columns array (each at least s's), the rest filled so
// that the array is continuous when wrapped around: past the last column a raised-cosine blend
// back to the first, then likewise past the last view. A filter in Fourier space then sees no
// jump at the borders, and a column's offset continues through the padding.
Sinogram periodic_extension(const Sinogram& s, std::size_t views, std::size_t columns);
// The top-left views x columns of `padded`.
Sinogram crop(const Sinogram& padded, std::size_t views, std::size_t columns);

}  // namespace riner::stripes
