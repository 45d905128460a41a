// stripe_columns.cl: the steps of classical stripe removal (riner/destripe.hpp) other than the
// sorting (stripe_sorting.cl), the Fourier filters (line_filter.cl) and the wavelet transform
// (wavelet.cl), on one sinogram [views][columns] (row-major, float). The CPU twins are
// lib/src/destripe/destripe.cpp and sinogram_ops.cpp, named alike.
//   column_means(views, columns, from, to, in, means)
//     one work-item per column: its mean over the views [from, to).
//   subtract_column_offsets(n, columns, offsets, values): values[v][c] -= offsets[c].
//   view_deviations(views, columns, reach, in, deviation)
//     deviation[v][c] = |in[v][c] - its moving mean along the views over 2 reach + 1 views|,
//     the column mirrored at its ends (d c b a | a b c d | d c b a).
//   column_fluctuation(views, columns, near, far, span, deviation, total, own)
//     one work-item per column c: total[c] = the sum over the views of deviation[v][c];
//     own[c] = the sum of what deviation[v][c] has beyond the largest deviation of the columns
//     c +- near..far within span views of v (span <= FLUCTUATION_SPAN_MAX).
//   interpolate_columns(n, columns, left, right, weight, values)
//     where weight[c] >= 0: values[v][c] = (1 - weight) values[v][left] + weight
//     values[v][right]; left and right are columns the step leaves alone (weight < 0).
//   replace_masked_columns(n, columns, mask, source, values): values = source where mask[c].
//   add_difference(views, columns, plus, plus_first, plus_stride, minus, minus_first,
//                  minus_stride, values)
//     values[v][c] += plus[plus_first + v plus_stride + c] - minus[minus_first + v minus_stride +
//     c].
//   polynomial_coefficients(views, columns, terms, basis, in, coefficients)
//     one work-item per (term j, column c): sum_v basis[v][j] in[v][c] (basis orthonormal).
//   polynomial_values(views, columns, terms, basis, coefficients, trend)
//     trend[v][c] = sum_j basis[v][j] coefficients[j][c].
//   reflect_pad_views(views, columns, pad, out_views, in, out)
//     out [out_views][columns], row i from in's row i - pad: each column mirrored about its first
//     and last views without repeating them (c b | a b c d | c b a).
//   periodic_extension(views, columns, out_views, out_columns, in, out)
//     in at out's top left, the rest a raised-cosine blend from the last column back to the
//     first, then from the last view back to the first (out continuous when wrapped).
//   copy_block(rows, columns, src, src_first, src_stride, dst, dst_first, dst_stride).
// Needs common.cl (mirrored). No -D constants.

#define FLUCTUATION_SPAN_MAX 8

__kernel void column_means(const uint views, const uint columns, const uint from, const uint to,
                           __global const float* in, __global float* means) {
  const uint c = get_global_id(0);
  if (c >= columns) return;
  float sum = 0.0f;
  for (uint v = from; v < to; ++v) sum += in[v * columns + c];
  means[c] = sum / (float)max(1u, to - from);
}

__kernel void subtract_column_offsets(const uint n, const uint columns,
                                      __global const float* offsets, __global float* values) {
  const uint i = get_global_id(0);
  if (i < n) values[i] -= offsets[i % columns];
}

__kernel void view_deviations(const uint views, const uint columns, const int reach,
                              __global const float* in, __global float* deviation) {
  const uint i = get_global_id(0);
  if (i >= views * columns) return;
  const int v = (int)(i / columns);
  const uint c = i % columns;
  float mean = 0.0f;
  for (int d = -reach; d <= reach; ++d) mean += in[mirrored(v + d, views) * columns + c];
  deviation[i] = fabs(in[i] - mean / (float)(2 * reach + 1));
}

// The largest deviation of the columns c +- near..far in view v (0 where none is in the row).
float neighbours_deviation(const uint columns, const int near, const int far, const int c,
                           __global const float* row) {
  float most = 0.0f;
  for (int k = near; k <= far; ++k) {
    if (c - k >= 0) most = fmax(most, row[c - k]);
    if (c + k < (int)columns) most = fmax(most, row[c + k]);
  }
  return most;
}

__kernel void column_fluctuation(const uint views, const uint columns, const int near,
                                 const int far, const int span, __global const float* deviation,
                                 __global float* total, __global float* own) {
  const int c = (int)get_global_id(0);
  if (c >= (int)columns) return;
  // The neighbours' largest deviation in the views v - span .. v + span, kept in a ring.
  float ring[2 * FLUCTUATION_SPAN_MAX + 1];
  const int width = 2 * span + 1, n = (int)views;
  for (int u = 0; u < min(span, n); ++u) {
    ring[u % width] = neighbours_deviation(columns, near, far, c, deviation + u * columns);
  }
  float sum = 0.0f, beyond = 0.0f;
  for (int v = 0; v < n; ++v) {
    const int ahead = v + span;
    if (ahead < n) {
      ring[ahead % width] =
          neighbours_deviation(columns, near, far, c, deviation + ahead * columns);
    }
    float most = 0.0f;
    for (int u = max(0, v - span); u <= min(n - 1, ahead); ++u) most = fmax(most, ring[u % width]);
    const float d = deviation[v * columns + c];
    sum += d;
    beyond += fmax(0.0f, d - most);
  }
  total[c] = sum;
  own[c] = beyond;
}

__kernel void interpolate_columns(const uint n, const uint columns, __global const uint* left,
                                  __global const uint* right, __global const float* weight,
                                  __global float* values) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint c = i % columns;
  const float t = weight[c];
  if (t < 0.0f) return;
  const uint row = i - c;
  values[i] = (1.0f - t) * values[row + left[c]] + t * values[row + right[c]];
}

__kernel void replace_masked_columns(const uint n, const uint columns,
                                     __global const uchar* mask, __global const float* source,
                                     __global float* values) {
  const uint i = get_global_id(0);
  if (i < n && mask[i % columns]) values[i] = source[i];
}

__kernel void add_difference(const uint views, const uint columns, __global const float* plus,
                             const uint plus_first, const uint plus_stride,
                             __global const float* minus, const uint minus_first,
                             const uint minus_stride, __global float* values) {
  const uint i = get_global_id(0);
  if (i >= views * columns) return;
  const uint v = i / columns, c = i % columns;
  values[i] += plus[plus_first + v * plus_stride + c] - minus[minus_first + v * minus_stride + c];
}

__kernel void polynomial_coefficients(const uint views, const uint columns, const uint terms,
                                      __global const float* basis, __global const float* in,
                                      __global float* coefficients) {
  const uint i = get_global_id(0);
  if (i >= terms * columns) return;
  const uint j = i / columns, c = i % columns;
  float sum = 0.0f;
  for (uint v = 0; v < views; ++v) sum += basis[v * terms + j] * in[v * columns + c];
  coefficients[i] = sum;
}

__kernel void polynomial_values(const uint views, const uint columns, const uint terms,
                                __global const float* basis, __global const float* coefficients,
                                __global float* trend) {
  const uint i = get_global_id(0);
  if (i >= views * columns) return;
  const uint v = i / columns, c = i % columns;
  float sum = 0.0f;
  for (uint j = 0; j < terms; ++j) sum += basis[v * terms + j] * coefficients[j * columns + c];
  trend[i] = sum;
}

__kernel void reflect_pad_views(const uint views, const uint columns, const uint pad,
                                const uint out_views, __global const float* in,
                                __global float* out) {
  const uint i = get_global_id(0);
  if (i >= out_views * columns) return;
  int v = (int)(i / columns) - (int)pad;
  if (v < 0) v = -v;
  if (v >= (int)views) v = 2 * (int)views - v - 2;
  v = clamp(v, 0, (int)views - 1);
  out[i] = in[v * columns + i % columns];
}

// The raised-cosine weight of the far end at step j + 1 of a blend of n steps.
inline float blend_weight(const uint j, const uint n) {
  return 0.5f - 0.5f * cospi((float)(j + 1) / (float)(n + 1));
}

// Row v (< views) of the extension at column c: in, then the blend back to the row's start.
inline float extended_row(const uint views, const uint columns, const uint out_columns,
                          __global const float* in, const uint v, const uint c) {
  if (c < columns) return in[v * columns + c];
  const float w = blend_weight(c - columns, out_columns - columns);
  return (1.0f - w) * in[v * columns + columns - 1] + w * in[v * columns];
}

__kernel void periodic_extension(const uint views, const uint columns, const uint out_views,
                                 const uint out_columns, __global const float* in,
                                 __global float* out) {
  const uint i = get_global_id(0);
  if (i >= out_views * out_columns) return;
  const uint v = i / out_columns, c = i % out_columns;
  if (v < views) {
    out[i] = extended_row(views, columns, out_columns, in, v, c);
    return;
  }
  const float w = blend_weight(v - views, out_views - views);
  out[i] = (1.0f - w) * extended_row(views, columns, out_columns, in, views - 1, c) +
           w * extended_row(views, columns, out_columns, in, 0, c);
}

__kernel void copy_block(const uint rows, const uint columns, __global const float* src,
                         const uint src_first, const uint src_stride, __global float* dst,
                         const uint dst_first, const uint dst_stride) {
  const uint i = get_global_id(0);
  if (i >= rows * columns) return;
  const uint r = i / columns, c = i % columns;
  dst[dst_first + r * dst_stride + c] = src[src_first + r * src_stride + c];
}
