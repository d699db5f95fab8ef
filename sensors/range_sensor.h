#pragma once
// A single ray (rangefinder, altimeter) along a fixed axis of the sensor frame.

#include <Eigen/Geometry>
#include <string>
#include <string_view>

#include "scene/settings.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

struct RangeSensorConfig {
  Eigen::Vector3d direction_S{0.0, 0.0, -1.0};  // unit, in the sensor frame (default: down)
  double range_m{100.0};
  void ValidateOrThrow() const;  // throws std::invalid_argument naming the field

  // The [[robot.sensor]] table's own keys (docs/reference/levels.md); throws scene::LevelError
  // naming the key.
  static RangeSensorConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "100 m"
};

struct RangeReading {
  Eigen::Vector3d origin_W{Eigen::Vector3d::Zero()};      // the ray, in the world frame
  Eigen::Vector3d direction_W{Eigen::Vector3d::UnitZ()};  // unit
  bool hit{false};
  double range_m{0.0};  // to the hit, or range_m when nothing
  Eigen::Vector3d point_W{Eigen::Vector3d::Zero()};
  Eigen::Vector3d normal_W{Eigen::Vector3d::Zero()};
  std::int32_t surface{RayHits::kNoHit};  // surface id of the hit (scene/surface_ids.h)
};

// One ray from sensor pose X_WS.
RangeReading MeasureRange(const RangeSensorConfig& config, const scene::CollisionWorld& world,
                          RayCaster& caster, const RayFilter& filter,
                          const Eigen::Isometry3d& X_WS);

class RangeSensor {
 public:
  using Config = RangeSensorConfig;
  using Output = RangeReading;
  static constexpr std::string_view kType = "ray";  // [[robot.sensor]] type

  explicit RangeSensor(const RangeSensorConfig& config);  // throws std::invalid_argument
  const RangeSensorConfig& config() const { return config_; }
  // The loop's call (sensors/sensor.h): one ray from the sensor as it is now.
  void Run(const SensorContext& at, RangeReading* reading) const;

 private:
  RangeSensorConfig config_;
};

}  // namespace sandbox::sensors
