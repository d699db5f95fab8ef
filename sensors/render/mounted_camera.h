#pragma once
// The cameras a level's robots declare ([[robot.camera]] tables), read into
// views and camera rigs once, and where each one is at a robot state.

#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "scene/level.h"
#include "scene/robot_model.h"
#include "scene/robot_state.h"
#include "sensors/render/cameras.h"
#include "sensors/render/debug_overlay.h"
#include "sensors/render/renderer.h"
#include "sensors/render/view.h"

namespace sandbox::render {

enum class CameraKind {
  kChase,     // a lagged spring arm behind the robot
  kTrailing,  // a fixed offset, steered by pan, tilt and zoom
  kPayload,   // on the robot or one of its bones
  kFixed,     // a world pose
};

// A camera declared by a [[robot.camera]] table.
struct MountedCamera {
  scene::SensorSpec spec;  // name, type, mount, X_MS, rate
  CameraKind kind{CameraKind::kChase};
  int robot{-1};
  CameraView view;  // size, field of view, clipping; the pose is set per frame
  ChaseConfig chase;
  double trailing_distance_m{25.0};
  double trailing_height_m{8.0};
  // The look (quality preset and switches) and the images it makes
  // (`images = [...]`; `depth = true` adds depth; payload cameras: colour and depth).
  RenderSettings look;
  bool overlay{false};         // the debug overlay (scanner samples, bone frames, actor bounds)
  double overlay_stub_m{0.0};  // scanner samples as points (0) or stubs this long
  SampleColour overlay_colour{SampleColour::kOccupancy};  // `overlay_colour`

  // The camera pose for a robot state (fixed cameras: their own pose; chase
  // cameras keep their lag in `chase_state`, advanced by dt_s).
  Eigen::Isometry3d Pose(const scene::RobotState& state, ChaseCamera* chase_state,
                         const TrailingCommand& command, double dt_s) const;
};

// Every robot's cameras; throws scene::LevelError naming the manifest, line,
// camera and setting (an unknown type, zero or huge resolution, an unknown key, ...).
std::vector<MountedCamera> MakeRobotCameras(const scene::Level& level);

}  // namespace sandbox::render
