// mlp.cl: the small MLP, input -> [width, ReLU] x MLP_HIDDEN -> 1 (linear output), one sample
// per work-item with the hidden layers in explicit float16 vectors (on CPUs this is what the
// compiler turns into full-width SIMD; see docs/history/RESULTS.md).
//   Helpers: mlp_forward(w, in, act) -> output; mlp_backward(w, g, in, act, d_out, d_in);
//            mlp_deltas(w, act, d_out, delta, d_in) (no weight gradients: see mlp_gradient.cl)
//   mlp_forward_batch(n, params, offset, inputs, outputs)    one work-item per sample
//   mlp_backward_batch(n, params, offset, inputs, d_outputs, grad, d_inputs)
//     one work-item per sample; weight gradients through GRAD_ADD (compile with
//     -D ATOMIC_GRADIENTS when work-items share g)
// -D MLP_INPUTS, MLP_WIDTH (a multiple of 16), MLP_HIDDEN (>= 1 hidden layers).
// Weights (w points at the MLP's first float; row-major): W_in [MLP_INPUTS][MLP_WIDTH],
// b_in [MLP_WIDTH], per extra hidden layer W [MLP_WIDTH][MLP_WIDTH] and b [MLP_WIDTH], then
// W_out [MLP_WIDTH], b_out [1]; the batch kernels find them at params + offset (and the
// gradient at grad + offset). Host mirror: lib/src/model/parameter_layout.hpp.
// Needs common.cl.

#ifndef MLP_INPUTS
#error "MLP_INPUTS must be defined"
#endif
#ifndef MLP_WIDTH
#error "MLP_WIDTH must be defined"
#endif
#ifndef MLP_HIDDEN
#error "MLP_HIDDEN must be defined"
#endif
#if MLP_WIDTH % 16 != 0
#error "MLP_WIDTH must be a multiple of 16"
#endif

#define MLP_V (MLP_WIDTH / 16)
#define MLP_W_IN 0
#define MLP_B_IN (MLP_INPUTS * MLP_WIDTH)
#define MLP_W_HIDDEN(h) (MLP_B_IN + MLP_WIDTH + ((h)-1) * (MLP_WIDTH * MLP_WIDTH + MLP_WIDTH))
#define MLP_B_HIDDEN(h) (MLP_W_HIDDEN(h) + MLP_WIDTH * MLP_WIDTH)
#define MLP_W_OUT MLP_W_HIDDEN(MLP_HIDDEN)
#define MLP_B_OUT (MLP_W_OUT + MLP_WIDTH)
#define MLP_PARAMS (MLP_B_OUT + 1)

RINER_INLINE float sum16(float16 v) {
  const float8 a = v.lo + v.hi;
  const float4 b = a.lo + a.hi;
  const float2 c = b.lo + b.hi;
  return c.x + c.y;
}

// g[offset .. offset + 16) += v
RINER_INLINE void grad_add16(__global float* g, int offset, float16 v) {
#ifdef ATOMIC_GRADIENTS
  float tmp[16];
  vstore16(v, 0, tmp);
  RINER_UNROLL
  for (int k = 0; k < 16; ++k) atomic_add_global(&g[offset + k], tmp[k]);
#else
  vstore16(vload16(0, g + offset) + v, 0, g + offset);
#endif
}

// act[h][j]: post-ReLU activations of hidden layer h, kept for the backward pass.
RINER_INLINE float mlp_forward(__global const float* w, const float* in,
                               float act[MLP_HIDDEN][MLP_WIDTH]) {
  float16 h[MLP_V];
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) h[v] = vload16(v, w + MLP_B_IN);
  RINER_UNROLL
  for (int i = 0; i < MLP_INPUTS; ++i) {
    const float x = in[i];
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v)
      h[v] = mad((float16)(x), vload16(v, w + MLP_W_IN + i * MLP_WIDTH), h[v]);
  }
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) vstore16(fmax(h[v], 0.0f), v, act[0]);
  RINER_UNROLL
  for (int layer = 1; layer < MLP_HIDDEN; ++layer) {
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v) h[v] = vload16(v, w + MLP_B_HIDDEN(layer));
    RINER_UNROLL
    for (int i = 0; i < MLP_WIDTH; ++i) {
      const float x = act[layer - 1][i];
      RINER_UNROLL
      for (int v = 0; v < MLP_V; ++v) {
        h[v] = mad((float16)(x), vload16(v, w + MLP_W_HIDDEN(layer) + i * MLP_WIDTH), h[v]);
      }
    }
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v) vstore16(fmax(h[v], 0.0f), v, act[layer]);
  }
  float out = w[MLP_B_OUT];
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v)
    out += sum16(vload16(v, act[MLP_HIDDEN - 1]) * vload16(v, w + MLP_W_OUT));
  return out;
}

// Back-propagates d_out without touching any weight gradient: delta[h][j] = dloss/d(pre-
// activation j of hidden layer h) and d_in = dloss/d(input). A layer's weight gradient is the
// sum over samples of its input times its delta (mlp_gradient.cl reduces it).
RINER_INLINE void mlp_deltas(__global const float* w, const float act[MLP_HIDDEN][MLP_WIDTH],
                             float d_out, float delta[MLP_HIDDEN][MLP_WIDTH], float* d_in) {
  float16 d[MLP_V];
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) {
    d[v] = select((float16)(0.0f), d_out * vload16(v, w + MLP_W_OUT),
                  vload16(v, act[MLP_HIDDEN - 1]) > 0.0f);
    vstore16(d[v], v, delta[MLP_HIDDEN - 1]);
  }
  RINER_UNROLL
  for (int layer = MLP_HIDDEN - 1; layer >= 1; --layer) {
    float next[MLP_WIDTH];
    RINER_UNROLL
    for (int i = 0; i < MLP_WIDTH; ++i) {
      float16 acc = (float16)(0.0f);
      RINER_UNROLL
      for (int v = 0; v < MLP_V; ++v)
        acc = mad(vload16(v, w + MLP_W_HIDDEN(layer) + i * MLP_WIDTH), d[v], acc);
      next[i] = sum16(acc);
    }
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v) {
      d[v] = select((float16)(0.0f), vload16(v, next), vload16(v, act[layer - 1]) > 0.0f);
      vstore16(d[v], v, delta[layer - 1]);
    }
  }
  RINER_UNROLL
  for (int i = 0; i < MLP_INPUTS; ++i) {
    float16 acc = (float16)(0.0f);
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v) acc = mad(vload16(v, w + MLP_W_IN + i * MLP_WIDTH), d[v], acc);
    d_in[i] = sum16(acc);
  }
}

// Accumulates d_out * d(output)/d(weights) into g and writes d_out * d(output)/d(input) to
// d_in: mlp_deltas, then each layer's input times its delta.
RINER_INLINE void mlp_backward(__global const float* w, __global float* g, const float* in,
                               const float act[MLP_HIDDEN][MLP_WIDTH], float d_out, float* d_in) {
  float delta[MLP_HIDDEN][MLP_WIDTH];
  mlp_deltas(w, act, d_out, delta, d_in);
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v)
    grad_add16(g, MLP_W_OUT + 16 * v, d_out * vload16(v, act[MLP_HIDDEN - 1]));
  GRAD_ADD(&g[MLP_B_OUT], d_out);
  RINER_UNROLL
  for (int layer = MLP_HIDDEN - 1; layer >= 1; --layer) {
    RINER_UNROLL
    for (int i = 0; i < MLP_WIDTH; ++i) {
      const float below = act[layer - 1][i];
      RINER_UNROLL
      for (int v = 0; v < MLP_V; ++v)
        grad_add16(g, MLP_W_HIDDEN(layer) + i * MLP_WIDTH + 16 * v,
                   below * vload16(v, delta[layer]));
    }
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v)
      grad_add16(g, MLP_B_HIDDEN(layer) + 16 * v, vload16(v, delta[layer]));
  }
  RINER_UNROLL
  for (int i = 0; i < MLP_INPUTS; ++i) {
    RINER_UNROLL
    for (int v = 0; v < MLP_V; ++v)
      grad_add16(g, MLP_W_IN + i * MLP_WIDTH + 16 * v, in[i] * vload16(v, delta[0]));
  }
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) grad_add16(g, MLP_B_IN + 16 * v, vload16(v, delta[0]));
}

__kernel void mlp_forward_batch(const uint n, __global const float* params, const uint offset,
                                __global const float* inputs, __global float* outputs) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  __global const float* w = params + offset;
  float in[MLP_INPUTS];
  RINER_UNROLL
  for (int k = 0; k < MLP_INPUTS; ++k) in[k] = inputs[i * MLP_INPUTS + k];
  float act[MLP_HIDDEN][MLP_WIDTH];
  outputs[i] = mlp_forward(w, in, act);
}

__kernel void mlp_backward_batch(const uint n, __global const float* params, const uint offset,
                                 __global const float* inputs, __global const float* d_outputs,
                                 __global float* grad, __global float* d_inputs) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  __global const float* w = params + offset;
  __global float* g = grad + offset;
  float in[MLP_INPUTS];
  RINER_UNROLL
  for (int k = 0; k < MLP_INPUTS; ++k) in[k] = inputs[i * MLP_INPUTS + k];
  float act[MLP_HIDDEN][MLP_WIDTH];
  mlp_forward(w, in, act);
  float d_in[MLP_INPUTS];
  mlp_backward(w, g, in, act, d_outputs[i], d_in);
  RINER_UNROLL
  for (int k = 0; k < MLP_INPUTS; ++k) d_inputs[i * MLP_INPUTS + k] = d_in[k];
}
