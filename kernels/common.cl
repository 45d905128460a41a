// common.cl: helpers shared by every riner program. Passed as the first source string of each
// program (never #included), so it holds no __kernel and needs no -D constants.
// OpenCL C 1.2, fp32.

// OpenCL 1.2 has no float atomics: a compare-and-swap loop on the bit pattern. Sums built with
// it depend on the order threads arrive, so results are not bit-deterministic. The first read
// is atomic too (atomic_or with 0), so race checkers see no plain access.
inline void atomic_add_f32(volatile __global float* address, float value) {
  volatile __global uint* bits = (volatile __global uint*)address;
  uint expected = atomic_or(bits, 0u);
  for (;;) {
    const uint desired = as_uint(as_float(expected) + value);
    const uint previous = atomic_cmpxchg(bits, expected, desired);
    if (previous == expected) break;
    expected = previous;
  }
}
