#include "reference/mlp_ref.hpp"

#include <algorithm>

namespace riner::ref {

namespace {

// y = relu(W^T x + b) with W [rows][cols] row-major.
void dense_relu(const double* w, const double* b, const double* x, int rows, int cols, double* y) {
  for (int j = 0; j < cols; ++j) y[j] = b[j];
  for (int i = 0; i < rows; ++i) {
    const double xi = x[i];
    for (int j = 0; j < cols; ++j) y[j] += xi * w[static_cast<std::size_t>(i) * cols + j];
  }
  for (int j = 0; j < cols; ++j) y[j] = std::max(0.0, y[j]);
}

}  // namespace

double mlp_forward(const model::ParameterLayout& l, const double* p, const double* input,
                   MlpTrace* trace) {
  std::vector<std::vector<double>> hidden(static_cast<std::size_t>(l.hidden_layers),
                                          std::vector<double>(static_cast<std::size_t>(l.width)));
  dense_relu(p + l.w_in(), p + l.b_in(), input, l.inputs, l.width, hidden[0].data());
  for (int h = 1; h < l.hidden_layers; ++h) {
    dense_relu(p + l.w_hidden(h), p + l.b_hidden(h), hidden[h - 1].data(), l.width, l.width,
               hidden[h].data());
  }
  double out = p[l.b_out()];
  const std::vector<double>& last = hidden.back();
  for (int j = 0; j < l.width; ++j) out += p[l.w_out() + j] * last[static_cast<std::size_t>(j)];
  if (trace != nullptr) {
    trace->hidden = std::move(hidden);
    trace->output = out;
  }
  return out;
}

void mlp_backward(const model::ParameterLayout& l, const double* p, const double* input,
                  const MlpTrace& trace, double d_output, double* grad, double* d_input) {
  const int w = l.width;
  std::vector<double> delta(static_cast<std::size_t>(w));
  const std::vector<double>& last = trace.hidden.back();
  for (int j = 0; j < w; ++j) {
    grad[l.w_out() + j] += d_output * last[static_cast<std::size_t>(j)];
    // Through the ReLU: zero where the unit was off.
    delta[static_cast<std::size_t>(j)] =
        last[static_cast<std::size_t>(j)] > 0.0 ? d_output * p[l.w_out() + j] : 0.0;
  }
  grad[l.b_out()] += d_output;
  for (int h = l.hidden_layers - 1; h >= 1; --h) {
    const std::vector<double>& below = trace.hidden[static_cast<std::size_t>(h - 1)];
    std::vector<double> next(static_cast<std::size_t>(w), 0.0);
    for (int i = 0; i < w; ++i) {
      for (int j = 0; j < w; ++j) {
        grad[l.w_hidden(h) + static_cast<std::size_t>(i) * w + j] +=
            below[static_cast<std::size_t>(i)] * delta[static_cast<std::size_t>(j)];
        next[static_cast<std::size_t>(i)] +=
            p[l.w_hidden(h) + static_cast<std::size_t>(i) * w + j] *
            delta[static_cast<std::size_t>(j)];
      }
    }
    for (int j = 0; j < w; ++j) grad[l.b_hidden(h) + j] += delta[static_cast<std::size_t>(j)];
    for (int i = 0; i < w; ++i) {
      delta[static_cast<std::size_t>(i)] =
          below[static_cast<std::size_t>(i)] > 0.0 ? next[static_cast<std::size_t>(i)] : 0.0;
    }
  }
  for (int i = 0; i < l.inputs; ++i) {
    double s = 0.0;
    for (int j = 0; j < w; ++j) {
      grad[l.w_in() + static_cast<std::size_t>(i) * w + j] +=
          input[i] * delta[static_cast<std::size_t>(j)];
      s += p[l.w_in() + static_cast<std::size_t>(i) * w + j] * delta[static_cast<std::size_t>(j)];
    }
    if (d_input != nullptr) d_input[i] = s;
  }
  for (int j = 0; j < w; ++j) grad[l.b_in() + j] += delta[static_cast<std::size_t>(j)];
}

std::vector<float> mlp_forward_batch(const model::ParameterLayout& l,
                                     const std::vector<float>& params,
                                     const std::vector<float>& inputs) {
  const std::vector<double> p(params.begin(), params.end());
  const std::size_t n = inputs.size() / static_cast<std::size_t>(l.inputs);
  std::vector<float> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<double> x(inputs.begin() + static_cast<long>(i * l.inputs),
                                inputs.begin() + static_cast<long>((i + 1) * l.inputs));
    out[i] = static_cast<float>(mlp_forward(l, p.data(), x.data()));
  }
  return out;
}

std::vector<double> mlp_backward_batch(const model::ParameterLayout& l,
                                       const std::vector<float>& params,
                                       const std::vector<float>& inputs,
                                       const std::vector<float>& d_out,
                                       std::vector<double>* d_inputs) {
  const std::vector<double> p(params.begin(), params.end());
  const std::size_t n = d_out.size();
  std::vector<double> grad(l.total, 0.0);
  if (d_inputs != nullptr) d_inputs->assign(n * static_cast<std::size_t>(l.inputs), 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<double> x(inputs.begin() + static_cast<long>(i * l.inputs),
                                inputs.begin() + static_cast<long>((i + 1) * l.inputs));
    MlpTrace trace;
    mlp_forward(l, p.data(), x.data(), &trace);
    mlp_backward(l, p.data(), x.data(), trace, d_out[i], grad.data(),
                 d_inputs != nullptr ? d_inputs->data() + i * l.inputs : nullptr);
  }
  return grad;
}

}  // namespace riner::ref
