#include "python/results.h"

#include <cstdint>

namespace sandbox::python {
namespace {

// A read-only array over `data` (owned by `owner`, which it keeps alive),
// C order. Made through numpy's C API directly: py::array's constructor
// (shape and stride vectors, flags read back) costs about twice as much, and
// a face scan hands out 24 of these.
template <typename T>
py::array View(const T* data, std::initializer_list<py::ssize_t> shape, py::handle owner) {
  auto& api = py::detail::npy_api::get();
  Py_intptr_t extents[3], strides[3];
  const int ndim = int(shape.size());
  std::copy(shape.begin(), shape.end(), extents);
  Py_intptr_t stride = Py_intptr_t(sizeof(T));
  for (int d = ndim - 1; d >= 0; --d) strides[d] = stride, stride *= extents[d];
  PyObject* descr = api.PyArray_DescrFromType_(py::detail::npy_format_descriptor<T>::value);
  if (descr == nullptr) throw py::error_already_set();
  auto array = py::reinterpret_steal<py::array>(api.PyArray_NewFromDescr_(
      api.PyArray_Type_, descr, ndim, extents, strides, const_cast<T*>(data), 0, nullptr));
  if (!array) throw py::error_already_set();
  if (api.PyArray_SetBaseObject_(array.ptr(), owner.inc_ref().ptr()) != 0) {
    throw py::error_already_set();
  }
  return array;
}

// The six faces' (n, n) views of one of a scan's fields ((n, n, 3) for a vector).
template <typename T, typename Field>
py::list FaceViews(const py::object& self, Field field, bool vector = false) {
  const auto& s = self.cast<const FaceScanResult&>().scan;
  py::list faces(s.faces.size());
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    const T* data = field(s.faces[f]);
    faces[f] = vector ? View(data, {s.n, s.n, 3}, self) : View(data, {s.n, s.n}, self);
  }
  return faces;
}

}  // namespace

void BindResults(py::module_& module) {
  py::class_<FaceScanResult>(module, "FaceScan",
                             "A six-face scan: per face an n x n grid (face f, row, column).")
      .def_property_readonly("n", [](const FaceScanResult& s) { return s.scan.n; })
      .def_property_readonly("resolution",
                             [](const FaceScanResult& s) { return s.scan.resolution_m; })
      .def_property_readonly("half_extent",
                             [](const FaceScanResult& s) { return s.scan.half_extent_m; })
      .def_property_readonly(
          "occupancy",
          [](const py::object& self) {
            return FaceViews<std::int8_t>(
                self, [](const auto& face) { return face.occupancy.data(); });
          },
          "6 int8 (n, n) views: 1 occupied, 0 free (sensors.md, Occupancy)")
      .def_property_readonly(
          "distance",
          [](const py::object& self) {
            return FaceViews<float>(
                self, [](const auto& face) { return face.distance_m.data(); });
          },
          "6 float32 (n, n) views: metres from the ray's start along the face's axis")
      .def_property_readonly(
          "surface",
          [](const py::object& self) {
            return FaceViews<std::int32_t>(
                self, [](const auto& face) { return face.surface.data(); });
          },
          "6 int32 (n, n) views: the surface id hit (World.surfaces()), 0 none")
      .def_property_readonly(
          "normal",
          [](const py::object& self) {
            return FaceViews<float>(
                self, [](const auto& face) { return face.normal_W.data()->data(); }, true);
          },
          "6 float32 (n, n, 3) views: the unit normal at the hit, world frame; 0 free")
      .def(
          "points",
          [](const FaceScanResult& self) {
            const auto& s = self.scan;
            py::array_t<double> points({6, s.n, s.n, 3});
            double* out = points.mutable_data();
            for (int f = 0; f < 6; ++f) {
              for (std::size_t k = 0; k < std::size_t(s.n) * std::size_t(s.n); ++k) {
                const Eigen::Vector3d p = s.PointW(f, k);
                for (int c = 0; c < 3; ++c) *out++ = p[c];
              }
            }
            return points;
          },
          "(6, n, n, 3) float64, world: each sample's hit or its ray's end (a new array)");

  py::class_<GroundScanResult>(module, "GroundScan",
                               "A height map below a point: n x n (row, column).")
      .def_property_readonly("n", [](const GroundScanResult& s) { return s.map.n; })
      .def_property_readonly("resolution",
                             [](const GroundScanResult& s) { return s.map.resolution_m; })
      .def_property_readonly(
          "corner",
          [](const GroundScanResult& s) {
            return py::make_tuple(s.map.corner_W.x(), s.map.corner_W.y());
          },
          "x, y of row 0, column 0 (rows along y, columns along x)")
      .def_property_readonly(
          "height",
          [](py::object self) {
            const auto& m = self.cast<const GroundScanResult&>().map;
            return View(m.height_m.data(), {m.n, m.n}, self);
          },
          "float64 (n, n) view: the ground's height, NaN without ground")
      .def_property_readonly(
          "surface",
          [](py::object self) {
            const auto& m = self.cast<const GroundScanResult&>().map;
            return View(m.surface.data(), {m.n, m.n}, self);
          },
          "int32 (n, n) view: the surface id hit, 0 none")
      .def_property_readonly(
          "normal",
          [](py::object self) {
            const auto& m = self.cast<const GroundScanResult&>().map;
            return View(m.normal_W.data()->data(), {m.n, m.n, 3}, self);
          },
          "float32 (n, n, 3) view: the ground's unit normal, world frame");

  py::class_<LidarScanResult>(module, "LidarScan", "A lidar sweep: channels x azimuth steps.")
      .def_property_readonly("channels", [](const LidarScanResult& s) { return s.scan.channels; })
      .def_property_readonly("steps", [](const LidarScanResult& s) { return s.scan.azimuth_steps; })
      .def_property_readonly(
          "range",
          [](py::object self) {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            return View(s.range_m.data(), {s.channels, s.azimuth_steps}, self);
          },
          "float32 (channels, steps) view: metres to the hit, or the range when none")
      .def_property_readonly(
          "hit",
          [](py::object self) {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            return View(s.hit.data(), {s.channels, s.azimuth_steps}, self);
          },
          "uint8 (channels, steps) view: 1 when the beam hit")
      .def_property_readonly(
          "points",
          [](py::object self) {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            return View(s.points_W.data()->data(), {s.channels, s.azimuth_steps, 3}, self);
          },
          "float64 (channels, steps, 3) view: the hit or the beam's end, world")
      .def_property_readonly(
          "surface",
          [](py::object self) {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            return View(s.surface.data(), {s.channels, s.azimuth_steps}, self);
          },
          "int32 (channels, steps) view: the surface id hit, 0 none")
      .def_property_readonly(
          "normal",
          [](py::object self) {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            return View(s.normal_W.data()->data(), {s.channels, s.azimuth_steps, 3}, self);
          },
          "float32 (channels, steps, 3) view: the unit normal at the hit, world")
      .def(
          "_addresses",
          [](const LidarScanResult& self) {
            py::dict out;
            out["range"] = reinterpret_cast<std::uintptr_t>(self.scan.range_m.data());
            out["points"] = reinterpret_cast<std::uintptr_t>(self.scan.points_W.data());
            return out;
          },
          "where the scan's own buffers are (the tests compare the arrays' data with them)")
      .def_property_readonly(
          "intensity",
          [](py::object self) -> py::object {
            const auto& s = self.cast<const LidarScanResult&>().scan;
            if (s.intensity.empty()) return py::none();
            return View(s.intensity.data(), {s.channels, s.azimuth_steps}, self);
          },
          "float32 (channels, steps) view, 0 to 1, or None without 'intensity = true'");

  py::class_<FrameResult>(module, "Frame", "A camera's images, row 0 at the top.")
      .def_property_readonly("width", [](const FrameResult& f) { return f.frame.width; })
      .def_property_readonly("height", [](const FrameResult& f) { return f.frame.height; })
      .def_property_readonly(
          "color",
          [](py::object self) -> py::object {
            const auto& f = self.cast<const FrameResult&>().frame;
            if (f.rgb.empty()) return py::none();
            return View(f.rgb.data(), {f.height, f.width, 3}, self);
          },
          "uint8 (height, width, 3) view, RGB; None when not asked for")
      .def_property_readonly(
          "depth",
          [](py::object self) -> py::object {
            const auto& f = self.cast<const FrameResult&>().frame;
            if (f.depth_m.empty()) return py::none();
            return View(f.depth_m.data(), {f.height, f.width}, self);
          },
          "float32 (height, width) view: metres along the optical axis, inf where sky")
      .def_property_readonly(
          "segmentation",
          [](py::object self) -> py::object {
            const auto& f = self.cast<const FrameResult&>().frame;
            if (f.segment.empty()) return py::none();
            return View(f.segment.data(), {f.height, f.width}, self);
          },
          "uint32 (height, width) view: the surface id seen (World.surfaces()), 0 sky")
      .def_property_readonly(
          "normals",
          [](py::object self) -> py::object {
            const auto& f = self.cast<const FrameResult&>().frame;
            if (f.normal_C.empty()) return py::none();
            return View(f.normal_C.data(), {f.height, f.width, 3}, self);
          },
          "float32 (height, width, 3) view: unit normals, camera frame (x forward, y left, z "
          "up); 0 where sky");
}

}  // namespace sandbox::python
