// stripe_sorting.cl: the sorting steps of Vo et al.'s stripe removal (riner/destripe.hpp) on one
// sinogram [views][columns]; the CPU twin is lib/src/destripe/sinogram_ops.cpp.
//   sort_columns(views, columns, n, in, sorted, order, keys, views_of)
//     one work-group per column: its readings sorted by (value, view), which is the order a
//     stable sort gives, by a bitonic sort in local memory over n (a power of two >= views; the
//     padding sorts last). sorted[k][c] is the column's k-th value, order[k][c] its view.
//   median_across_columns(views, columns, size, sorted, filtered)
//     one work-item per (rank k, column c): the median of the `size` (odd, <= kMostWindow)
//     columns around c at rank k, mirrored at the ends (d c b a | a b c d | d c b a).
//   unsort_columns(views, columns, filtered, order, out)
//     out[order[k][c]][c] = filtered[k][c].
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

__kernel void unsort_columns(const uint views, const uint columns, __global const float* filtered,
                             __global const uint* order, __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= views * columns) return;
  const uint c = gid % columns;
  out[order[gid] * columns + c] = filtered[gid];
}
