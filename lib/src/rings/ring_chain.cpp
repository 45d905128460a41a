#include "riner/ring_chain.hpp"

#include <string>

#include "riner/error.hpp"

namespace riner {

RingChain correct_rings_in_order(const Array& image, const Array& alpha, const Geometry& g,
                                 const std::vector<std::size_t>& dead_elements,
                                 const RingCorrectionConfig& config,
                                 const std::vector<std::uint8_t>& sampled) {
  if (!sampled.empty() && sampled.size() != image.size()) {
    throw InputError("ring corrections: the sampled-pixel mask has " +
                     std::to_string(sampled.size()) + " values for an image of " +
                     std::to_string(image.size()));
  }
  RingChain out{image, alpha, std::nullopt, std::nullopt, std::nullopt, std::nullopt,
                std::nullopt};
  const auto take = [&out, &sampled](std::optional<RingCorrection>& slot, RingCorrection c) {
    out.image = c.image;
    out.alpha = c.alpha;
    for (std::size_t p = 0; p < sampled.size(); ++p) {
      if (!sampled[p]) out.image.data[p] = 0.0f;
    }
    slot = std::move(c);
  };
  // First: what training put into alpha that is an object goes back before the others judge
  // the image's rings (after them, it would undo their rings: docs/history/RESULTS.md, issue 32).
  if (config.mirror_reference) {
    take(out.mirror,
         correct_rings_from_mirrors(out.image, out.alpha, g, dead_elements, config.mirror));
  }
  if (config.air_reference) {
    take(out.air, correct_rings_from_air(out.image, out.alpha, g, config.air));
  }
  const std::vector<double> objects =
      out.mirror ? out.mirror->object_radii_mm : std::vector<double>{};
  if (config.gradient_reference) {
    take(out.gradient,
         correct_rings_from_gradient(out.image, out.alpha, g, config.gradient, objects));
  }
  if (config.response_reference) {
    take(out.response, correct_rings_from_response(out.image, out.alpha, g, dead_elements,
                                                   config.response, objects));
    if (config.gradient_reference && config.gradient_after_response) {
      take(out.gradient_after_response,
           correct_rings_from_gradient(out.image, out.alpha, g, config.gradient, objects));
    }
  }
  return out;
}

}  // namespace riner
