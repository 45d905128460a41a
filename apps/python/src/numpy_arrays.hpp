// numpy arrays in and out of riner::Array. riner::Array owns its float32 data, so an array coming
// in is copied once (a memcpy when it is float32 and C-contiguous, a conversion otherwise); an
// array going out hands its buffer to numpy without a copy.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "riner/array.hpp"

namespace riner::python {

namespace py = pybind11;

// `what` names the argument in the TypeError raised for anything but a numpy array of real
// numbers (bool, complex, object and string arrays are refused).
Array to_array(const py::handle& value, const char* what);

py::array to_numpy(Array array);

}  // namespace riner::python
