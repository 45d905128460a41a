// CPU twin of kernels/ray_sum.cl: the forward model of one ray and its loss (METHOD.md §2),
//   rho_hat = (-ln alpha + sum(mu) dx) beta,  alpha = max(alpha0, eps),  beta = sigmoid(beta0),
//   loss = weight |rho_hat - rho beta|,
// with a non-finite measured rho taken as 0 (its element's beta then learns to switch it off),
// but +inf a bound rho >= floor (model/starved_readings.hpp): a loss only below it.
#pragma once

namespace riner::ref {

constexpr double kAlphaEpsilon = 1e-8;

struct RayLoss {
  double rho_hat = 0.0;
  double loss = 0.0;
  double d_sum = 0.0;  // dloss / d(sum(mu) dx)
  double d_alpha0 = 0.0;
  double d_beta0 = 0.0;
};

RayLoss ray_loss(double ray_sum, double alpha0, double beta0, double rho, double weight,
                 double floor);

// |(-ln alpha + ray_sum) - rho| with rho's non-finite values taken as 0 and +inf as the floor
// (a mismatch only below it): a ray's mismatch before beta.
double ray_mismatch(double ray_sum, double alpha0, double rho, double floor);

// The regulariser of one element, lambda * (-beta^2), and its gradient in beta0.
double beta_penalty(double beta0, double lambda, double* d_beta0);

}  // namespace riner::ref
