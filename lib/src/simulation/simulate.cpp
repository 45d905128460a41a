#include "riner/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "riner/error.hpp"
#include "riner/log.hpp"
#include "simulation/random.hpp"

namespace riner {

namespace {

// The most incident photons a simulation draws (RingModel::validate).
constexpr double kMostPhotons = 1e15;

// Independent streams for responses and noise, both derived from the user's seed (splitmix64).
std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + stream * 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The first k entries of a uniformly random permutation of `pool` (partial Fisher-Yates).
std::vector<std::size_t> choose(std::vector<std::size_t> pool, std::size_t k, sim::Random& rng) {
  k = std::min(k, pool.size());
  for (std::size_t i = 0; i < k; ++i) {
    const std::size_t j = i + static_cast<std::size_t>(rng.below(pool.size() - i));
    std::swap(pool[i], pool[j]);
  }
  pool.resize(k);
  return pool;
}

std::vector<std::size_t> iota(std::size_t n) {
  std::vector<std::size_t> v(n);
  std::iota(v.begin(), v.end(), std::size_t{0});
  return v;
}

// A response for an element that changes part-way: U[alpha_min, alpha_max], redrawn until it
// is at least kPartialChange (in log) from the old one.
constexpr double kPartialChange = 0.15;

double changed_response(double old, const RingModel& model, sim::Random& rng) {
  for (int attempt = 0; attempt < 64; ++attempt) {
    const double a = model.alpha_min + (model.alpha_max - model.alpha_min) * rng.uniform();
    if (std::fabs(std::log(a / old)) >= kPartialChange) return a;
  }
  return old * std::exp(old < std::sqrt(model.alpha_min * model.alpha_max) ? kPartialChange
                                                                           : -kPartialChange);
}

// Per-element responses `alpha` ([n_u], [n_v, n_u] in 3D) made per view ([n_views, n_u],
// [n_views, n_v, n_u]): partial elements change from a view in the middle three fifths of the
// scan on.
Array with_partial_responses(const Array& alpha, const Geometry& g, const RingModel& model,
                             const std::vector<std::size_t>& live, sim::Random& rng) {
  const std::size_t views = g.n_views();
  const std::size_t n = alpha.size();
  if (model.partial_elements + model.partial_dead_elements > live.size()) {
    throw InputError("more partial elements than live detector elements");
  }
  Array out(g.is_3d() ? std::vector<std::size_t>{views, g.n_v, g.n_u}
                      : std::vector<std::size_t>{views, g.n_u});
  for (std::size_t v = 0; v < views; ++v) {
    std::copy(alpha.data.begin(), alpha.data.end(),
              out.data.begin() + static_cast<std::ptrdiff_t>(v * n));
  }
  const std::vector<std::size_t> chosen =
      choose(live, model.partial_elements + model.partial_dead_elements, rng);
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const std::size_t e = chosen[i];
    const auto from = static_cast<std::size_t>(
        std::floor(static_cast<double>(views) * (0.2 + 0.6 * rng.uniform())));
    const double after =
        i < model.partial_elements ? changed_response(alpha.data[e], model, rng) : 0.0;
    for (std::size_t v = from; v < views; ++v) out.data[v * n + e] = static_cast<float>(after);
  }
  return out;
}

}  // namespace

void RingModel::validate() const {
  if (!(nonideal_fraction >= 0.0 && nonideal_fraction <= 1.0)) {
    throw InputError("the non-ideal fraction must be in [0, 1]");
  }
  if (!(alpha_min > 0.0) || !(alpha_max >= alpha_min) || !std::isfinite(alpha_max)) {
    throw InputError("the response range must satisfy 0 < alpha_min <= alpha_max");
  }
  // The counts are drawn as 64-bit integers: at 1e20 they overflowed and nearly every reading
  // came out infinite. Beyond 1e15 the noise is far below float's precision anyway.
  if (!(photons >= 0.0) || !(photons <= kMostPhotons)) {
    throw InputError("photons must be 0 (no noise) to 1e15");
  }
}

std::vector<std::size_t> dead_in_every_view(const Array& alpha, std::size_t elements) {
  std::vector<std::size_t> dead;
  for (std::size_t e = 0; e < elements; ++e) {
    bool all = true;
    for (std::size_t i = e; i < alpha.size() && all; i += elements) all = alpha.data[i] == 0.0f;
    if (all) dead.push_back(e);
  }
  return dead;
}

std::vector<std::size_t> dead_part_way(const Array& alpha, std::size_t elements) {
  std::vector<std::size_t> out;
  for (std::size_t e = 0; e < elements; ++e) {
    std::size_t zeros = 0;
    std::size_t views = 0;
    for (std::size_t i = e; i < alpha.size(); i += elements, ++views)
      zeros += alpha.data[i] == 0.0f;
    if (zeros > 0 && zeros < views) out.push_back(e);
  }
  return out;
}

std::vector<std::size_t> response_change_views(const Array& alpha, const Geometry& g,
                                               std::size_t e) {
  std::vector<std::size_t> views;
  const std::size_t elements = g.n_u * (g.is_3d() ? g.n_v : 1);
  if (alpha.size() != g.n_views() * elements) return views;
  for (std::size_t v = 1; v < g.n_views(); ++v) {
    if (alpha.data[v * elements + e] != alpha.data[(v - 1) * elements + e]) views.push_back(v);
  }
  return views;
}

Array draw_responses(const Geometry& g, const RingModel& model) {
  model.validate();
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t n = rows * g.n_u;
  if (!g.is_3d() && (model.dead_rows > 0 || model.dead_columns > 0)) {
    throw InputError("dead rows and columns need a 3D detector");
  }
  if (!g.is_3d() && model.pattern == ResponsePattern::kRowsTimesColumns) {
    throw InputError("responses by rows x columns need a 3D detector");
  }
  if (model.partial_elements + model.partial_dead_elements > 0 &&
      model.pattern == ResponsePattern::kRowsTimesColumns) {
    throw InputError("responses that change part-way are per element, not by rows x columns");
  }
  if (model.dead_rows > rows || model.dead_columns > g.n_u || model.dead_elements > n) {
    throw InputError("more dead rows, columns or elements than the detector has");
  }
  sim::Random rng(stream_seed(model.seed, 1));
  if (model.dead_rows == rows || model.dead_columns == g.n_u || model.dead_elements == n) {
    throw InputError("every detector element would be dead: the scan would measure nothing");
  }
  std::vector<char> dead(n, 0);
  for (std::size_t r : choose(iota(rows), model.dead_rows, rng)) {
    for (std::size_t u = 0; u < g.n_u; ++u) dead[r * g.n_u + u] = 1;
  }
  for (std::size_t u : choose(iota(g.n_u), model.dead_columns, rng)) {
    for (std::size_t r = 0; r < rows; ++r) dead[r * g.n_u + u] = 1;
  }
  std::vector<std::size_t> live;
  for (std::size_t e = 0; e < n; ++e) {
    if (!dead[e]) live.push_back(e);
  }
  for (std::size_t e : choose(live, model.dead_elements, rng)) dead[e] = 1;
  live.clear();
  for (std::size_t e = 0; e < n; ++e) {
    if (!dead[e]) live.push_back(e);
  }
  Array alpha(g.is_3d() ? std::vector<std::size_t>{rows, g.n_u} : std::vector<std::size_t>{g.n_u},
              1.0f);
  for (std::size_t e = 0; e < n; ++e) {
    if (dead[e]) alpha.data[e] = 0.0f;
  }
  if (model.pattern == ResponsePattern::kRowsTimesColumns) {
    const double low = std::sqrt(model.alpha_min);
    const double high = std::sqrt(model.alpha_max);
    auto factors = [&](std::size_t count) {
      std::vector<double> f(count, 1.0);
      const auto nonideal = static_cast<std::size_t>(std::llround(model.nonideal_fraction * count));
      for (std::size_t i : choose(iota(count), nonideal, rng)) {
        f[i] = low + (high - low) * rng.uniform();
      }
      return f;
    };
    const std::vector<double> row = factors(rows);
    const std::vector<double> column = factors(g.n_u);
    for (std::size_t e : live)
      alpha.data[e] = static_cast<float>(row[e / g.n_u] * column[e % g.n_u]);
    return alpha;
  }
  const auto nonideal = static_cast<std::size_t>(std::llround(model.nonideal_fraction * n));
  for (std::size_t e : choose(live, nonideal, rng)) {
    alpha.data[e] =
        static_cast<float>(model.alpha_min + (model.alpha_max - model.alpha_min) * rng.uniform());
  }
  if (model.partial_elements + model.partial_dead_elements == 0) return alpha;
  return with_partial_responses(alpha, g, model, live, rng);
}

Array corrupt_measurement(const Array& clean, const Array& alpha, const RingModel& model) {
  model.validate();
  if (alpha.size() == 0 || clean.size() % alpha.size() != 0) {
    throw InputError("the response map does not match the measurement's detector");
  }
  // The mistake this catches is an image in 1/cm read as 1/mm (DeepLesion without mu_unit):
  // said by the library, so the CLI and Python both say it.
  if (model.photons > 0.0) {
    const double longest = compute_stats(clean).max;
    if (longest > std::log(model.photons / 10.0)) {
      warn("the longest ray leaves fewer than 10 photons (line integral " +
           std::to_string(longest) + "): is the image's unit right (mu in 1/mm; --mu-unit cm)?");
    }
  }
  sim::Random rng(stream_seed(model.seed, 2));
  Array out(clean.shape);
  // Per element (repeated for every view) or per view and element.
  const std::size_t per_view = alpha.size();
  for (std::size_t r = 0; r < clean.size(); ++r) {
    const double p = clean.data[r];
    if (!std::isfinite(p)) throw InputError("clean projections must be finite");
    const double a = alpha.data[r % per_view];
    double rho;
    if (model.photons == 0.0) {
      rho = a > 0.0 ? p - std::log(a) : INFINITY;
    } else {
      const std::uint64_t counts = rng.poisson(a * model.photons * std::exp(-p));
      rho = counts > 0 ? -std::log(static_cast<double>(counts) / model.photons) : INFINITY;
    }
    out.data[r] = static_cast<float>(rho);
  }
  return out;
}

SimulatedScan simulate(const Array& ground_truth, const Projector& projector,
                       const RingModel& model) {
  SimulatedScan sim;
  sim.ground_truth = ground_truth;
  sim.clean = projector.project(ground_truth);
  sim.alpha = draw_responses(projector.geometry(), model);
  sim.scan.geometry = projector.geometry();
  sim.scan.measurement = corrupt_measurement(sim.clean, sim.alpha, model);
  sim.scan.non_finite = compute_stats(sim.scan.measurement).non_finite();
  return sim;
}

bool is_preset_geometry(std::string_view name) {
  return name == "fan2d-paper" || name == "cone3d-paper" || name == "parallel3d";
}

Geometry preset_geometry(std::string_view name) {
  Geometry g;
  UniformAngles angles{360, 0.0, 2.0 * M_PI};
  if (name == "fan2d-paper") {
    g.type = GeometryType::kFan2d;
    g.n_u = 500;
    g.pitch_u = 2.0;
    g.source_origin_mm = 370.0;
    g.origin_detector_mm = 370.0;
    g.volume_shape = {256, 256};
  } else if (name == "cone3d-paper") {
    g.type = GeometryType::kCone3d;
    g.n_u = 300;
    g.n_v = 200;
    g.pitch_u = 2.0;
    g.pitch_v = 2.0;
    g.source_origin_mm = 300.0;
    g.origin_detector_mm = 300.0;
    g.volume_shape = {100, 256, 256};
  } else if (name == "parallel3d") {
    // The cone preset's volume in a synchrotron's parallel beam: 360 views over 180 degrees, a
    // 1 mm detector wide enough for the grid's diagonal (362 mm).
    g.type = GeometryType::kParallel3d;
    g.n_u = 384;
    g.n_v = 100;
    g.pitch_u = 1.0;
    g.pitch_v = 1.0;
    g.volume_shape = {100, 256, 256};
    angles = {360, 0.0, M_PI};
  } else {
    throw InputError("unknown preset geometry \"" + std::string(name) +
                     "\" (presets: fan2d-paper, cone3d-paper, parallel3d)");
  }
  g.voxel_mm = 1.0;
  g.uniform_angles = angles;
  g.angles = uniform_angles(angles);
  g.validate();
  return g;
}

}  // namespace riner
