// wavelet.cl: one level of the periodised orthogonal wavelet transform along lines of an array
// (the decomposition of Münch et al.'s stripe filter); the CPU twin is analyse_line and
// synthesise_line in lib/src/destripe/wavelets.cpp. A line l holds n (even) values, value i at
// first + l * line_step + i * stride; in and out share that layout and must not overlap.
//   wavelet_analyse(n_out, n, first, line_step, stride, taps, h, g, in, out)
//     one work-item per (line, k < n / 2), n_out = lines * n / 2: out[k] = sum_t h[t]
//     in[(2k + t) mod n] (the approximation) and out[n / 2 + k] the same with g (the detail).
//   wavelet_synthesise(n_out, n, first, line_step, stride, taps, h, g, in, out)
//     its transpose, which is its inverse: one work-item per (line, i < n), n_out = lines * n:
//     out[i] = sum over t with i - t even (mod n) of h[t] in[k] + g[t] in[n / 2 + k],
//     k = ((i - t) mod n) / 2.
// h and g float[taps] (low and high pass). Needs nothing else. No -D constants.

__kernel void wavelet_analyse(const uint n_out, const uint n, const uint first,
                              const uint line_step, const uint stride, const uint taps,
                              __global const float* h, __global const float* g,
                              __global const float* in, __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= n_out) return;
  const uint mid = n / 2;
  const uint k = gid % mid;
  const uint start = first + (gid / mid) * line_step;
  float a = 0.0f, d = 0.0f;
  for (uint t = 0; t < taps; ++t) {
    const float x = in[start + ((2 * k + t) % n) * stride];
    a += h[t] * x;
    d += g[t] * x;
  }
  out[start + k * stride] = a;
  out[start + (mid + k) * stride] = d;
}

__kernel void wavelet_synthesise(const uint n_out, const uint n, const uint first,
                                 const uint line_step, const uint stride, const uint taps,
                                 __global const float* h, __global const float* g,
                                 __global const float* in, __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= n_out) return;
  const int i = gid % n;
  const uint start = first + (gid / n) * line_step;
  const uint mid = n / 2;
  float sum = 0.0f;
  for (int t = 0; t < (int)taps; ++t) {
    const int r = ((i - t) % (int)n + (int)n) % (int)n;
    if (r % 2 != 0) continue;
    const uint k = r / 2;
    sum += h[t] * in[start + k * stride] + g[t] * in[start + (mid + k) * stride];
  }
  out[start + i * stride] = sum;
}
