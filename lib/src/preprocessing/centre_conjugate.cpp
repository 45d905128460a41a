#include "preprocessing/centre_conjugate.hpp"
#include "preprocessing/mismatch_sums.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "riner/centre.hpp"
#include "riner/rays.hpp"

namespace riner::preprocessing {

namespace {

// At most this many views and elements enter the cost (evenly spread): enough rays, a cost of
// a few milliseconds per offset; the coarse search takes a sixth of them.
struct RaySample {
  std::size_t views = 180;
  std::size_t elements = 512;
};
constexpr RaySample kFine{};
constexpr RaySample kCoarse{60, 256};
// The half-acquisition search beyond the detector's central half: a wide range, fewer rays.
constexpr RaySample kOuter{30, 128};

// The reading at fractional element u of a view, linear between elements; NaN off the detector
// or next to a non-finite reading.
double reading_at(const Array& rho, std::size_t view, double u, std::size_t n_u) {
  if (!(u >= 0.0) || u > static_cast<double>(n_u - 1))
    return std::numeric_limits<double>::quiet_NaN();
  const auto e = std::min(static_cast<std::size_t>(u), n_u - 2);
  const double w = u - static_cast<double>(e);
  const float* row = rho.ptr() + view * n_u;
  return (1.0 - w) * row[e] + w * row[e + 1];
}

struct Turn {
  double first = 0.0;     // the first view's source angle (rad)
  double step = 0.0;      // between views, signed
  std::size_t views = 0;  // views in a full turn (the scan may hold one more, the turn's end)
};

// The sources' angles about the axis, checked to step evenly over at least a full turn less
// two steps.
std::optional<Turn> full_turn(const Geometry& g) {
  const std::size_t n = g.n_views();
  if (n < 8) return std::nullopt;
  std::vector<double> angle(n);
  for (std::size_t v = 0; v < n; ++v) {
    const Vec3 s = detector_ray(g, v, 0.0).origin;
    angle[v] = std::atan2(s.y, s.x);
    if (v > 0) {  // unwrap
      while (angle[v] - angle[v - 1] > M_PI) angle[v] -= 2.0 * M_PI;
      while (angle[v] - angle[v - 1] < -M_PI) angle[v] += 2.0 * M_PI;
    }
  }
  Turn t;
  t.first = angle[0];
  t.step = (angle[n - 1] - angle[0]) / static_cast<double>(n - 1);
  if (t.step == 0.0) return std::nullopt;
  for (std::size_t v = 1; v < n; ++v) {
    if (std::fabs(angle[v] - angle[v - 1] - t.step) > 0.1 * std::fabs(t.step)) return std::nullopt;
  }
  const double per_turn = 2.0 * M_PI / std::fabs(t.step);
  if (static_cast<double>(n) < per_turn - 2.0) return std::nullopt;
  t.views = static_cast<std::size_t>(std::lround(per_turn));
  if (t.views > n) t.views = n;
  return t;
}

struct Cost {
  double mean = std::numeric_limits<double>::infinity();
  std::size_t rays = 0;
  double relative = std::numeric_limits<double>::infinity();  // MismatchSums::relative
};

Cost conjugate_cost(const Geometry& geometry, const Array& rho, const Turn& turn, double offset_px,
                    RaySample sample) {
  Geometry g = geometry;
  g.offset_u = offset_px;
  const std::size_t n_u = g.n_u;
  const std::size_t view_step = std::max<std::size_t>(1, turn.views / sample.views);
  const std::size_t element_step = std::max<std::size_t>(1, n_u / sample.elements);
  MismatchSums sums;
  for (std::size_t v = 0; v < turn.views; v += view_step) {
    for (std::size_t e = 0; e < n_u; e += element_step) {
      const double here = rho.data[v * n_u + e];
      if (!std::isfinite(here)) continue;
      const Ray ray = detector_ray(g, v, static_cast<double>(e));
      const Vec3& s = ray.origin;
      const Vec3& d = ray.direction;
      const double along = s.x * d.x + s.y * d.y;
      // Where the line leaves the source circle (a source half a turn on), and its point
      // nearest the axis.
      const double px = s.x - 2.0 * along * d.x, py = s.y - 2.0 * along * d.y;
      const Vec3 nearest{s.x - along * d.x, s.y - along * d.y, 0.0};
      double f = (std::atan2(py, px) - turn.first) / turn.step;
      const auto n = static_cast<double>(turn.views);
      f = std::fmod(f, n);
      if (f < 0.0) f += n;
      const auto v0 = static_cast<std::size_t>(f) % turn.views;
      const std::size_t v1 = (v0 + 1) % turn.views;
      const double w = f - std::floor(f);
      const double a = reading_at(rho, v0, project_to_detector(g, v0, nearest).u, n_u);
      const double b = reading_at(rho, v1, project_to_detector(g, v1, nearest).u, n_u);
      const double there = (1.0 - w) * a + w * b;
      if (!std::isfinite(there)) continue;
      sums.add(here, there);
    }
  }
  return {sums.mean(), sums.pairs, sums.relative()};
}

Cost conjugate_cost(const Scan& scan, const Turn& turn, double offset_px, RaySample sample) {
  return conjugate_cost(scan.geometry, scan.measurement, turn, offset_px, sample);
}

// The offset within 2 px of `around`, every pixel, with the least relative cost, and that cost
// (the axis is checked on its own: a distance wrong by 10% moves it by a few hundredths).
std::pair<double, double> least_cost_near(const Geometry& g, const Array& rho, const Turn& turn,
                                          double around, RaySample sample) {
  std::pair<double, double> best{around, std::numeric_limits<double>::infinity()};
  for (double o = around - 2.0; o <= around + 2.0; o += 1.0) {
    const double cost = conjugate_cost(g, rho, turn, o, sample).relative;
    if (cost < best.second) best = {o, cost};
  }
  return best;
}

// The offsets a half acquisition's axis can have: beyond the detector's central half
// (kCentreSearchShare either way), up to where a ray's conjugate still lands on the detector
// for a twentieth of its elements (16 at least) around the axis. Every 2 px on 30 views by 128
// elements by the relative cost (4 px missed a 64-element detector's axis); the best and that
// cost.
double farthest_outer_offset(std::size_t n_u) {
  const double n = static_cast<double>(n_u);
  return 0.5 * (n - 1.0) - 0.5 * std::max(16.0, n / 20.0);
}

std::optional<std::pair<double, double>> outer_offset(const Scan& scan, const Turn& turn) {
  const Geometry& g = scan.geometry;
  const double n = static_cast<double>(g.n_u);
  const double inner = kCentreSearchShare * n, outer = farthest_outer_offset(g.n_u);
  constexpr double kCoarseStep = 2.0;
  std::optional<std::pair<double, double>> best;
  for (double magnitude = inner; magnitude <= outer; magnitude += kCoarseStep) {
    for (const double offset : {magnitude, -magnitude}) {
      const Cost cost = conjugate_cost(scan, turn, offset, kOuter);
      if (std::isfinite(cost.relative) && (!best || cost.relative < best->second)) {
        best = std::pair{offset, cost.relative};
      }
    }
  }
  return best;
}

// The half-pixel search moves on from its end at most this many times (5 px each).
constexpr int kMostFineMoves = 8;

// An outer offset is taken over the search around the geometry's only where it matches this
// much better, relatively (as the view pairs of a parallel beam: riner/centre.hpp).
constexpr double kOuterAdvantage = 0.25;

}  // namespace

std::optional<ConjugateAxis> conjugate_axis(const Scan& scan, const Scan& fine_scan,
                                            double search_px) {
  const Geometry& g = scan.geometry;
  if (g.type != GeometryType::kFan2d || g.n_u < 8) return std::nullopt;
  const std::optional<Turn> turn = full_turn(g);
  if (!turn) return std::nullopt;
  // Every 2 px over the search on a sixth of the rays, half pixels around the best on all of
  // them, then a parabola through the best and its neighbours.
  constexpr double kCoarseStep = 2.0;
  constexpr double kStep = 0.5;
  // A geometry that already puts the axis beyond the detector's central half is a half
  // acquisition: around its offset only the few rays near the axis have conjugates, and the
  // absolute mismatch, which counts only offsets with most rays paired, would pull the axis
  // inwards (-19.6 for -35 on 100 elements); the relative one counts every offset.
  const double inner = kCentreSearchShare * static_cast<double>(g.n_u);
  const bool declared_half = std::fabs(g.offset_u) >= inner && farthest_outer_offset(g.n_u) > inner;
  // An offset that leaves most conjugates off the detector compares only the few rays left
  // (often air): it does not count.
  const auto enough = [&](const Cost& c, std::size_t most) { return 2 * c.rays >= most; };
  struct Coarse {
    double best = 0.0;
    double least = std::numeric_limits<double>::infinity();
    bool at_end = false;  // the best is the search's first or last offset
  };
  // Every `step` px within `half_width` of `centre`; a half acquisition's offsets by the
  // relative cost (`outer`), others by the absolute one over offsets with most rays paired.
  const auto search_around = [&](double centre, double half_width, bool outer, double step) {
    const auto steps = static_cast<long>(std::ceil(half_width / step));
    std::vector<double> at;
    std::vector<Cost> costs;
    std::size_t most_rays = 0;
    for (long k = -steps; k <= steps; ++k) {
      const double offset = centre + static_cast<double>(k) * step;
      if (outer && std::fabs(offset) > farthest_outer_offset(g.n_u)) continue;
      at.push_back(offset);
      costs.push_back(conjugate_cost(scan, *turn, at.back(), outer ? kOuter : kCoarse));
      most_rays = std::max(most_rays, costs.back().rays);
    }
    Coarse out;
    out.best = centre;
    std::size_t index = 0;
    for (std::size_t k = 0; k < costs.size(); ++k) {
      const double cost = outer ? costs[k].relative : costs[k].mean;
      if ((outer || enough(costs[k], most_rays)) && std::isfinite(cost) && cost < out.least) {
        out.least = cost;
        out.best = at[k];
        index = k;
      }
    }
    out.at_end = !outer && std::isfinite(out.least) && (index == 0 || index + 1 == costs.size());
    return out;
  };
  // The whole central half in at most 129 steps (a wide detector's basin is as wide), which
  // the half-pixel search below moves on from.
  const double central_step = std::max(kCoarseStep, inner / 64.0);
  const auto search_central = [&]() { return search_around(0.0, inner, false, central_step); };
  const auto relative_at = [&](double offset) {
    return conjugate_cost(fine_scan, *turn, offset, kOuter).relative;
  };
  Coarse c;
  bool half_acquisition = declared_half;
  if (declared_half) {
    // An offset with the wrong sign (a convention's slip) matched far from the truth (a
    // review's: -216.06 for 200, -155.10 for 60): its mirror image is searched too.
    c = search_around(g.offset_u, search_px, true, kCoarseStep);
    const Coarse mirrored = search_around(-g.offset_u, search_px, true, kCoarseStep);
    if (mirrored.least < c.least) c = mirrored;
    // An offset guessed a few tens of pixels off (150 given as 200 read -233.30 px, where a
    // few pairs happened to match) or off the detector: every offset beyond the central half.
    const std::optional<std::pair<double, double>> far = outer_offset(fine_scan, *turn);
    if (far && !(relative_at(c.best) <= far->second)) c = Coarse{far->first, far->second, false};
    // A half acquisition declared where the axis lies in the detector's central half (an
    // offset mistyped or guessed: 20 px given as 150 read -176.00 px, half acquisition): the
    // central half is searched too, and taken where it matches clearly better.
    const Coarse central = search_central();
    if (std::isfinite(central.least) && !central.at_end &&
        relative_at(central.best) < kOuterAdvantage * relative_at(c.best)) {
      c = central;
      half_acquisition = false;
    }
  } else {
    c = search_around(g.offset_u, search_px, false, kCoarseStep);
    // An offset with the wrong sign (a convention's slip): where the search does not reach its
    // mirror image, that is searched too.
    if (std::fabs(g.offset_u) > search_px) {
      const Coarse mirrored = search_around(-g.offset_u, search_px, false, kCoarseStep);
      if (mirrored.least < c.least) c = mirrored;
    }
    // The best at the search's end: the axis may lie beyond (an audit's 40 px off on 240
    // elements read 34.50 from a search of 32 px). The search moves on that way while the
    // central half reaches, its end no answer past it.
    for (double centre = g.offset_u; c.at_end && std::fabs(c.best - g.offset_u) < inner &&
                                     (c.best - centre) * (c.best - g.offset_u) > 0.0;) {
      centre = c.best;
      const Coarse next = search_around(centre, search_px, false, kCoarseStep);
      if (!(next.least <= c.least)) break;
      c = next;
    }
    // The whole central half by the relative cost too, which (unlike the absolute one, over
    // offsets with most rays paired) compares an offset near the middle fairly with one near
    // the half's end; taken where the searches above end at an end, or where it matches 4
    // times better than their best. Before, a search's end, or a poor match near the half's
    // end, lost to a spurious one beyond (20 px given as -120 on 500 elements read -181.53, a
    // half acquisition; -60 given as 120 read 172.38; 90 given as 120, -145.47), and an axis
    // far from the geometry's went to a spurious basin near it (250 px given as 0 on 2000
    // elements read 84.50; 400 px, 7.50; 120 px on 500, -124.71).
    {
      const auto steps = static_cast<long>(std::floor(inner / central_step));
      Coarse relative;
      for (long k = -steps; k <= steps; ++k) {
        const double offset = static_cast<double>(k) * central_step;
        const double cost = relative_at(offset);
        if (cost < relative.least) {
          relative.least = cost;
          relative.best = offset;
          relative.at_end = k == -steps || k == steps;
        }
      }
      if (std::isfinite(relative.least) && !relative.at_end &&
          (c.at_end || relative.least < kOuterAdvantage * relative_at(c.best))) {
        c = relative;
      }
    }
  }
  double coarse_best = c.best;
  double coarse_least = c.least;
  const bool at_end = c.at_end;
  // A half acquisition's axis beyond the detector's central half: where its conjugates meet
  // far better than at the best offset around the geometry's, relatively, the fine search
  // goes there, and every offset around it counts (its few pairs are all the scan has).
  if (!declared_half) {
    const std::optional<std::pair<double, double>> far = outer_offset(fine_scan, *turn);
    const double central = std::isfinite(coarse_least) ? relative_at(coarse_best)
                                                       : std::numeric_limits<double>::infinity();
    if (far && far->second < kOuterAdvantage * central) {
      coarse_best = far->first;
      coarse_least = far->second;
      half_acquisition = true;
    }
  }
  if (!std::isfinite(coarse_least)) return std::nullopt;
  if (at_end && !half_acquisition) {
    ConjugateAxis edge;
    edge.offset_px = coarse_best;
    edge.at_search_end = true;
    return edge;
  }
  std::vector<double> offsets, costs;
  std::vector<Cost> fine;
  std::size_t best = 0;
  // Half pixels about the coarse best; where their best is at an end, about that end again (the
  // coarse search reads the stripes too: a ringed fan scan of an object wider than the field
  // of view, 3.5 px off, had its half pixels end at 2.0).
  double around = coarse_best;
  for (int moves = 0; moves <= kMostFineMoves; ++moves) {
    offsets.clear();
    costs.clear();
    fine.clear();
    std::size_t most_fine = 0;
    for (long k = -5; k <= 5; ++k) {
      offsets.push_back(around + static_cast<double>(k) * kStep);
      fine.push_back(conjugate_cost(fine_scan, *turn, offsets.back(), kFine));
      most_fine = std::max(most_fine, fine.back().rays);
    }
    for (const Cost& f : fine) {
      if (half_acquisition) {
        costs.push_back(f.relative);
      } else {
        costs.push_back(enough(f, most_fine) ? f.mean : std::numeric_limits<double>::infinity());
      }
    }
    best = static_cast<std::size_t>(std::min_element(costs.begin(), costs.end()) - costs.begin());
    if (!std::isfinite(costs[best])) return std::nullopt;
    if (best > 0 && best + 1 < costs.size()) break;
    around = offsets[best];
  }
  ConjugateAxis out;
  out.offset_px = offsets[best];
  out.rays = fine[best].rays;
  if (best > 0 && best + 1 < costs.size()) {
    const double c0 = costs[best - 1], c1 = costs[best], c2 = costs[best + 1];
    const double curvature = c0 - 2.0 * c1 + c2;
    if (std::isfinite(curvature) && curvature > 0.0) {
      out.offset_px += 0.5 * kStep * (c0 - c2) / curvature;
    }
  }
  // A declared half acquisition whose search, on a small detector, reached the central half
  // and found the axis there is none (a review's: 0, 6 and 12 given as 20 on 64 elements said
  // "half acquisition").
  out.half_acquisition = half_acquisition && std::fabs(out.offset_px) >= inner;
  return out;
}

std::optional<FanDistanceFit> conjugate_fan_distance(const Scan& fine_scan, double offset_px) {
  const Geometry& g = fine_scan.geometry;
  if (g.type != GeometryType::kFan2d || g.n_u < 8) return std::nullopt;
  const std::optional<Turn> turn = full_turn(g);
  if (!turn) return std::nullopt;
  const auto best_at = [&](double scale, RaySample sample) {
    Geometry scaled = g;
    scaled.pitch_u = g.pitch_u / scale;
    return least_cost_near(scaled, fine_scan.measurement, *turn, offset_px, sample);
  };
  FanDistanceFit fit;
  const std::pair<double, double> as_given = best_at(1.0, kCoarse);
  if (!std::isfinite(as_given.second)) return std::nullopt;
  fit.cost_as_given = fit.cost = as_given.second;
  fit.offset_px = as_given.first;
  // Factors 1/2 to 2 in steps of 2^(1/8) (9%) on a quarter of the rays, then 2^(1/32) (2%)
  // about the best on all of them, then a parabola in log scale through the best and its
  // neighbours.
  double coarse = 1.0, coarse_cost = best_at(1.0, kOuter).second;
  for (int k = -8; k <= 8; ++k) {
    if (k == 0) continue;
    const double scale = std::pow(2.0, k / 8.0);
    const double cost = best_at(scale, kOuter).second;
    if (cost < coarse_cost) coarse_cost = cost, coarse = scale;
  }
  const double step = std::log(2.0) / 32.0;
  std::vector<double> costs;
  for (int k = -4; k <= 4; ++k) {
    const double scale = coarse * std::exp(k * step);
    const std::pair<double, double> b =
        k == 0 && coarse == 1.0 ? as_given : best_at(scale, kCoarse);
    costs.push_back(b.second);
    if (b.second < fit.cost) {
      fit.cost = b.second;
      fit.scale = scale;
      fit.offset_px = b.first;
    }
  }
  const auto at =
      static_cast<std::size_t>(std::min_element(costs.begin(), costs.end()) - costs.begin());
  if (at > 0 && at + 1 < costs.size() && fit.scale != 1.0) {
    const double c0 = costs[at - 1], c1 = costs[at], c2 = costs[at + 1];
    const double curvature = c0 - 2.0 * c1 + c2;
    if (std::isfinite(curvature) && curvature > 0.0) {
      fit.scale *= std::exp(0.5 * step * (c0 - c2) / curvature);
    }
  }
  return fit;
}

std::optional<FanSense> conjugate_sense(const Scan& fine_scan, double offset_px) {
  const Geometry& g = fine_scan.geometry;
  if (g.type != GeometryType::kFan2d || g.n_u < 8) return std::nullopt;
  const std::optional<Turn> turn = full_turn(g);
  Geometry reversed = g;
  reversed.uniform_angles.reset();
  for (double& a : reversed.angles) a = -a;
  const std::optional<Turn> back = full_turn(reversed);
  if (!turn || !back) return std::nullopt;
  // The detector's columns reversed pair rays as the angles negated, the offset mirrored; an
  // offset whose sign alone is wrong (a half acquisition's, say) is no reversed sense: both
  // ways are read about either sign.
  FanSense sense;
  // Offsets within a pixel of 0 are their own mirror image within the 2 px searched.
  const std::vector<double> arounds = std::fabs(offset_px) > 1.0
                                          ? std::vector<double>{offset_px, -offset_px}
                                          : std::vector<double>{offset_px};
  for (const double around : arounds) {
    sense.cost_as_given =
        std::min(sense.cost_as_given,
                 least_cost_near(g, fine_scan.measurement, *turn, around, kCoarse).second);
    sense.cost_reversed =
        std::min(sense.cost_reversed,
                 least_cost_near(reversed, fine_scan.measurement, *back, around, kCoarse).second);
  }
  if (!std::isfinite(sense.cost_as_given)) return std::nullopt;
  return sense;
}

}  // namespace riner::preprocessing
