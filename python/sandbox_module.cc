// The Python extension `sandbox._sandbox` (pybind11): a level loaded in-process, its
// robots posed, scans at any pose and cameras' images, returned as numpy
// views (python/results.h). The GIL is released while a scan casts or a
// camera draws; scans from several threads run at once (each beyond the
// first on a one-thread caster of its own), poses and renders wait for them.
// docs/reference/python.md.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <sstream>
#include <string>
#include <vector>

#include "app/defaults.h"
#include "app/images.h"
#include "app/loaded_level.h"
#include "python/lcm_access.h"
#include "python/results.h"
#include "scene/collision_world.h"
#include "scene/robot_state.h"
#include "scene/terrain_streamer.h"
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"
#include "sensors/render/cameras.h"
#include "sensors/render/renderer.h"

namespace py = pybind11;

namespace sandbox::python {
namespace {

// `value` as `count` finite doubles, else ValueError naming `argument`.
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

// A one-off face scan's settings, as `sandbox scan` has them: every face
// in full, with normals, finer than a sensor of the loop may be.
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

// KeyError naming `name` and listing the known ones.
[[noreturn]] void Unknown(const std::string& what, const std::string& name,
                          const std::vector<std::string>& known) {
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  throw py::key_error("no " + what + " '" + name +
                      "'; the level has: " + (list.empty() ? "none" : list));
}

class World {
 public:
  World(const std::optional<std::string>& level, bool isolate)
      : loaded_(
            app::LoadCheckedLevel(level.value_or(app::kDefaultLevel), {},
                                  isolate ? app::Isolation::kAlways : app::Isolation::kSceneFiles)),
        world_(loaded_.level) {
    for (const scene::RobotModel& model : loaded_.level.robots) {
      states_.push_back(std::make_unique<scene::RobotState>(model));
    }
    for (std::size_t r = 0; r < states_.size(); ++r) world_.UpdateRobot(int(r), *states_[r]);
    if (loaded_.level.terrain) terrain_ = std::make_unique<scene::TerrainStreamer>(loaded_.level);
  }

  std::string name() const { return loaded_.level.name; }
  std::vector<std::string> robots() const {
    std::vector<std::string> names;
    for (const scene::RobotModel& model : loaded_.level.robots) names.push_back(model.name);
    return names;
  }

  int Robot(const std::string& name) const {
    const int r = loaded_.level.FindRobot(name);
    if (r < 0) Unknown("robot", name, robots());
    return r;
  }

  void SetPose(const std::string& robot, const py::handle& position,
               const py::handle& orientation) {
    const int r = Robot(robot);
    const Eigen::Isometry3d X = Pose(position, orientation);
    Change(r, "pose", [&](scene::RobotState& state) { return state.SetPose(X); });
  }

  void SetBones(const std::string& robot, const py::handle& values) {
    const int r = Robot(robot);
    const std::size_t count = std::size_t(loaded_.level.robots[std::size_t(r)].num_values);
    if (count == 0) throw py::value_error(robot + " has no bones");
    const std::vector<double> v = FiniteVector(values, count, "values");
    Change(r, "bone values", [&](scene::RobotState& state) { return state.SetBones(v); });
  }

  py::tuple GetPose(const std::string& robot) const {
    const int r = Robot(robot);
    std::shared_lock<std::shared_mutex> lock(mutex_);
    const Eigen::Isometry3d& X = states_[std::size_t(r)]->pose();
    const Eigen::Quaterniond q(X.linear());
    return py::make_tuple(
        py::make_tuple(X.translation().x(), X.translation().y(), X.translation().z()),
        py::make_tuple(q.w(), q.x(), q.y(), q.z()));
  }

  std::vector<double> Bones(const std::string& robot) const {
    const int r = Robot(robot);
    std::shared_lock<std::shared_mutex> lock(mutex_);
    return states_[std::size_t(r)]->bone_values();
  }

  std::vector<py::dict> Surfaces() const {
    std::vector<py::dict> rows;
    std::shared_lock<std::shared_mutex> lock(mutex_);
    for (const scene::SurfaceEntry& e : world_.SurfaceTable()) {
      py::dict row;
      row["id"] = e.id;
      row["kind"] = e.kind;
      row["name"] = e.name;
      row["robot"] = e.robot_name;
      row["bone"] = e.bone_name;
      rows.push_back(row);
    }
    return rows;
  }

  FaceScanResult FaceScan(const py::handle& position, const py::handle& orientation,
                          double resolution, double half_extent, const std::string& aligned,
                          bool see_robots) {
    const sensors::FaceScannerConfig config = FaceConfig(resolution, half_extent, aligned);
    const Eigen::Isometry3d X_WS = Pose(position, orientation);
    const sensors::FaceScanner scanner(config);  // throws std::invalid_argument
    FaceScanResult result{scanner.EmptyScan()};
    Cast(X_WS.translation(), see_robots,
         [&](sensors::RayCaster& caster, const sensors::RayFilter& filter) {
           scanner.Scan(world_, caster, filter, X_WS, 0, &result.scan);
         });
    return result;
  }

  GroundScanResult GroundScan(const py::handle& position, double resolution, double half_extent,
                              double depth, bool see_robots) {
    sensors::GroundScannerConfig config;
    config.resolution_m = Positive(resolution, "resolution");
    config.half_extent_m = Positive(half_extent, "half_extent");
    config.depth_m = Positive(depth, "depth");
    config.normals = true;
    const std::vector<double> p = FiniteVector(position, 3, "position");
    const Eigen::Vector3d p_WS(p[0], p[1], p[2]);
    const sensors::GroundScanner scanner(config);
    GroundScanResult result;
    Cast(p_WS, see_robots, [&](sensors::RayCaster& caster, const sensors::RayFilter& filter) {
      scanner.Scan(world_, caster, filter, p_WS, &result.map);
    });
    return result;
  }

  LidarScanResult LidarScan(const py::handle& position, const py::handle& orientation,
                            const std::string& settings, bool see_robots) {
    sensors::LidarConfig config = sensors::LidarConfig::FromText(settings, "settings");
    config.normals = true;
    const Eigen::Isometry3d X_WS = Pose(position, orientation);
    const sensors::Lidar lidar(config);
    LidarScanResult result;
    Cast(X_WS.translation(), see_robots,
         [&](sensors::RayCaster& caster, const sensors::RayFilter& filter) {
           lidar.Sweep(world_, caster, filter, X_WS, X_WS, &result.scan);
         });
    return result;
  }

  FrameResult Render(const std::string& camera, const py::object& position,
                     const py::handle& orientation, const std::optional<std::string>& robot,
                     int width, int height, double fov, const std::string& kinds,
                     const std::string& quality) {
    render::RenderSettings settings = render::RenderSettings::Preset(render::ParseQuality(quality));
    settings.images = render::ParseImageKinds(kinds);
    render::CameraView view;
    if (width < 1 || width > 16384 || height < 1 || height > 16384) {
      throw py::value_error("width and height must be 1 to 16384, got " + std::to_string(width) +
                            " x " + std::to_string(height));
    }
    view.width = width;
    view.height = height;
    view.fov_y_rad = fov * M_PI / 180.0;
    if (camera == "fixed") {
      if (position.is_none()) throw py::value_error("a fixed camera needs its position");
      view.X_WC = Pose(position, orientation);
    } else if (camera == "chase" || camera == "trailing" || camera == "payload") {
      if (!position.is_none()) {
        throw py::value_error("a " + camera +
                              " camera follows its robot: give robot, not position");
      }
      if (states_.empty())
        throw py::value_error("a " + camera + " camera needs a robot; the level has none");
      const Eigen::Isometry3d X_WB = states_[std::size_t(robot ? Robot(*robot) : 0)]->pose();
      view.X_WC = camera == "chase"      ? render::ChaseCamera({}).Update(X_WB, 0.0)
                  : camera == "trailing" ? render::TrailingPose(X_WB, 25.0, 8.0, {})
                                         : X_WB;
    } else {
      throw py::value_error("camera must be 'fixed', 'chase', 'trailing' or 'payload', got '" +
                            camera + "'");
    }
    if (loaded_.level.terrain) view.far_m = 1.0e6;
    view.ValidateOrThrow();
    FrameResult result;
    py::gil_scoped_release release;
    RenderInto(view, settings, &result.frame);
    return result;
  }

  // A fixed camera's colour and depth at `position` (looking along x),
  // `repeats` times in C++ alone: the best time of one, in seconds (for
  // bench/python_scan.py, against render from Python).
  double TimeRender(const py::handle& position, int width, int height, int repeats) {
    render::RenderSettings settings = render::RenderSettings::Preset(render::Quality::kHigh);
    settings.images = render::kColorImage | render::kDepthImage;
    render::CameraView view;
    view.width = width;
    view.height = height;
    view.X_WC = Pose(position, py::make_tuple(1, 0, 0, 0));
    view.ValidateOrThrow();
    py::gil_scoped_release release;
    double best = 1e300;
    for (int i = 0; i < repeats; ++i) {
      const auto start = std::chrono::steady_clock::now();
      render::Frame frame;
      RenderInto(view, settings, &frame);
      best = std::min(
          best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    return best;
  }

  // The same face scan as FaceScan's, `repeats` times in C++ alone (no
  // Python objects, no arrays): the best time of one, in seconds. For
  // bench/python_scan.py, which compares it with face_scan from Python.
  double TimeFaceScan(const py::handle& position, double resolution, double half_extent,
                      int repeats) {
    const sensors::FaceScannerConfig config = FaceConfig(resolution, half_extent, "body");
    const Eigen::Isometry3d X_WS = Pose(position, py::make_tuple(1, 0, 0, 0));
    const sensors::FaceScanner scanner(config);
    double best = 1e300;
    for (int i = 0; i < repeats; ++i) {
      const auto start = std::chrono::steady_clock::now();
      sensors::FaceScan scan = scanner.EmptyScan();
      Cast(X_WS.translation(), false,
           [&](sensors::RayCaster& caster, const sensors::RayFilter& filter) {
             scanner.Scan(world_, caster, filter, X_WS, 0, &scan);
           });
      best = std::min(
          best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    return best;
  }

  py::dict Ray(const py::handle& position, const py::handle& orientation, double range,
               bool see_robots) {
    sensors::RangeSensorConfig config;
    config.range_m = Positive(range, "range");
    const Eigen::Isometry3d X_WS = Pose(position, orientation);
    sensors::RangeReading reading;
    Cast(X_WS.translation(), see_robots,
         [&](sensors::RayCaster& caster, const sensors::RayFilter& filter) {
           reading = sensors::MeasureRange(config, world_, caster, filter, X_WS);
         });
    py::dict out;
    out["hit"] = reading.hit;
    out["range"] = reading.range_m;
    out["point"] = py::make_tuple(reading.point_W.x(), reading.point_W.y(), reading.point_W.z());
    out["normal"] =
        py::make_tuple(reading.normal_W.x(), reading.normal_W.y(), reading.normal_W.z());
    out["surface"] = reading.surface;
    return out;
  }

 private:
  // Runs `scan` without the GIL: first, alone (the world changes), the
  // terrain's tiles around `p_WS` in and the floating origin to the metre
  // nearest the sensor (as `sandbox scan` has it: the same hits, to the bit);
  // then the rays, beside other scans.
  template <typename Scan>
  void Cast(const Eigen::Vector3d& p_WS, bool see_robots, Scan&& scan) {
    sensors::RayFilter filter;
    if (!see_robots) filter.group_mask = scene::kWorldStatic | scene::kWorldMovable;
    const Eigen::Vector3d origin = p_WS.array().round().matrix();
    py::gil_scoped_release release;
    bool change = terrain_ != nullptr;
    if (!change) {
      std::shared_lock<std::shared_mutex> lock(mutex_);
      change = world_.origin() != origin;
    }
    if (change) {
      std::unique_lock<std::shared_mutex> lock(mutex_);
      if (terrain_) {
        terrain_->Update({p_WS}, 0.0, &world_, scene::TerrainStreamer::Wait::kFine);
        terrain_->TakeMessages();
      }
      world_.SetOrigin(origin);
    }
    std::shared_lock<std::shared_mutex> lock(mutex_);
    std::unique_lock<std::mutex> mine(caster_mutex_, std::try_to_lock);
    if (mine.owns_lock()) {
      scan(caster_, filter);
    } else {
      sensors::RayCaster own(1);
      scan(own, filter);
    }
  }

  // Robot r's state changed by `set` (false: refused, ValueError with the
  // state's reason), alone: its nodes and collision body follow.
  template <typename Set>
  void Change(int r, const std::string& what, Set&& set) {
    scene::RobotState& state = *states_[std::size_t(r)];
    py::gil_scoped_release release;
    std::unique_lock<std::shared_mutex> lock(mutex_);
    if (!set(state)) {
      throw std::invalid_argument(what + " of " + state.model().name +
                                  " refused: " + state.last_rejection());
    }
    state.UpdateKinematics();
    world_.UpdateRobot(r, state);
  }

  // Draws the level and the robots as posed, alone (the robots' skins are
  // brought up to date, and one renderer draws one frame at a time).
  void RenderInto(const render::CameraView& view, const render::RenderSettings& settings,
                  render::Frame* frame) {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    if (!renderer_) {
      renderer_ = render::MakeRenderer();
      renderer_->SetLevel(loaded_.level, app::OpenCvTextureDecoder(loaded_.level.limits));
    }
    if (terrain_) {
      terrain_->Update({view.X_WC.translation()}, 0.0, &world_, scene::TerrainStreamer::Wait::kAll);
      terrain_->TakeMessages();
      renderer_->SetTerrain(terrain_->drawn());
    }
    std::vector<const scene::RobotState*> robots;
    for (const auto& state : states_) {
      state->Skin();
      robots.push_back(state.get());
    }
    renderer_->Render(view, {}, robots, settings, frame);
  }

  const app::LoadedLevel loaded_;
  scene::CollisionWorld world_;
  std::vector<std::unique_ptr<scene::RobotState>> states_;
  std::unique_ptr<scene::TerrainStreamer> terrain_;
  mutable std::shared_mutex mutex_;  // scans share the world; poses and tiles change it
  std::mutex caster_mutex_;
  sensors::RayCaster caster_;
  std::unique_ptr<render::Renderer> renderer_;  // made at the first render
};

}  // namespace
}  // namespace sandbox::python

PYBIND11_MODULE(_sandbox, module) {
  using namespace sandbox::python;
  using sandbox::sensors::FaceScan;
  module.doc() =
      "The sandbox in-process: a level, its robots, scans as numpy arrays "
      "(docs/reference/python.md).";
  py::register_exception<sandbox::scene::LevelError>(module, "LevelError", PyExc_RuntimeError)
      .attr("__module__") = "sandbox";

  BindResults(module);
  BindLcm(module);
  BindLockstep(module);

  py::class_<World>(module, "World",
                    "A level loaded in-process (a manifest or a scene file; default: the "
                    "bundled sample level), its robots at their spawn poses.")
      .def(py::init<const std::optional<std::string>&, bool>(), py::arg("level") = py::none(),
           py::arg("isolate") = false)
      .def_property_readonly("name", &World::name)
      .def_property_readonly("robots", &World::robots, "the robots' names")
      .def("set_pose", &World::SetPose, py::arg("robot"), py::arg("position"),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0},
           "Places a robot: position (x, y, z) m, orientation (w, x, y, z), world ENU.")
      .def("set_bones", &World::SetBones, py::arg("robot"), py::arg("values"),
           "All bone values at once, flat in bone-map order (as BONES carries them).")
      .def("pose", &World::GetPose, py::arg("robot"), "((x, y, z), (w, x, y, z))")
      .def("bones", &World::Bones, py::arg("robot"))
      .def("surfaces", &World::Surfaces, "the surface ids' table: id, kind, name, robot, bone")
      .def("face_scan", &World::FaceScan, py::arg("position"),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("resolution") = 1.0,
           py::arg("half_extent") = 25.0, py::arg("aligned") = "body",
           py::arg("see_robots") = false,
           "The six-face scanner at a pose, every face (as sandbox scan --sensor face).")
      .def("ground_scan", &World::GroundScan, py::arg("position"), py::arg("resolution") = 1.0,
           py::arg("half_extent") = 25.0, py::arg("depth") = 100.0, py::arg("see_robots") = false,
           "A height map below a point (as sandbox scan --sensor ground).")
      .def("lidar_scan", &World::LidarScan, py::arg("position"),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("settings") = "",
           py::arg("see_robots") = false,
           "A lidar sweep at a pose; settings: the manifest's lidar keys as TOML on one line, "
           "e.g. 'channels = 32, seed = 7' (default 16 x 1024, -15..15 degrees, 100 m).")
      .def("render", &World::Render, py::arg("camera") = "fixed", py::arg("position") = py::none(),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("robot") = py::none(),
           py::arg("width") = 640, py::arg("height") = 480, py::arg("fov") = 60.0,
           py::arg("kinds") = "color", py::arg("quality") = "high",
           "A camera's images as numpy (as sandbox render): 'fixed' at position and orientation "
           "(x forward, y left, z up), or 'chase', 'trailing', 'payload' following a robot as "
           "posed (default the first); kinds: a comma list of color, depth, segmentation, "
           "normals; quality: fast, high or plain.")
      .def("_time_render", &World::TimeRender, py::arg("position"), py::arg("width"),
           py::arg("height"), py::arg("repeats"),
           "The best of `repeats` renders (colour and depth) timed in C++ alone, seconds (for "
           "the benchmark).")
      .def("_time_face_scan", &World::TimeFaceScan, py::arg("position"), py::arg("resolution"),
           py::arg("half_extent"), py::arg("repeats"),
           "The best of `repeats` face scans timed in C++ alone, seconds (for the benchmark).")
      .def("ray", &World::Ray, py::arg("position"),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("range") = 100.0,
           py::arg("see_robots") = false,
           "One ray along the pose's -z (down at the identity): hit, range, point, normal, "
           "surface.");
}
