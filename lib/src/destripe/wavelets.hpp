// Orthogonal Daubechies wavelets and their periodised discrete transform, the decomposition
// Münch et al.'s wavelet-Fourier stripe filter works in. The filters come from the spectral
// factorisation of Daubechies' polynomial (the minimum-phase root of each pair), so any order
// is available without a table of coefficients.
#pragma once

#include <cstddef>
#include <vector>

namespace riner::stripes {

// The low-pass (scaling) filter of Daubechies' orthogonal wavelet of `order` vanishing moments
// (db1 is Haar): 2 * order taps, summing to sqrt(2), orthonormal to its shifts by 2. order in
// [1, 12] (beyond, the factorisation loses digits: db15 is orthonormal to only 1e-8).
std::vector<double> daubechies_filter(int order);
// The high-pass filter of the orthogonal pair of `low_pass`: g[n] = (-1)^n h[L - 1 - n].
std::vector<double> wavelet_high_pass(const std::vector<double>& low_pass);

// One level of the periodised transform of the 2D array `values` [rows][columns] (row-major,
// `stride` values between rows), in place on its top-left rows x columns block (both even):
// along the columns, then along the rows. The block's quadrants afterwards: [low rows][low
// columns] (the approximation, the next level's input), [low rows][high columns] (details
// that vary across columns but slowly along the rows: a stripe's), and the two with high rows.
// Orthonormal, so inverse_wavelet_level undoes it exactly.
void wavelet_level(std::vector<double>& values, std::size_t rows, std::size_t columns,
                   std::size_t stride, const std::vector<double>& low_pass);
void inverse_wavelet_level(std::vector<double>& values, std::size_t rows, std::size_t columns,
                           std::size_t stride, const std::vector<double>& low_pass);

}  // namespace riner::stripes
