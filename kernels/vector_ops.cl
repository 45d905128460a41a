// vector_ops.cl: element-wise vector kernels.
//   vector_ops_axpy(n, a, x, y):  y[i] += a * x[i]            one work-item per element
//   vector_ops_sum(n, x, total):  total[0] += sum_i x[i]      one work-item per element,
//                                 through atomic_add_f32 (not bit-deterministic)
//   vector_ops_fill(n, value, y): y[i] = value                one work-item per element
//                                 (a kernel rather than clEnqueueFillBuffer so that oclgrind's
//                                 uninitialised-value checker sees the writes)
// No -D constants. Buffers are plain float arrays of n elements.

__kernel void vector_ops_axpy(const uint n, const float a, __global const float* x,
                              __global float* y) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  y[i] += a * x[i];
}

__kernel void vector_ops_sum(const uint n, __global const float* x, __global float* total) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  atomic_add_f32(total, x[i]);
}

__kernel void vector_ops_fill(const uint n, const float value, __global float* y) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  y[i] = value;
}
