#pragma once
// Python arguments read and checked: ValueError naming the argument for
// wrong shapes, NaN or infinity, KeyError listing the known names.

#include <pybind11/pybind11.h>

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "sensors/face_scanner.h"

namespace sandbox::python {

namespace py = pybind11;

// `value` as `count` finite doubles (any count when 0), else ValueError naming `argument`.
std::vector<double> FiniteVector(const py::handle& value, std::size_t count,
                                 const std::string& argument);
// A position and a unit quaternion (w, x, y, z) as a pose.
Eigen::Isometry3d Pose(const py::handle& position, const py::handle& orientation);
// `value` when positive and finite, else ValueError naming `argument`.
double Positive(double value, const std::string& argument);
// A one-off face scan's settings, as `sandbox scan` has them: every face
// in full, with normals, finer than a sensor of the loop may be.
sensors::FaceScannerConfig FaceConfig(double resolution, double half_extent,
                                      const std::string& aligned);
// KeyError naming `name` and listing the known ones.
[[noreturn]] void Unknown(const std::string& what, const std::string& name,
                          const std::vector<std::string>& known);

}  // namespace sandbox::python
