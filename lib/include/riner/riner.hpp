// The whole public library in one include: scans and their files, FBP, Riner's reconstruction,
// the classical stripe filters, the centre search, slab runs, simulation and the metrics. The
// single headers below are for code that wants fewer.
#pragma once

#include "riner/angular_range.hpp"
#include "riner/array.hpp"
#include "riner/centre.hpp"
#include "riner/destripe.hpp"
#include "riner/device.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/flat_field.hpp"
#include "riner/geometry.hpp"
#include "riner/geometry_doubts.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"
#include "riner/riner_config.hpp"
#include "riner/scan.hpp"
#include "riner/scan_source.hpp"
#include "riner/simulate.hpp"
#include "riner/slab_fbp.hpp"
#include "riner/slab_run.hpp"
#include "riner/version.hpp"
