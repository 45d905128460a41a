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

// Gradient accumulation: plain adds into a buffer the work-item owns (one partial gradient per
// lane, reduced later: deterministic), or float atomics into one shared buffer when compiled
// with -D ATOMIC_GRADIENTS.
#ifdef ATOMIC_GRADIENTS
#define GRAD_ADD(p, v) atomic_add_f32((p), (v))
#else
#define GRAD_ADD(p, v) (*(p) += (v))
#endif

// Counter-based random numbers, identical to lib/src/model/counter_rng.hpp: a 32-bit integer
// hash with good avalanche (Chris Wellons' "lowbias32").
inline uint hash32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

inline uint hash_keys(uint a, uint b, uint c, uint d) {
  return hash32(d ^ hash32(c ^ hash32(b ^ hash32(a))));
}

// Uniform in [0, 1) with 24 bits, exactly representable in float.
inline float uniform24(uint h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

#define JITTER_STREAM 3u

// Fractional offset of sample k of a ray within its interval at a training step.
inline float sample_jitter(uint seed, uint step, uint ray, uint k) {
  return uniform24(hash32(k ^ hash_keys(JITTER_STREAM, seed, step, ray)));
}
