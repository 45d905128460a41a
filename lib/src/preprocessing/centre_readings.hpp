// The readings the centre finders and the geometry checks compare, prepared alike: spikes and
// stuck elements left out, a large 3D scan cut to the rows they read, a full turn's element
// means taken out, a cone's fan through the source's plane, views in angle order.
#pragma once

#include <cstddef>

#include "riner/array.hpp"
#include "riner/scan.hpp"

namespace riner::preprocessing {

// Whether the finite readings differ at all (a constant scan would match itself at every
// offset, and the search would report the edge of its range).
bool holds_structure(const Array& measurement);

// Beyond this many readings a 3D scan is read on centre_rows.
constexpr std::size_t kMostCopiedReadings = std::size_t{1} << 25;
// A parallel 3D scan's rows for the centre: evenly spread, each a slice of its own.
constexpr std::size_t kCentreRows = 24;

// A 3D scan cut to the rows the centre is found on: a cone's four rows about the source's
// plane; a parallel beam's kCentreRows evenly spread.
Scan centre_rows(const Scan& scan);

// Elements that read one steady value while their neighbours vary, and spikes, set NaN (left
// out as unread readings are); a large 3D scan first cut to centre_rows.
Scan prepared(const Scan& scan);

// The readings the methods compare: a full turn's less each element's mean over the turn.
Scan compared(Scan scan);

// A cone beam's rays through the source's plane as a fan-beam scan with the cone's distances.
Scan midplane_fan(const Scan& cone);

// Whether a cone's source plane projects onto its detector (within half a row of its rows):
// where it does not (a band of rows cropped off the middle), no row holds the conjugate rays.
bool source_plane_on_detector(const Geometry& cone);

// A 2D scan's views in order of angle; the same scan where its angles already run one way.
Scan in_angle_order(Scan scan);

// The fan the conjugate checks read: prepared(), compared(), a cone's midplane fan, in angle
// order.
Scan compared_fan(const Scan& scan);

}  // namespace riner::preprocessing
