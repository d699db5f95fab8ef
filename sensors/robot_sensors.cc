#include "sensors/robot_sensors.h"

#include <cmath>
#include <stdexcept>

namespace sandbox::sensors {
namespace {

using scene::LevelError;
using scene::SensorSpec;

SensorConfig ReadConfig(const SensorSpec& spec) {
  scene::SettingsReader read(spec.settings);
  SensorConfig config;
  if (spec.type == "face") {
    FaceScannerConfig face;
    face.resolution_m = read.Number("resolution_m", face.resolution_m);
    face.half_extent_m = read.Number("half_extent_m", face.half_extent_m);
    const std::string refresh = read.Text("refresh", "six_stage");
    if (refresh == "full") {
      face.refresh = Refresh::kFull;
    } else if (refresh == "six_stage") {
      face.refresh = Refresh::kSixStage;
    } else if (refresh == "twelve_stage") {
      face.refresh = Refresh::kTwelveStage;
    } else {
      read.Fail("refresh",
                "'refresh' must be full, six_stage or twelve_stage, got '" + refresh + "'");
    }
    const std::string aligned = read.Text("aligned", "body");
    if (aligned != "body" && aligned != "world") {
      read.Fail("aligned", "'aligned' must be body or world, got '" + aligned + "'");
    }
    face.alignment = aligned == "body" ? Alignment::kBody : Alignment::kWorld;
    config = face;
  } else if (spec.type == "ground") {
    GroundScannerConfig ground;
    ground.resolution_m = read.Number("resolution_m", ground.resolution_m);
    ground.half_extent_m = read.Number("half_extent_m", ground.half_extent_m);
    ground.depth_m = read.Number("depth_m", ground.depth_m);
    config = ground;
  } else if (spec.type == "lidar") {
    LidarConfig lidar;
    if (read.Has("elevations_deg")) {
      for (const double deg : read.Numbers("elevations_deg")) {
        lidar.elevations_rad.push_back(deg * M_PI / 180.0);
      }
    } else {
      const int channels = read.Whole("channels", 16);
      if (channels < 1) read.Fail("channels", "'channels' must be at least 1");
      lidar = LidarConfig::Uniform(channels, read.Number("min_elevation_deg", -15.0),
                                   read.Number("max_elevation_deg", 15.0), 1024);
    }
    lidar.azimuth_steps = read.Whole("azimuth_steps", 1024);
    lidar.range_m = read.Number("range_m", 100.0);
    lidar.rotation_hz = read.Number("rotation_hz", 10.0);
    config = lidar;
  } else {
    RangeSensorConfig ray;
    const std::vector<double> direction = read.Numbers("direction");
    if (!direction.empty()) {
      if (direction.size() != 3) read.Fail("direction", "'direction' must be [x, y, z]");
      ray.direction_S = Eigen::Vector3d(direction[0], direction[1], direction[2]).normalized();
    }
    ray.range_m = read.Number("range_m", ray.range_m);
    config = ray;
  }
  read.RejectUnknownKeys(spec.type + " sensor");
  // The config's own checks, named with the sensor.
  try {
    std::visit([](const auto& c) { c.ValidateOrThrow(); }, config);
  } catch (const std::invalid_argument& error) {
    throw LevelError(spec.Where() + error.what());
  }
  return config;
}

}  // namespace

Eigen::Isometry3d MountedSensor::Pose(const scene::RobotState& state) const {
  const Eigen::Isometry3d X_BM =
      spec.mount_node < 0
          ? Eigen::Isometry3d::Identity()
          : scene::RigidPart(state.node_poses_B()[static_cast<std::size_t>(spec.mount_node)]);
  return state.pose() * X_BM * spec.X_MS;
}

Eigen::Isometry3d MountedCamera::Pose(const scene::RobotState& state, ChaseCamera* chase_state,
                                      const TrailingCommand& command, double dt_s) const {
  if (spec.type == "chase") return chase_state->Update(state.pose(), dt_s);
  if (spec.type == "trailing") {
    return TrailingPose(state.pose(), trailing_distance_m, trailing_height_m, command);
  }
  if (spec.type == "fixed") return spec.X_MS;
  const Eigen::Isometry3d X_BM =
      spec.mount_node < 0
          ? Eigen::Isometry3d::Identity()
          : scene::RigidPart(state.node_poses_B()[static_cast<std::size_t>(spec.mount_node)]);
  return state.pose() * X_BM * spec.X_MS;
}

std::vector<MountedCamera> MakeRobotCameras(const scene::Level& level) {
  std::vector<MountedCamera> cameras;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    for (const scene::SensorSpec& spec : level.robots[r].cameras) {
      scene::SettingsReader read(spec.settings);
      MountedCamera camera;
      camera.spec = spec;
      camera.robot = static_cast<int>(r);
      camera.view.width = read.Whole("width", 640);
      camera.view.height = read.Whole("height", 480);
      camera.view.fov_y_rad = read.Number("fov_deg", 60.0) * M_PI / 180.0;
      camera.view.near_m = read.Number("near_m", 0.1);
      camera.view.far_m = read.Number("far_m", 2000.0);
      camera.chase.arm_length_m = read.Number("arm_length_m", camera.chase.arm_length_m);
      camera.chase.arm_height_m = read.Number("arm_height_m", camera.chase.arm_height_m);
      camera.chase.position_lag_s = read.Number("position_lag_s", camera.chase.position_lag_s);
      camera.chase.rotation_lag_s = read.Number("rotation_lag_s", camera.chase.rotation_lag_s);
      camera.trailing_distance_m = read.Number("distance_m", camera.trailing_distance_m);
      camera.trailing_height_m = read.Number("height_m", camera.trailing_height_m);
      camera.depth = read.Flag("depth", spec.type == "payload");
      camera.overlay = read.Flag("overlay", false);
      camera.overlay_stub_m = read.Number("overlay_stub_m", 0.0);
      if (!(camera.overlay_stub_m >= 0.0 && camera.overlay_stub_m <= 100.0)) {
        throw LevelError(spec.Where() + "overlay_stub_m must be 0 (points) to 100 m");
      }
      read.RejectUnknownKeys(spec.type + " camera");
      try {
        camera.view.ValidateOrThrow();
      } catch (const std::invalid_argument& error) {
        throw LevelError(spec.Where() + error.what());
      }
      cameras.push_back(std::move(camera));
    }
  }
  return cameras;
}

std::vector<MountedSensor> MakeRobotSensors(const scene::Level& level) {
  std::vector<MountedSensor> sensors;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    for (const SensorSpec& spec : level.robots[r].sensors) {
      MountedSensor sensor;
      sensor.spec = spec;
      sensor.robot = static_cast<int>(r);
      sensor.config = ReadConfig(spec);
      sensors.push_back(std::move(sensor));
    }
  }
  return sensors;
}

}  // namespace sandbox::sensors
