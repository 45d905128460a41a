// Detector elements whose response changes part-way through the scan (partial rings), found
// from the measurement before training. A per-element alpha constant over the views cannot model
// an element that drifts, switches gain, or dies half-way (issue 32): the part of the scan that
// disagrees with the element's mean response becomes a half ring in the image.
//
// Two kinds of evidence, both strong by construction, so that a scan without such elements
// trains exactly as before:
//   - a change: the element's reading jumps between two views against its neighbours' (the
//     view-to-view difference minus the neighbours' median difference is at least spike_sigmas
//     times the noise there, eight times either neighbour's within one view, and four times its
//     own in the views before and after), and the jump holds as a step of the element's offset
//     from its neighbours: over the next and the previous min_views / 2 views (at least half
//     the jump, three times the spread there) and, at half its size or more, over min_views
//     views on either side (near the scan's ends over the views left, at least views / 36:
//     a change from view views / 36 on is looked for). An edge of the object sweeping past an
//     element moves its
//     neighbours' readings too or spreads over several views; a tangent edge dwelling on it
//     comes and goes (two jumps closer than min_views: neither kept);
//   - dying part-way: a run of at least min_views non-finite readings in an element that also
//     has at least min_views finite ones.
// min_views is max(24, views / 12). On 14 simulated scans (DeepLesion and Shepp-Logan, fan and
// parallel beams, 10^4 to 10^7 photons) it found 82 of 97 changes at their view and nothing
// else; nothing on the ten DeepLesion slices of the paper's protocol, wood_neutron, the HTC
// disc and the tooth; on neutron360 the two elements that read nothing for part of the scan.
// Changes within views / 12 of the scan's ends (the same scans, 12 per slice there): 93 of
// 120 at their view, nothing else. What it misses: changes where the object varies as much
// around the jump (near the axis of busy slices), within views / 36 of the ends, and slow
// drifts (docs/history/RESULTS.md, issue 32).
#pragma once

#include <cstddef>
#include <vector>

#include "riner/array.hpp"

namespace riner::model {

struct ResponseChange {
  std::size_t element = 0;
  // The first view of every segment after the first, ascending; each segment holds at least
  // min_views views, except where non-finite readings bound it.
  std::vector<std::size_t> starts;
  bool dies = false;  // segments bounded by runs of non-finite readings
};

struct ResponseChangeSettings {
  double spike_sigmas = 12.0;
};

// rho: [views, elements] (a 2D sinogram) or [views, rows, columns] (each detector row's
// sinogram on its own; elements row-major); non-finite readings allowed. Elements in order.
std::vector<ResponseChange> find_response_changes(const Array& rho,
                                                  const ResponseChangeSettings& settings);

// The shortest segment a change leaves (views).
std::size_t response_change_min_views(std::size_t views);

}  // namespace riner::model
