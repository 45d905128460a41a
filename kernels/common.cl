// common.cl: helpers shared by every riner program. Passed as the first source string of each
// program (never #included), so it holds no __kernel and needs no -D constants.
// OpenCL C 1.2, fp32.

// Helpers inlined and fixed-count loops unrolled: PoCL's compiler otherwise leaves the small
// loops over levels, corners and MLP vectors rolled, with their arrays on the stack, and the
// helpers out of line (measured: the training step 1.7x slower on a CPU); NVIDIA's compiler
// takes the same hints.
#if defined(__clang__)
#define RINER_INLINE inline __attribute__((always_inline))
#else
#define RINER_INLINE inline
#endif
#define RINER_UNROLL _Pragma("unroll")

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

// Float atomic add where the sum is all that matters (no old value returned), in the fastest
// form the device has; the host's execution plan picks one with -D:
//   FLOAT_ATOMICS_NV   NVIDIA: inline PTX red.global.add.f32 (fire-and-forget, done in L2)
//   FLOAT_ATOMICS_EXT  cl_ext_float_atomics (built with -cl-std=CL3.0), where the compiler
//                      declares it (PoCL 5 reports the extension but does not: CAS there)
//   FLOAT_ATOMICS_AMD  AMD's builtin, where the compiler has it
//   otherwise          the compare-and-swap loop above (serialises under contention)
inline void atomic_add_global(volatile __global float* address, float value) {
#if defined(FLOAT_ATOMICS_NV)
  asm volatile("red.global.add.f32 [%0], %1;" ::"l"(address), "f"(value) : "memory");
#elif defined(FLOAT_ATOMICS_EXT) && defined(__opencl_c_ext_fp32_global_atomic_add)
  atomic_fetch_add_explicit((volatile __global atomic_float*)address, value, memory_order_relaxed);
#elif defined(FLOAT_ATOMICS_AMD) && defined(__has_builtin)
#if __has_builtin(__builtin_amdgcn_global_atomic_fadd_f32)
  __builtin_amdgcn_global_atomic_fadd_f32(address, value);
#else
  atomic_add_f32(address, value);
#endif
#else
  atomic_add_f32(address, value);
#endif
}

// Gradient accumulation: plain adds into a buffer the work-item owns, or float atomics into
// one shared buffer when compiled with -D ATOMIC_GRADIENTS.
#ifdef ATOMIC_GRADIENTS
#define GRAD_ADD(p, v) atomic_add_global((p), (v))
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

// Index i in [-n, 2n) mirrored into [0, n), repeating the end (d c b a | a b c d | d c b a):
// scipy's 'reflect', the stripe filters' edge rule.
inline int mirrored(int i, const int n) {
  if (i < 0) i = -i - 1;
  if (i >= n) i = 2 * n - i - 1;
  return clamp(i, 0, n - 1);
}
