#include "model/broad_even_hold.hpp"

#include <algorithm>
#include <cmath>

#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "rings/radial.hpp"

namespace riner::model {

BroadEvenHold::BroadEvenHold(const Geometry& g, double sigma_px, std::span<const float> initial) {
  if (g.is_3d()) throw InputError("alpha's broad even hold: a 2D geometry only");
  if (!(sigma_px > 0.0)) throw InputError("alpha's broad even hold: sigma must be positive");
  if (initial.size() != g.n_u) throw Error("alpha's broad even hold: one initial alpha per element");
  const std::vector<double> distance = column_ray_distances(g);
  const auto [lowest, highest] = std::minmax_element(distance.begin(), distance.end());
  const double sigma = sigma_px * g.voxel_mm;
  rows_.resize(distance.size());
  std::vector<double> row(distance.size(), 0.0);
  // Normalised Gaussian weights at x, scaled by `share`, into the row being built.
  const auto add = [&](double x, double share) {
    const auto weights = rings::gaussian_weights_at(distance, x, sigma);
    double sum = 0.0;
    for (const auto& [f, w] : weights) sum += w;
    for (const auto& [f, w] : weights) row[f] += share * w / sum;
  };
  for (std::size_t e = 0; e < distance.size(); ++e) {
    const double mirror = -distance[e];
    const bool paired = mirror >= *lowest && mirror <= *highest;
    add(distance[e], paired ? 0.5 : 1.0);
    if (paired) add(mirror, 0.5);
    for (std::size_t f = 0; f < row.size(); ++f) {
      if (row[f] == 0.0) continue;
      rows_[e].push_back({f, row[f]});
      row[f] = 0.0;
    }
  }
  log_initial_.resize(initial.size());
  for (std::size_t e = 0; e < initial.size(); ++e)
    log_initial_[e] = std::log(std::max(initial[e], 1e-8f));
}

std::vector<double> BroadEvenHold::broad_even(std::span<const double> values) const {
  std::vector<double> out(rows_.size(), 0.0);
  for (std::size_t e = 0; e < rows_.size(); ++e) {
    for (const Weight& w : rows_[e]) out[e] += w.weight * values[w.element];
  }
  return out;
}

template <typename T>
void BroadEvenHold::remove_broad_even(std::span<T> alpha) const {
  if (alpha.size() != rows_.size()) throw Error("alpha's broad even hold: one alpha per element");
  std::vector<double> change(alpha.size());
  for (std::size_t e = 0; e < alpha.size(); ++e)
    change[e] = std::log(std::max<double>(alpha[e], 1e-8)) - log_initial_[e];
  const std::vector<double> broad = broad_even(change);
  for (std::size_t e = 0; e < alpha.size(); ++e)
    alpha[e] = static_cast<T>(alpha[e] * std::exp(-broad[e]));
}

void BroadEvenHold::apply(std::span<float> alpha) const { remove_broad_even(alpha); }
void BroadEvenHold::apply(std::span<double> alpha) const { remove_broad_even(alpha); }

}  // namespace riner::model
