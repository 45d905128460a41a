// line_filter.cl: a convolution along lines of an array, the ramp filter of FBP/FDK along each
// detector row and the Fourier filters of stripe removal (a circular filter of period n is the
// linear convolution with its taps over lags -(n-1)..n-1). A line l holds n values, value i at
// first + l * line_step + i * stride (rows of a row-major array: line_step n, stride 1; its
// columns: line_step 1, stride the row's length); in and out share that layout and must not
// overlap. The CPU twins: reference/fbp_ref.cpp (FBP) and filter_lines in
// destripe/destripe.cpp (stripe removal).
//   line_filter_direct(n_out, n, first, line_step, stride, taps, in, out)
//     one work-item per output value (n_out = lines * n): out[l][j] = sum_j' taps[j - j' + n - 1]
//     * in[l][j'] (taps float[2 n - 1]).
//   line_filter_fft(n_lines, n, first, line_step, stride, n_fft, spectrum, twiddles, in, out, x)
//     the same by FFT, n_fft log n_fft instead of n^2 per line: one work-group per pair of lines,
//     the second as the imaginary part (the taps are real, so the two convolve apart),
//     zero-padded to n_fft, a power of two >= 2 n - 1 (the circular convolution is then the
//     linear one), transformed in local memory x[n_fft] by a radix-2 FFT (decimation in
//     frequency: the spectrum comes out in bit-reversed order), multiplied by the taps' spectrum
//     (given in that order, 1/n_fft folded in) and transformed back (decimation in time from
//     bit-reversed order to natural). twiddles[k] = exp(-2 pi i k / n_fft), k < n_fft / 2.
//   line_filter_fft_global(..., scratch)
//     the same for lines whose padded length does not fit the local memory (a GPU's 48 KiB:
//     lines over 2048, a 2560-column detector's rows): each work-group filters pairs of lines
//     get_num_groups apart in its own n_fft of scratch (float2[groups * n_fft]).
// Needs nothing else. No -D constants.

__kernel void line_filter_direct(const uint n_out, const int n, const uint first,
                                 const uint line_step, const uint stride,
                                 __global const float* taps, __global const float* in,
                                 __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= n_out) return;
  const int j = gid % n;
  const uint start = first + (gid / n) * line_step;
  __global const float* h = taps + j + n - 1;  // h[-j'] = taps[j - j' + n - 1]
  float sum = 0.0f;
  for (int k = 0; k < n; ++k) sum += h[-k] * in[start + k * stride];
  out[start + j * stride] = sum;
}

inline float2 complex_times(const float2 a, const float2 b) {
  return (float2)(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

// One pair of lines (from `line`, the second as the imaginary part) filtered through x[n_fft]:
// in local memory (a line that fits) or in the group's own part of a global scratch buffer (a
// longer line); FENCE orders x's accesses between the passes.
#define FILTER_LINE_PAIR(x, FENCE)                                                         \
  do {                                                                                     \
    const int pair = line + 1 < n_lines;                                                   \
    const uint a = first + line * line_step;                                               \
    const uint b = a + line_step;                                                          \
    for (uint i = t; i < n_fft; i += threads) {                                            \
      x[i] = i < n ? (float2)(in[a + i * stride], pair ? in[b + i * stride] : 0.0f)        \
                   : (float2)(0.0f, 0.0f);                                                 \
    }                                                                                      \
    barrier(FENCE);                                                                        \
    for (uint span = n_fft / 2; span >= 1; span /= 2) {                                    \
      const uint step = n_fft / (2 * span);                                                \
      for (uint k = t; k < n_fft / 2; k += threads) {                                      \
        const uint pos = k & (span - 1);                                                   \
        const uint i = (k - pos) * 2 + pos;                                                \
        const float2 u = x[i];                                                             \
        const float2 v = x[i + span];                                                      \
        x[i] = u + v;                                                                      \
        x[i + span] = complex_times(u - v, twiddles[pos * step]);                          \
      }                                                                                    \
      barrier(FENCE);                                                                      \
    }                                                                                      \
    for (uint k = t; k < n_fft; k += threads) x[k] = complex_times(x[k], spectrum[k]);     \
    barrier(FENCE);                                                                        \
    for (uint span = 1; span < n_fft; span *= 2) {                                         \
      const uint step = n_fft / (2 * span);                                                \
      for (uint k = t; k < n_fft / 2; k += threads) {                                      \
        const uint pos = k & (span - 1);                                                   \
        const uint i = (k - pos) * 2 + pos;                                                \
        const float2 w = twiddles[pos * step];                                             \
        const float2 u = x[i];                                                             \
        const float2 v = complex_times(x[i + span], (float2)(w.x, -w.y));                  \
        x[i] = u + v;                                                                      \
        x[i + span] = u - v;                                                               \
      }                                                                                    \
      barrier(FENCE);                                                                      \
    }                                                                                      \
    for (uint i = t; i < n; i += threads) {                                                \
      out[a + i * stride] = x[i].x;                                                        \
      if (pair) out[b + i * stride] = x[i].y;                                              \
    }                                                                                      \
  } while (0)

__kernel void line_filter_fft(const uint n_lines, const uint n, const uint first,
                              const uint line_step, const uint stride, const uint n_fft,
                              __global const float2* spectrum, __global const float2* twiddles,
                              __global const float* in, __global float* out, __local float2* x) {
  const uint line = 2 * get_group_id(0);
  const uint t = get_local_id(0);
  const uint threads = get_local_size(0);
  FILTER_LINE_PAIR(x, CLK_LOCAL_MEM_FENCE);
}

__kernel void line_filter_fft_global(const uint n_lines, const uint n, const uint first,
                                     const uint line_step, const uint stride, const uint n_fft,
                                     __global const float2* spectrum,
                                     __global const float2* twiddles, __global const float* in,
                                     __global float* out, __global float2* scratch) {
  const uint t = get_local_id(0);
  const uint threads = get_local_size(0);
  __global float2* x = scratch + get_group_id(0) * n_fft;
  for (uint line = 2 * get_group_id(0); line < n_lines; line += 2 * get_num_groups(0)) {
    FILTER_LINE_PAIR(x, CLK_GLOBAL_MEM_FENCE);
    barrier(CLK_GLOBAL_MEM_FENCE);  // the last pass's reads of x before the next pair's writes
  }
}
