#include "reference/ray_sum_ref.hpp"

#include <algorithm>
#include <cmath>

namespace riner::ref {

namespace {

bool is_bound(double rho) { return std::isinf(rho) && rho > 0.0; }

double target(double rho, double floor) {
  return is_bound(rho) ? floor : (std::isfinite(rho) ? rho : 0.0);
}

}  // namespace

RayLoss ray_loss(double ray_sum, double alpha0, double beta0, double rho, double weight,
                 double floor) {
  const bool bound = is_bound(rho);
  rho = target(rho, floor);
  const bool clamped = !(alpha0 > kAlphaEpsilon);
  const double alpha = clamped ? kAlphaEpsilon : alpha0;
  const double beta = 1.0 / (1.0 + std::exp(-beta0));
  const double inside = -std::log(alpha) + ray_sum;
  RayLoss out;
  out.rho_hat = inside * beta;
  const double residual = bound ? std::min(beta * (inside - rho), 0.0) : beta * (inside - rho);
  out.loss = weight * std::fabs(residual);
  const double sign = residual > 0.0 ? 1.0 : (residual < 0.0 ? -1.0 : 0.0);
  const double g = weight * sign;  // dloss / d residual
  out.d_sum = g * beta;
  out.d_alpha0 = clamped ? 0.0 : -g * beta / alpha;
  out.d_beta0 = g * (inside - rho) * beta * (1.0 - beta);
  return out;
}

double ray_mismatch(double ray_sum, double alpha0, double rho, double floor) {
  const double d =
      -std::log(alpha0 > kAlphaEpsilon ? alpha0 : kAlphaEpsilon) + ray_sum - target(rho, floor);
  return is_bound(rho) ? std::max(-d, 0.0) : std::fabs(d);
}

double beta_penalty(double beta0, double lambda, double* d_beta0) {
  const double beta = 1.0 / (1.0 + std::exp(-beta0));
  if (d_beta0 != nullptr) *d_beta0 = -2.0 * lambda * beta * beta * (1.0 - beta);
  return -lambda * beta * beta;
}

}  // namespace riner::ref
