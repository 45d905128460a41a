// Which response (an alpha0 and a beta0 in the parameter buffer) each reading uses. Element e's
// response is slot e; an element whose response changes part-way (model/response_changes.hpp)
// has one slot per segment of views: slot e for its first, slots past the last element for the
// others. The step kernel reads the table (kernels/riner_step.cl, response_slot):
//   table[e] = slot of every view of e, or kViewTable | o for a changing element, where
//   table[o] = its segment count n, table[o + 1 .. o + n] = its slots in view order and
//   table[o + 1 + n + v] = the slot of view v.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "model/response_changes.hpp"

namespace riner::model {

class ResponseMap {
 public:
  static constexpr std::uint32_t kViewTable = 0x80000000u;

  ResponseMap() = default;
  // One response per element, the same in every view.
  explicit ResponseMap(std::size_t elements);
  // Element-per-view responses split where `changes` say (elements ascending).
  ResponseMap(std::size_t elements, std::size_t views, const std::vector<ResponseChange>& changes);

  std::size_t elements() const { return elements_; }
  std::size_t slots() const { return slots_; }
  bool varies() const { return slots_ > elements_; }
  std::size_t slot(std::size_t element, std::size_t view) const;
  // The element a slot belongs to.
  std::size_t element_of(std::size_t slot) const;
  // An element's slots in view order, and each slot's first view.
  struct Segment {
    std::size_t slot;
    std::size_t first_view;
    std::size_t views;
  };
  std::vector<Segment> segments(std::size_t element) const;
  const std::vector<std::uint32_t>& table() const { return table_; }

 private:
  std::size_t elements_ = 0;
  std::size_t views_ = 0;
  std::size_t slots_ = 0;
  std::vector<std::uint32_t> table_;
  std::vector<std::uint32_t> owner_;  // element of each slot past elements_
};

}  // namespace riner::model
