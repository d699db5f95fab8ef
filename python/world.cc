// World (the Python class): a level loaded in-process, its robots posed,
// scans at any pose and cameras' images, returned as numpy views
// (python/results.h). The GIL is released while a scan casts or a camera
// draws; scans from several threads run at once (each beyond the first on a
// one-thread caster of its own), poses and renders wait for them.
// docs/reference/python.md.

#include "python/world.h"

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
#include <tuple>
#include <type_traits>
#include <variant>
#include <vector>

#include "app/defaults.h"
#include "app/images.h"
#include "app/loaded_level.h"
#include "python/arguments.h"
#include "python/results.h"
#include "scene/collision_world.h"
#include "scene/robot_state.h"
#include "scene/terrain_streamer.h"
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"
#include "sensors/render/cameras.h"
#include "sensors/render/mounted_camera.h"
#include "sensors/render/renderer.h"
#include "sensors/sensor.h"

namespace py = pybind11;

namespace sandbox::python {
namespace {

py::tuple PoseTuple(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  return py::make_tuple(
      py::make_tuple(X.translation().x(), X.translation().y(), X.translation().z()),
      py::make_tuple(q.w(), q.x(), q.y(), q.z()));
}

py::dict Reading(const sensors::RangeReading& reading) {
  py::dict out;
  out["hit"] = reading.hit;
  out["range"] = reading.range_m;
  out["point"] = py::make_tuple(reading.point_W.x(), reading.point_W.y(), reading.point_W.z());
  out["normal"] = py::make_tuple(reading.normal_W.x(), reading.normal_W.y(), reading.normal_W.z());
  out["surface"] = reading.surface;
  return out;
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
    return PoseTuple(states_[std::size_t(r)]->pose());
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
    const Eigen::Isometry3d X_WS = Pose(position, py::make_tuple(1, 0, 0, 0));
    double best = 1e300;
    for (int i = 0; i < repeats; ++i) {  // what face_scan() does in C++, timed
      const auto start = std::chrono::steady_clock::now();
      const sensors::FaceScanner scanner(FaceConfig(resolution, half_extent, "body"));
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
    return Reading(reading);
  }

  // The declared sensors: (robot, name, type) each, in manifest order.
  std::vector<std::tuple<std::string, std::string, std::string>> Sensors() const {
    std::vector<std::tuple<std::string, std::string, std::string>> sensors;
    for (const sensors::MountedSensor& m : loaded_.sensors) {
      sensors.emplace_back(loaded_.level.robots[std::size_t(m.robot)].name, m.spec.name,
                           std::string(sensors::Info(m.kind).type));
    }
    return sensors;
  }

  // A declared sensor run once, in full, at its robot's pose now (its own
  // robot unseen, as in the loop; the other robots seen unless see_robots is
  // false). A face scan, height map or lidar sweep, or a range reading (dict).
  py::object ScanSensor(const std::string& sensor, const std::optional<std::string>& robot,
                        bool see_robots) {
    const int r = robot ? Robot(*robot) : -1;
    std::vector<const sensors::MountedSensor*> found;
    std::vector<std::string> known;
    for (const sensors::MountedSensor& m : loaded_.sensors) {
      if (r >= 0 && m.robot != r) continue;
      known.push_back(m.spec.name);
      if (m.spec.name == sensor) found.push_back(&m);
    }
    if (found.empty()) Unknown(robot ? "sensor on " + *robot : "sensor", sensor, known);
    if (found.size() > 1) {
      throw py::value_error("sensor '" + sensor + "' is on several robots: give robot");
    }
    if (found.front()->RunsEveryTick()) {  // an instrument
      throw py::value_error("sensor '" + sensor + "' is a " + found.front()->spec.type +
                            " instrument: it measures the robot's motion, not the world; "
                            "read it from Lockstep.step()'s outputs");
    }
    sensors::MountedSensor full = *found.front();
    std::visit(
        [](auto& config) {
          using Config = std::decay_t<decltype(config)>;
          if constexpr (std::is_same_v<Config, sensors::FaceScannerConfig>) {
            config.refresh = sensors::Refresh::kFull;
          }
          if constexpr (std::is_same_v<Config, sensors::FaceScannerConfig> ||
                        std::is_same_v<Config, sensors::GroundScannerConfig> ||
                        std::is_same_v<Config, sensors::LidarConfig>) {
            config.normals = true;
          }
        },
        full.config);
    Eigen::Isometry3d X_WS, X_WR;
    {
      std::shared_lock<std::shared_mutex> lock(mutex_);
      const scene::RobotState& state = *states_[std::size_t(full.robot)];
      X_WS = full.Pose(state);
      X_WR = state.pose();
    }
    sensors::Sensor runner(full);
    Cast(X_WS.translation(), see_robots,
         [&](sensors::RayCaster& caster, const sensors::RayFilter& seen) {
           sensors::RayFilter filter = seen;
           filter.ignore_robot = full.robot;
           runner.Run({world_, caster, filter, X_WS, X_WR, nullptr, 0.0, 0});
         });
    const sensors::SensorOutput& output = runner.output();
    if (const auto* scan = std::get_if<sensors::FaceScan>(&output))
      return py::cast(FaceScanResult{*scan});
    if (const auto* map = std::get_if<sensors::HeightMap>(&output))
      return py::cast(GroundScanResult{*map});
    if (const auto* sweep = std::get_if<sensors::LidarScan>(&output))
      return py::cast(LidarScanResult{*sweep});
    return Reading(std::get<sensors::RangeReading>(output));
  }

  // The declared cameras: (robot, name, kind) each, in manifest order.
  std::vector<std::tuple<std::string, std::string, std::string>> Cameras() const {
    std::vector<std::tuple<std::string, std::string, std::string>> cameras;
    for (const render::MountedCamera& c : loaded_.cameras) {
      cameras.emplace_back(loaded_.level.robots[std::size_t(c.robot)].name, c.spec.name,
                           c.spec.type);
    }
    return cameras;
  }

  // A declared camera's images at its robot's pose now, as the loop draws
  // them (its size, field of view, look and images; a chase camera without
  // lag), without the debug overlay.
  FrameResult RenderCamera(const std::string& camera, const std::optional<std::string>& robot) {
    const int r = robot ? Robot(*robot) : -1;
    const render::MountedCamera* found = nullptr;
    std::vector<std::string> known;
    for (const render::MountedCamera& c : loaded_.cameras) {
      if (r >= 0 && c.robot != r) continue;
      known.push_back(c.spec.name);
      if (c.spec.name == camera) {
        if (found != nullptr) {
          throw py::value_error("camera '" + camera + "' is on several robots: give robot");
        }
        found = &c;
      }
    }
    if (found == nullptr) Unknown(robot ? "camera on " + *robot : "camera", camera, known);
    render::CameraView view = found->view;
    {
      std::shared_lock<std::shared_mutex> lock(mutex_);
      render::ChaseCamera chase(found->chase);
      view.X_WC = found->Pose(*states_[std::size_t(found->robot)], &chase, {}, 0.0);
    }
    FrameResult result;
    py::gil_scoped_release release;
    RenderInto(view, found->look, &result.frame);
    return result;
  }

  // The robot's joints (bones of one value) and their values.
  py::dict Joints(const std::string& robot) const {
    const int r = Robot(robot);
    std::shared_lock<std::shared_mutex> lock(mutex_);
    const scene::RobotState& state = *states_[std::size_t(r)];
    const std::vector<double>& values = state.bone_values();
    py::dict joints;
    std::size_t offset = 0;
    for (const scene::Bone& bone : state.model().bones) {
      if (bone.num_values == 1) joints[py::str(bone.name)] = values[offset];
      offset += std::size_t(bone.num_values);
    }
    return joints;
  }

  // Joint values by name, all or none (as JOINTS applies them).
  void SetJoints(const std::string& robot, const py::dict& values) {
    const int r = Robot(robot);
    const scene::RobotModel& model = loaded_.level.robots[std::size_t(r)];
    std::vector<std::string> joints;
    for (const scene::Bone& bone : model.bones) {
      if (bone.num_values == 1) joints.push_back(bone.name);
    }
    std::vector<std::pair<int, double>> set;
    for (const auto& [key, value] : values) {
      if (!py::isinstance<py::str>(key)) throw py::value_error("joint names must be strings");
      const std::string name = key.cast<std::string>();
      const int b = model.FindBone(name);
      if (b < 0 || model.bones[std::size_t(b)].num_values != 1) Unknown("joint", name, joints);
      const double v = FiniteVector(py::make_tuple(value), 1, "joints['" + name + "']")[0];
      const std::string problem = scene::BoneValuesProblem(model.bones[std::size_t(b)], &v, 1);
      if (!problem.empty()) throw py::value_error("joints['" + name + "']: " + problem);
      set.emplace_back(b, v);
    }
    Change(r, "joint values", [&](scene::RobotState& state) {
      for (const auto& [b, v] : set) {
        if (!state.SetBone(b, &v, 1)) return false;
      }
      return true;
    });
  }

  // The movable actors' names.
  std::vector<std::string> Actors() const {
    std::vector<std::string> names;
    for (const scene::Actor& actor : loaded_.level.actors) {
      if (actor.movable) names.push_back(actor.name);
    }
    return names;
  }

  int MovableActor(const std::string& name) const {
    const int a = loaded_.level.FindActor(name);
    if (a < 0 || !loaded_.level.actors[std::size_t(a)].movable)
      Unknown("movable actor", name, Actors());
    return a;
  }

  void SetActor(const std::string& actor, const py::handle& position,
                const py::handle& orientation) {
    const int a = MovableActor(actor);
    const Eigen::Isometry3d X = Pose(position, orientation);
    py::gil_scoped_release release;
    std::unique_lock<std::shared_mutex> lock(mutex_);
    world_.SetActorPose(a, X);
  }

  py::tuple ActorPose(const std::string& actor) const {
    const int a = MovableActor(actor);
    std::shared_lock<std::shared_mutex> lock(mutex_);
    return PoseTuple(world_.actor_pose(a));
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

void BindWorld(py::module_& module) {
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
           "surface.")
      .def_property_readonly("sensors", &World::Sensors,
                             "the declared sensors: (robot, name, type) each")
      .def("scan", &World::ScanSensor, py::arg("sensor"), py::arg("robot") = py::none(),
           py::arg("see_robots") = true,
           "A declared sensor once, in full, at its robot's pose now (its own robot unseen): a "
           "FaceScan, GroundScan, LidarScan or a range reading (dict).")
      .def_property_readonly("cameras", &World::Cameras,
                             "the declared cameras: (robot, name, kind) each")
      .def("render_camera", &World::RenderCamera, py::arg("camera"), py::arg("robot") = py::none(),
           "A declared camera's images at its robot's pose now, as the loop draws them (without "
           "the debug overlay).")
      .def("joints", &World::Joints, py::arg("robot"),
           "{joint: value}: the robot's bones of one value")
      .def("set_joints", &World::SetJoints, py::arg("robot"), py::arg("values"),
           "Joint values by name ({joint: value}; radians or metres), all or none.")
      .def_property_readonly("actors", &World::Actors, "the movable actors' names")
      .def("set_actor", &World::SetActor, py::arg("actor"), py::arg("position"),
           py::arg("orientation") = std::vector<double>{1, 0, 0, 0},
           "Places a movable actor: position m, orientation (w, x, y, z), world.")
      .def("actor_pose", &World::ActorPose, py::arg("actor"), "((x, y, z), (w, x, y, z))");
}

}  // namespace sandbox::python
