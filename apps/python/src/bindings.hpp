// The parts of the _riner extension module, one per concern; module.cpp puts them together.
#pragma once

#include <optional>
#include <string>

#include <pybind11/pybind11.h>

#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/scan.hpp"

namespace riner::python {

namespace py = pybind11;

// devices(), settings(), the geometry helpers.
void bind_environment(py::module_& m);
// fbp(), simulate(), center(), flat_field(), load_scan(), read_array(), write_array(),
// compare().
void bind_scan_functions(py::module_& m);
// reconstruct(): training with the GIL released, progress callback, Ctrl-C.
void bind_reconstruct(py::module_& m);

// A scan from a numpy measurement and geometry JSON, checked (check_scan) and its non-finite
// readings counted.
Scan scan_from(const py::handle& measurement, const std::string& geometry_json);

// The device an engine runs on: none for the reference engine, else Device::open(selector).
std::optional<Device> device_for(Engine engine, const std::string& selector);

}  // namespace riner::python
