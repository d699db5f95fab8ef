#pragma once
// What a scan or a render returns to Python: the C++ result kept whole, its
// buffers shown as read-only numpy arrays that keep it alive (no copies).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/render/view.h"

namespace sandbox::python {

namespace py = pybind11;

struct FaceScanResult {
  sensors::FaceScan scan;
};
struct GroundScanResult {
  sensors::HeightMap map;
};
struct LidarScanResult {
  sensors::LidarScan scan;
};
struct FrameResult {
  render::Frame frame;
};

// Adds FaceScan, GroundScan, LidarScan and Frame to `module`.
void BindResults(py::module_& module);

}  // namespace sandbox::python
