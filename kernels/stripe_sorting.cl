// stripe_sorting.cl: the sorting steps of Vo et al.'s stripe removal (riner/destripe.hpp) on one
// sinogram [views][columns]; the CPU twin is lib/src/destripe/sinogram_ops.cpp.
//   sort_columns(views, columns, n, in, sorted, order, keys, views_of)
//     one work-group per column: its readings sorted by (value, view), which is the order a
//     stable sort gives, by a bitonic sort in local memory over n (a power of two >= views; the
//     padding sorts last). sorted[k][c] is the column's k-th value, order[k][c] its view.
//   median_across_columns(views, columns, size, sorted, filtered)
//     one work-item per (rank k, column c): the median of the `size` (odd, <= kMostWindow)
//     columns around c at rank k, mirrored at the ends (d c b a | a b c d | d c b a).
//   smooth_along_ranks(views, columns, window, sorted, filtered, out)
//     one work-item per column: out = sorted plus the correction (filtered - sorted) averaged
//     over the `window` (odd) ranks around each rank, the window cut at the column's ends.
//   unsort_columns(views, columns, filtered, order, out)
//     out[order[k][c]][c] = filtered[k][c].
// A CPU's shapes of the first two (the same results to the bit; a barrier per bitonic stage and
// a quickselect per element are what a CPU runs slowest):
//   sort_columns_merge(views, columns, in, sorted, order, keys_a, views_a, keys_b, views_b)
//     one work-item per column: a stable merge sort (runs of 8 by insertion, then merges) in
//     the scratch [columns][views] of keys_a/views_a and keys_b/views_b.
//   median_across_columns_sliding(views, columns, size, sorted, filtered)
//     one work-item per rank k: the window kept sorted while it slides along the columns.
// Needs common.cl (mirrored). No -D constants.

#define kMostWindow 255

__kernel void sort_columns(const uint views, const uint columns, const uint n,
                           __global const float* in, __global float* sorted,
                           __global uint* order, __local float* keys, __local uint* views_of) {
  const uint c = get_group_id(0);
  const uint t = get_local_id(0);
  const uint threads = get_local_size(0);
  for (uint i = t; i < n; i += threads) {
    keys[i] = i < views ? in[i * columns + c] : INFINITY;
    views_of[i] = i;  // the padding's "views" come after every real one
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint size = 2; size <= n; size *= 2) {
    for (uint stride = size / 2; stride > 0; stride /= 2) {
      for (uint p = t; p < n / 2; p += threads) {
        const uint a = 2 * p - (p & (stride - 1));
        const uint b = a + stride;
        const int ascending = (a & size) == 0;
        const int a_after_b =
            keys[a] > keys[b] || (keys[a] == keys[b] && views_of[a] > views_of[b]);
        if (a_after_b == ascending) {
          const float k = keys[a];
          keys[a] = keys[b];
          keys[b] = k;
          const uint v = views_of[a];
          views_of[a] = views_of[b];
          views_of[b] = v;
        }
      }
      barrier(CLK_LOCAL_MEM_FENCE);
    }
  }
  for (uint k = t; k < views; k += threads) {
    sorted[k * columns + c] = keys[k];
    order[k * columns + c] = views_of[k];
  }
}

__kernel void median_across_columns(const uint views, const uint columns, const uint size,
                                    __global const float* sorted, __global float* filtered) {
  const uint gid = get_global_id(0);
  if (gid >= views * columns) return;
  const int c = gid % columns;
  const uint row = gid - c;
  const int reach = size / 2;
  float window[kMostWindow];
  for (int d = -reach; d <= reach; ++d) window[d + reach] = sorted[row + mirrored(c + d, columns)];
  // Quickselect of the middle element (Hoare's partition, the middle as pivot).
  int lo = 0, hi = size - 1;
  const int want = reach;
  while (lo < hi) {
    const float pivot = window[(lo + hi) / 2];
    int i = lo, j = hi;
    while (i <= j) {
      while (window[i] < pivot) ++i;
      while (window[j] > pivot) --j;
      if (i <= j) {
        const float x = window[i];
        window[i] = window[j];
        window[j] = x;
        ++i;
        --j;
      }
    }
    if (want <= j) {
      hi = j;
    } else if (want >= i) {
      lo = i;
    } else {
      break;
    }
  }
  filtered[gid] = window[want];
}

// A compensated sum (Kahan's): a window slides over thousands of ranks, each adding one
// correction and taking one away, and a float sum's rounding would accumulate along them.
inline void add_compensated(float* sum, float* lost, const float x) {
  const float y = x - *lost;
  const float t = *sum + y;
  *lost = (t - *sum) - y;
  *sum = t;
}

__kernel void smooth_along_ranks(const uint views, const uint columns, const uint window,
                                 __global const float* sorted, __global const float* filtered,
                                 __global float* out) {
  const uint c = get_global_id(0);
  if (c >= columns) return;
  const int n = views, reach = window / 2;
  float sum = 0.0f, lost = 0.0f;
  for (int k = 0; k <= min(reach, n - 1); ++k) {
    add_compensated(&sum, &lost, filtered[k * columns + c] - sorted[k * columns + c]);
  }
  for (int k = 0; k < n; ++k) {
    const int first = max(k - reach, 0), last = min(k + reach, n - 1);
    out[k * columns + c] = sorted[k * columns + c] + (sum - lost) / (float)(last - first + 1);
    const int entering = k + reach + 1, leaving = k - reach;
    if (entering < n) {
      add_compensated(&sum, &lost,
                      filtered[entering * columns + c] - sorted[entering * columns + c]);
    }
    if (leaving >= 0) {
      add_compensated(&sum, &lost, sorted[leaving * columns + c] - filtered[leaving * columns + c]);
    }
  }
}

__kernel void unsort_columns(const uint views, const uint columns, __global const float* filtered,
                             __global const uint* order, __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= views * columns) return;
  const uint c = gid % columns;
  out[order[gid] * columns + c] = filtered[gid];
}

// Merges the sorted runs [first, middle) and [middle, last) of keys/views into out_keys/out_views,
// the left first among equals (stable).
inline void merge_runs(__global const float* keys, __global const uint* views,
                       __global float* out_keys, __global uint* out_views, const uint first,
                       const uint middle, const uint last) {
  uint i = first, j = middle;
  for (uint o = first; o < last; ++o) {
    const int take_left = j >= last || (i < middle && !(keys[j] < keys[i]));
    const uint from = take_left ? i++ : j++;
    out_keys[o] = keys[from];
    out_views[o] = views[from];
  }
}

__kernel void sort_columns_merge(const uint views, const uint columns, __global const float* in,
                                 __global float* sorted, __global uint* order,
                                 __global float* keys_a, __global uint* views_a,
                                 __global float* keys_b, __global uint* views_b) {
  const uint c = get_global_id(0);
  if (c >= columns) return;
  __global float* keys = keys_a + (size_t)c * views;
  __global uint* view_of = views_a + (size_t)c * views;
  __global float* other_keys = keys_b + (size_t)c * views;
  __global uint* other_views = views_b + (size_t)c * views;
  const uint run = 8;
  for (uint first = 0; first < views; first += run) {
    const uint last = min(first + run, views);
    for (uint i = first; i < last; ++i) {
      const float x = in[i * columns + c];
      uint j = i;
      // Strictly greater: equal readings keep their views' order.
      for (; j > first && keys[j - 1] > x; --j) {
        keys[j] = keys[j - 1];
        view_of[j] = view_of[j - 1];
      }
      keys[j] = x;
      view_of[j] = i;
    }
  }
  for (uint width = run; width < views; width *= 2) {
    for (uint first = 0; first < views; first += 2 * width) {
      const uint middle = min(first + width, views), last = min(first + 2 * width, views);
      merge_runs(keys, view_of, other_keys, other_views, first, middle, last);
    }
    __global float* k = keys;
    keys = other_keys;
    other_keys = k;
    __global uint* v = view_of;
    view_of = other_views;
    other_views = v;
  }
  for (uint k = 0; k < views; ++k) {
    sorted[k * columns + c] = keys[k];
    order[k * columns + c] = view_of[k];
  }
}

__kernel void median_across_columns_sliding(const uint views, const uint columns, const uint size,
                                            __global const float* sorted,
                                            __global float* filtered) {
  const uint k = get_global_id(0);
  if (k >= views) return;
  __global const float* row = sorted + (size_t)k * columns;
  __global float* out = filtered + (size_t)k * columns;
  const int n = columns;
  const int reach = size / 2;
  float window[kMostWindow];
  for (int d = -reach; d <= reach; ++d) {  // insertion sort of the first window
    const float x = row[mirrored(d, n)];
    int j = d + reach;
    for (; j > 0 && window[j - 1] > x; --j) window[j] = window[j - 1];
    window[j] = x;
  }
  for (int c = 0; c < n; ++c) {
    out[c] = window[reach];
    if (c + 1 == n) break;
    // One reading leaves at the window's left end and one enters at its right: the leaving one's
    // slot is found, the entering one slid into place from there.
    const float leaving = row[mirrored(c - reach, n)];
    const float entering = row[mirrored(c + reach + 1, n)];
    int i = 0;
    while (i + 1 < (int)size && window[i] != leaving) ++i;
    while (i > 0 && window[i - 1] > entering) {
      window[i] = window[i - 1];
      --i;
    }
    while (i + 1 < (int)size && window[i + 1] < entering) {
      window[i] = window[i + 1];
      ++i;
    }
    window[i] = entering;
  }
}
