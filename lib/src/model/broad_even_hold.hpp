// alpha's part that is even about the axis and broad, held at its initial value while the rest
// of alpha learns (training.alpha_warmup_broad_px). Before the field has drawn the object every
// element whose rays cross it reads more than the field gives; alpha's even part of that offset
// reads exactly like a radially symmetric image, so nothing in the data takes it back later,
// and its broad part stays a ring band (docs/history/RESULTS.md, issue 29). Holding all of
// alpha keeps that band out, but meanwhile the field learns the narrow rings, which a sharp
// scene then keeps; holding only the broad even part lets alpha take the narrow offsets from
// the first step.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "riner/geometry.hpp"

namespace riner::model {

class BroadEvenHold {
 public:
  // sigma_px: the Gaussian's sigma over ray distances, in grid pixels; initial: alpha's
  // starting value per element (n_u of them; a 2D geometry).
  BroadEvenHold(const Geometry& g, double sigma_px, std::span<const float> initial);

  // Takes the broad even part of ln(alpha / initial) out of alpha (n_u elements).
  void apply(std::span<float> alpha) const;
  void apply(std::span<double> alpha) const;  // the reference engine's
  // The broad even part of values (one per element): the Gaussian mean at each element's ray
  // distance and at its mirror's, averaged (the mean at its own alone where the mirror lies off
  // the detector).
  std::vector<double> broad_even(std::span<const double> values) const;

 private:
  template <typename T>
  void remove_broad_even(std::span<T> alpha) const;

  struct Weight {
    std::size_t element;
    double weight;
  };
  std::vector<std::vector<Weight>> rows_;  // per element, weights summing to 1
  std::vector<double> log_initial_;
};

}  // namespace riner::model
