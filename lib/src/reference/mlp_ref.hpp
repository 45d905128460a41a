// CPU twin of kernels/mlp.cl, in double: input -> [width, ReLU] x hidden_layers -> 1 (linear).
#pragma once

#include <vector>

#include "model/parameter_layout.hpp"

namespace riner::ref {

// Activations of one evaluation, kept for the backward pass.
struct MlpTrace {
  std::vector<std::vector<double>> hidden;  // post-ReLU, one vector per hidden layer
  double output = 0.0;
};

double mlp_forward(const model::ParameterLayout& l, const double* params, const double* input,
                   MlpTrace* trace = nullptr);

// Accumulates d_output * d(output)/d(weights) into grad and writes d(output)/d(input) * d_output
// into d_input (inputs values).
void mlp_backward(const model::ParameterLayout& l, const double* params, const double* input,
                  const MlpTrace& trace, double d_output, double* grad, double* d_input);

// Batched, fp32 at the boundary: outputs [n] from inputs [n][inputs].
std::vector<float> mlp_forward_batch(const model::ParameterLayout& l,
                                     const std::vector<float>& params,
                                     const std::vector<float>& inputs);
// Gradient over all parameters of sum(d_out * out), and d_inputs [n][inputs].
std::vector<double> mlp_backward_batch(const model::ParameterLayout& l,
                                       const std::vector<float>& params,
                                       const std::vector<float>& inputs,
                                       const std::vector<float>& d_out,
                                       std::vector<double>* d_inputs);

}  // namespace riner::ref
