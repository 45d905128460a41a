// ray_sum.cl: the forward model of a ray and its loss (METHOD.md section 2):
//   rho_hat = (-ln alpha + sum(mu) dx) beta,  alpha = max(alpha0, 1e-8),  beta = sigmoid(beta0)
//   loss = weight |rho_hat - rho beta|, a non-finite measured rho counting as 0, but +inf (a
//   beam the object stopped: model/starved_readings.hpp) a bound: rho >= floor, a
//   loss only while rho_hat < floor beta;
//   penalty = lambda (-beta^2) per element of the batch.
//   Helpers: ray_loss(...), ray_mismatch(...), beta_penalty(...)
//   ray_sum_loss(n_rays, offsets, mu, dx, elements, rho, alpha0, beta0, weight, floor, d_mu,
//                loss, d_alpha0, d_beta0)
//     one work-item per ray r, whose samples are mu[offsets[r] .. offsets[r + 1]); writes
//     d_mu = dloss/dmu per sample, the ray's loss, and adds its alpha0/beta0 gradients with
//     GRAD_ADD (compile with -D ATOMIC_GRADIENTS when rays share elements).
// Needs common.cl. No -D constants of its own. CPU twin: lib/src/reference/ray_sum_ref.cpp.

#define ALPHA_EPSILON 1e-8f

// A reading of +inf: a bound (model/starved_readings.hpp).
RINER_INLINE int is_bound(float rho) { return isinf(rho) && rho > 0.0f; }

// The reading a ray is compared with: a bound's floor, 0 for another non-finite reading.
RINER_INLINE float ray_target(float rho, float floor) {
  return is_bound(rho) ? floor : (isfinite(rho) ? rho : 0.0f);
}

// Returns the ray's loss; writes the gradients with respect to the ray sum, alpha0, beta0.
RINER_INLINE float ray_loss(float ray_sum, float alpha0, float beta0, float rho, float weight,
                            float floor, float* d_sum, float* d_alpha0, float* d_beta0) {
  const int bound = is_bound(rho);
  rho = ray_target(rho, floor);
  const int clamped = !(alpha0 > ALPHA_EPSILON);
  const float alpha = clamped ? ALPHA_EPSILON : alpha0;
  const float beta = 1.0f / (1.0f + exp(-beta0));
  const float inside = -log(alpha) + ray_sum;
  const float residual = bound ? fmin(beta * (inside - rho), 0.0f) : beta * (inside - rho);
  const float g = weight * (residual > 0.0f ? 1.0f : (residual < 0.0f ? -1.0f : 0.0f));
  *d_sum = g * beta;
  *d_alpha0 = clamped ? 0.0f : -g * beta / alpha;
  *d_beta0 = g * (inside - rho) * beta * (1.0f - beta);
  return weight * fabs(residual);
}

// |(-ln alpha + ray_sum) - rho|: how far a ray is from its measurement, before beta (from a
// bound's floor only below it).
RINER_INLINE float ray_mismatch(float ray_sum, float alpha0, float rho, float floor) {
  const float d = -log(fmax(alpha0, ALPHA_EPSILON)) + ray_sum - ray_target(rho, floor);
  return is_bound(rho) ? fmax(-d, 0.0f) : fabs(d);
}

RINER_INLINE float beta_penalty(float beta0, float lambda, float* d_beta0) {
  const float beta = 1.0f / (1.0f + exp(-beta0));
  *d_beta0 = -2.0f * lambda * beta * beta * (1.0f - beta);
  return -lambda * beta * beta;
}

__kernel void ray_sum_loss(const uint n_rays, __global const uint* offsets,
                           __global const float* mu, __global const float* dx,
                           __global const uint* elements, __global const float* rho,
                           __global const float* alpha0, __global const float* beta0,
                           const float weight, const float floor, __global float* d_mu,
                           __global float* loss, __global float* d_alpha0,
                           __global float* d_beta0) {
  const uint r = get_global_id(0);
  if (r >= n_rays) return;
  float sum = 0.0f;
  for (uint k = offsets[r]; k < offsets[r + 1]; ++k) sum += mu[k];
  const uint e = elements[r];
  float d_sum;
  float g_alpha0;
  float g_beta0;
  loss[r] = ray_loss(sum * dx[r], alpha0[e], beta0[e], rho[r], weight, floor, &d_sum, &g_alpha0,
                     &g_beta0);
  for (uint k = offsets[r]; k < offsets[r + 1]; ++k) d_mu[k] = d_sum * dx[r];
  GRAD_ADD(&d_alpha0[e], g_alpha0);
  GRAD_ADD(&d_beta0[e], g_beta0);
}
