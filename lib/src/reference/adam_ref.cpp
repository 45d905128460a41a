#include "reference/adam_ref.hpp"

#include <cmath>

namespace riner::ref {

void adam_step(const AdamSettings& s, int step, const std::vector<double>& grad,
               std::vector<double>& params, std::vector<double>& m, std::vector<double>& v) {
  const double bias1 = 1.0 - std::pow(s.beta1, step);
  const double bias2 = 1.0 - std::pow(s.beta2, step);
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (i < s.sparse_below && grad[i] == 0.0) continue;
    m[i] = s.beta1 * m[i] + (1.0 - s.beta1) * grad[i];
    v[i] = s.beta2 * v[i] + (1.0 - s.beta2) * grad[i] * grad[i];
    const double denom = std::sqrt(v[i]) / std::sqrt(bias2) + s.epsilon;
    const double lr = i < s.alpha_offset  ? s.learning_rate
                      : i < s.beta_offset ? s.alpha_learning_rate
                                          : s.beta_learning_rate;
    params[i] -= lr / bias1 * m[i] / denom;
  }
}

}  // namespace riner::ref
