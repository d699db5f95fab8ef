#pragma once
// The sensors a robot carries, as one family. A [[robot.sensor]] table's
// `type` is parsed once into a SensorKind and its keys into that kind's
// config (MakeRobotSensors); a Sensor is made once from it, and each run
// gives one output value, a SensorOutput. The bridge publishes any output
// through one call (bridge::RobotOutputs::Publish).
//
// Adding a kind (docs/how-to/add-a-sensor.md): its class (with Config,
// Output, Run), then one line in each of the lists below, then its publish
// function in bridge/outputs.cc.

#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "scene/level.h"
#include "scene/robot_model.h"
#include "scene/robot_state.h"
#include "sensors/air_data.h"
#include "sensors/face_scanner.h"
#include "sensors/gnss.h"
#include "sensors/ground_scanner.h"
#include "sensors/imu.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

// The kinds, in the order of SensorClasses.
enum class SensorKind { kFace, kGround, kLidar, kRange, kImu, kGnss, kAirData };

// One class a kind. Each has `kType` (its manifest name), `Config` (with
// static Read, Summary and ValidateOrThrow), `Output` (a type of its own) and
// `void Run(const SensorContext&, Output*)` (const, or not for a kind that
// keeps state between runs); `double history_s() const` when it needs its
// robot's earlier poses. A Config with a `rate_hz` member samples on its own
// clock: it is given the table's rate_hz and run every tick.
template <typename... Classes>
struct SensorClassList {
  using Any = std::variant<Classes...>;
  using Config = std::variant<typename Classes::Config...>;
  using Output = std::variant<typename Classes::Output...>;
};
using SensorClasses =
    SensorClassList<FaceScanner, GroundScanner, Lidar, RangeSensor, Imu, Gnss, AirData>;

// How the manifest names each kind and where it publishes.
struct SensorKindInfo {
  SensorKind kind;
  std::string_view type;     // [[robot.sensor]] type = "...": the class's kType
  std::string_view channel;  // after "<ROBOT>/", unless the table sets `channel`
  bool shares_channel;       // several on one robot may share it (messages name the sensor)
};
inline constexpr std::array<SensorKindInfo, 7> kSensorKinds{{
    {SensorKind::kFace, FaceScanner::kType, "SCAN_FACE", false},
    {SensorKind::kGround, GroundScanner::kType, "GROUND", false},
    {SensorKind::kLidar, Lidar::kType, "LIDAR", false},
    {SensorKind::kRange, RangeSensor::kType, "RANGE", true},
    {SensorKind::kImu, Imu::kType, "IMU", true},
    {SensorKind::kGnss, Gnss::kType, "GNSS", true},
    {SensorKind::kAirData, AirData::kType, "AIR_DATA", true},
}};

using SensorConfig = SensorClasses::Config;
using SensorOutput = SensorClasses::Output;

const SensorKindInfo& Info(SensorKind kind);
// The kind a table's type names; throws scene::LevelError naming the known ones.
SensorKind ParseSensorKind(const scene::SensorSpec& spec);
// The channel a sensor publishes on, after "<ROBOT>/": its `channel`, or its kind's.
std::string OutputChannel(const scene::SensorSpec& spec);

// A sensor declared by a [[robot.sensor]] table, its settings read.
struct MountedSensor {
  scene::SensorSpec spec;  // name, type, mount, X_MS, rate, channel
  SensorKind kind{SensorKind::kFace};
  int robot{-1};        // index into Level::robots
  std::string channel;  // OutputChannel(spec)
  SensorConfig config;  // the alternative of `kind`

  // X_WS: the robot's pose, the mount node's pose and the mounting offset.
  Eigen::Isometry3d Pose(const scene::RobotState& state) const { return state.MountPose(spec); }
  // "face 51x51x6 at 1 m on body at 10 Hz"
  std::string Describe() const;
  // Run every tick whatever its rate (it samples on its own clock).
  bool RunsEveryTick() const;
};

// Every robot's sensors. Throws scene::LevelError naming the manifest, the line,
// the sensor and the setting: an unknown type or key, a wrong type, a value its
// config rejects (zero or negative resolution, a grid over its sample budget, ...).
std::vector<MountedSensor> MakeRobotSensors(const scene::Level& level);

// One sensor, made once; Run fills its output in place (a face scan keeps the
// faces it did not refresh; buffers are reused).
class Sensor {
 public:
  explicit Sensor(const MountedSensor& mounted);

  const MountedSensor& mounted() const { return *mounted_; }
  SensorKind kind() const { return mounted_->kind; }
  // Runs once at `at` and returns the output, kept until the next run.
  const SensorOutput& Run(const SensorContext& at);
  const SensorOutput& output() const { return output_; }
  // The kind's class, or null for another kind.
  template <typename Class>
  const Class* get() const {
    return std::get_if<Class>(&sensor_);
  }
  // How long its robot's poses must be kept for it (0: not at all).
  double history_s() const;

 private:
  const MountedSensor* mounted_;  // outlives the sensor
  SensorClasses::Any sensor_;
  SensorOutput output_;
};

}  // namespace sandbox::sensors
