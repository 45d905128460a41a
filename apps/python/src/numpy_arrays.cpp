#include "numpy_arrays.hpp"

#include <string>
#include <vector>

namespace riner::python {

Array to_array(const py::handle& value, const char* what) {
  if (!py::isinstance<py::array>(value)) {
    throw py::type_error(std::string(what) + " must be a numpy array (got " +
                         py::str(value.get_type().attr("__name__")).cast<std::string>() + ")");
  }
  const auto array = py::reinterpret_borrow<py::array>(value);
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::type_error(std::string(what) + " must hold real numbers (got dtype " +
                         py::str(array.dtype()).cast<std::string>() + ")");
  }
  const auto floats = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!floats) throw py::error_already_set();
  std::vector<std::size_t> shape;
  for (py::ssize_t axis = 0; axis < floats.ndim(); ++axis) {
    shape.push_back(static_cast<std::size_t>(floats.shape(axis)));
  }
  const float* first = floats.data();
  return Array(std::move(shape), std::vector<float>(first, first + floats.size()));
}

py::array to_numpy(Array array) {
  auto* data = new std::vector<float>(std::move(array.data));
  const py::capsule owner(data, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  const std::vector<py::ssize_t> shape(array.shape.begin(), array.shape.end());
  return py::array_t<float>(shape, data->data(), owner);
}

}  // namespace riner::python
