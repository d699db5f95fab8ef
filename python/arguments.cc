#include "python/arguments.h"

#include <pybind11/numpy.h>

#include <cmath>
#include <sstream>

namespace sandbox::python {

std::vector<double> FiniteVector(const py::handle& value, std::size_t count,
                                 const std::string& argument) {
  // A tuple or list of Python numbers (the common case) read as it is;
  // anything else through numpy.
  if (PyTuple_Check(value.ptr()) || PyList_Check(value.ptr())) {
    const py::sequence items = py::reinterpret_borrow<py::sequence>(value);
    std::vector<double> values;
    bool numbers = count == 0 || std::size_t(items.size()) == count;
    for (std::size_t i = 0; numbers && i < std::size_t(items.size()); ++i) {
      PyObject* item = PyTuple_Check(value.ptr()) ? PyTuple_GET_ITEM(value.ptr(), i)
                                                  : PyList_GET_ITEM(value.ptr(), i);
      numbers = PyFloat_Check(item) || PyLong_Check(item);
      if (numbers) values.push_back(PyFloat_AsDouble(item));
      if (PyErr_Occurred()) {  // an int too large for a double
        PyErr_Clear();
        throw py::value_error(argument + " must be finite, got a number too large for a double");
      }
    }
    if (numbers) {
      for (const double v : values) {
        if (!std::isfinite(v)) {
          throw py::value_error(argument + " must be finite, got " + std::to_string(v));
        }
      }
      return values;
    }
  }
  py::array_t<double, py::array::c_style | py::array::forcecast> array;
  try {
    array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!array || array.ndim() != 1 || (count > 0 && std::size_t(array.size()) != count)) {
    std::ostringstream why;
    why << argument << " must be " << (count > 0 ? std::to_string(count) : std::string("a list of"))
        << " numbers" << (count > 0 ? " in a flat sequence" : "") << ", got "
        << std::string(py::str(py::repr(value)));
    throw py::value_error(why.str());
  }
  std::vector<double> values(array.data(), array.data() + array.size());
  for (const double v : values) {
    if (!std::isfinite(v))
      throw py::value_error(argument + " must be finite, got " + std::to_string(v));
  }
  return values;
}

Eigen::Isometry3d Pose(const py::handle& position, const py::handle& orientation) {
  const std::vector<double> p = FiniteVector(position, 3, "position");
  const std::vector<double> q = FiniteVector(orientation, 4, "orientation");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1.0) > 1e-3) {
    throw py::value_error("orientation must be a unit quaternion (w, x, y, z), its norm is " +
                          std::to_string(rotation.norm()));
  }
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  X.linear() = rotation.normalized().toRotationMatrix();
  return X;
}

double Positive(double value, const std::string& argument) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw py::value_error(argument + " must be a positive number, got " + std::to_string(value));
  }
  return value;
}

sensors::FaceScannerConfig FaceConfig(double resolution, double half_extent,
                                      const std::string& aligned) {
  sensors::FaceScannerConfig config;
  config.resolution_m = Positive(resolution, "resolution");
  config.half_extent_m = Positive(half_extent, "half_extent");
  if (aligned != "body" && aligned != "world") {
    throw py::value_error("aligned must be 'body' or 'world', got '" + aligned + "'");
  }
  config.alignment = aligned == "body" ? sensors::Alignment::kBody : sensors::Alignment::kWorld;
  config.refresh = sensors::Refresh::kFull;
  config.sample_budget = 1e7;
  config.normals = true;
  return config;
}

[[noreturn]] void Unknown(const std::string& what, const std::string& name,
                          const std::vector<std::string>& known) {
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  throw py::key_error("no " + what + " '" + name +
                      "'; the level has: " + (list.empty() ? "none" : list));
}

}  // namespace sandbox::python
