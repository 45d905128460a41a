#include "model/response_map.hpp"

#include "riner/error.hpp"

namespace riner::model {

ResponseMap::ResponseMap(std::size_t elements)
    : elements_(elements), slots_(elements), table_(elements) {
  for (std::size_t e = 0; e < elements; ++e) table_[e] = static_cast<std::uint32_t>(e);
}

ResponseMap::ResponseMap(std::size_t elements, std::size_t views,
                         const std::vector<ResponseChange>& changes)
    : ResponseMap(elements) {
  views_ = views;
  for (const ResponseChange& c : changes) {
    if (c.element >= elements || c.starts.empty()) continue;
    const std::size_t o = table_.size();
    if (o >= kViewTable) throw Error("response map: too many changing elements");
    table_[c.element] = kViewTable | static_cast<std::uint32_t>(o);
    const std::size_t n = c.starts.size() + 1;
    table_.push_back(static_cast<std::uint32_t>(n));
    table_.push_back(static_cast<std::uint32_t>(c.element));
    for (std::size_t k = 1; k < n; ++k) {
      table_.push_back(static_cast<std::uint32_t>(slots_++));
      owner_.push_back(static_cast<std::uint32_t>(c.element));
    }
    std::size_t segment = 0;
    for (std::size_t v = 0; v < views; ++v) {
      while (segment + 1 < n && v >= c.starts[segment]) ++segment;
      table_.push_back(table_[o + 1 + segment]);
    }
  }
}

std::size_t ResponseMap::slot(std::size_t element, std::size_t view) const {
  const std::uint32_t s = table_[element];
  if (!(s & kViewTable)) return s;
  const std::size_t o = s & ~kViewTable;
  return table_[o + 1 + table_[o] + view];
}

std::size_t ResponseMap::element_of(std::size_t slot) const {
  return slot < elements_ ? slot : owner_[slot - elements_];
}

std::vector<ResponseMap::Segment> ResponseMap::segments(std::size_t element) const {
  const std::uint32_t s = table_[element];
  if (!(s & kViewTable)) return {{s, 0, views_}};
  const std::size_t o = s & ~kViewTable;
  const std::size_t first = o + 1 + table_[o];
  std::vector<Segment> out;
  for (std::size_t v = 0; v < views_; ++v) {
    if (out.empty() || out.back().slot != table_[first + v])
      out.push_back({table_[first + v], v, 0});
    ++out.back().views;
  }
  return out;
}

}  // namespace riner::model
