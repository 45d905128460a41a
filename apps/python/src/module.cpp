// _riner: the C++ half of the `riner` Python package (apps/python/riner/__init__.py is the
// other). riner's exceptions become Python exceptions with the same one-line message:
// riner.InputError (also a ValueError) for bad input, riner.OpenCLError for device failures,
// riner.Error (a RuntimeError) as their base; options the message names are worded as
// Python's keywords (python_wording.hpp).
#include <pybind11/stl.h>

#include <cstdio>

#include "bindings.hpp"
#include "python_wording.hpp"
#include "riner/error.hpp"
#include "riner/geometry.hpp"
#include "riner/io.hpp"
#include "riner/log.hpp"
#include "riner/riner_config.hpp"
#include "riner/simulate.hpp"
#include "summary_json.hpp"

namespace riner::python {

std::optional<Device> device_for(Engine engine, const std::string& selector) {
  if (engine == Engine::kReference) return std::nullopt;
  return Device::open(selector);
}

void bind_environment(py::module_& m) {
  m.def("devices_json", [] {
    nlohmann::json out = nlohmann::json::array();
    for (const DeviceInfo& d : list_devices()) out.push_back(app::device_json(d));
    return out.dump();
  });
  m.def("settings_json", [] {
    nlohmann::json out = nlohmann::json::array();
    for (const RinerConfig::SettingInfo& s : RinerConfig::settings()) {
      out.push_back({{"name", s.name},
                     {"type", s.type},
                     {"allowed", s.allowed},
                     {"default", nlohmann::json::parse(s.default_value)},
                     {"help", s.help}});
    }
    return out.dump();
  });
  // Geometry JSON in, validated and written back in the scan contract's form; presets by
  // name; files by path.
  m.def("geometry_json", [](const std::string& text, const std::string& source) {
    return Geometry::from_json(text, source).to_json();
  });
  m.def("preset_geometry_json", [](const std::string& name) {
    if (!is_preset_geometry(name)) {
      throw InputError("unknown geometry preset '" + name +
                       "' (fan2d-paper, cone3d-paper, parallel3d)");
    }
    return preset_geometry(name).to_json();
  });
  m.def("load_geometry_json",
        [](const std::string& path) { return Geometry::load(path).to_json(); });
  // What the temporary files of process `pid` on this host carry in their names (the tests
  // plant a dead writer's file with it).
  m.def("temporary_marker", [](long pid) { return temporary_marker(pid); });
}

}  // namespace riner::python

PYBIND11_MODULE(_riner, m) {
  namespace py = pybind11;
  m.doc() = "riner's C++ library; use the riner package, not this module";
  // The library's warnings as Python warnings where the calling thread holds the GIL (a
  // UserWarning a script can filter or catch); from inside a call that released it, on stderr
  // as before.
  riner::set_warning_handler([](std::string_view message) {
    if (PyGILState_Check() == 1) {
      const std::string text = riner::python::python_wording(std::string(message));
      if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) == 0) return;
      PyErr_Clear();  // warnings as errors: no exception can leave from here
    }
    std::fprintf(stderr, "riner: warning: %.*s\n", static_cast<int>(message.size()),
                 message.data());
  });
  static py::exception<riner::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<riner::InputError> input_error(
      m, "InputError", py::make_tuple(error, py::handle(PyExc_ValueError)));
  static py::exception<riner::ClError> opencl_error(m, "OpenCLError", error);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const riner::InputError& e) {
      input_error(riner::python::python_wording(e.what()).c_str());
    } catch (const riner::ClError& e) {
      opencl_error(riner::python::python_wording(e.what()).c_str());
    } catch (const riner::Error& e) {
      error(riner::python::python_wording(e.what()).c_str());
    }
  });
  riner::python::bind_environment(m);
  riner::python::bind_scan_functions(m);
  riner::python::bind_reconstruct(m);
}
