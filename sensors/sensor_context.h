#pragma once
// What one run of a sensor is given (Sensor::Run in sensors/sensor.h): the
// world and the caster, where the sensor and its robot are now, the robot's
// recent poses, the loop's time and tick, the newest pose's own time stamp,
// the level's geodetic frame and its wind.

#include <Eigen/Geometry>
#include <cstdint>

#include "scene/collision_world.h"
#include "scene/geodetic.h"
#include "scene/wind.h"
#include "sensors/pose_history.h"
#include "sensors/ray_caster.h"

namespace sandbox::sensors {

struct SensorContext {
  const scene::CollisionWorld& world;
  RayCaster& caster;
  RayFilter filter;            // its own robot ignored
  Eigen::Isometry3d X_WS;      // the sensor now
  Eigen::Isometry3d X_WR;      // its robot now
  const PoseHistory* history;  // its robot's recent poses; null: none kept
  double t_s{0.0};             // loop time
  std::int64_t tick{0};
  std::int64_t pose_utime{-1};  // its robot's newest pose's time stamp; -1: none yet
  const scene::LocalTangentPlane* geodetic{nullptr};  // the level's anchor; null: none
  const scene::WindSpec* wind{nullptr};               // the level's [wind]; null: still air
};

}  // namespace sandbox::sensors
