#pragma once
// The cameras of `sandbox run`, directed each tick: every camera follows its
// robot (a chase camera's lag advances every tick, seen or not), is steered
// by <ROBOT>/CAMERA and the live view's keys, and the ones that are due
// become render jobs for the FramePipeline (copies; the loop never waits).
// The live view shows the camera the keys chose, or the one a robot's
// CAMERA command chose last. Threads: the loop thread.

#include <cstdint>
#include <string>
#include <vector>

#include "app/frame_pipeline.h"
#include "app/live_view.h"
#include "app/rate_schedule.h"
#include "bridge/robot_feed.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/render/mounted_camera.h"
#include "sensors/sensor.h"

namespace sandbox::app {

class CameraDirector {
 public:
  // `cameras` (and `level`) must outlive the director. Cameras without a rate run at 30 Hz.
  CameraDirector(const scene::Level& level, const std::vector<render::MountedCamera>& cameras);

  // What the cameras see this tick; indexed like Level::robots.
  struct Shot {
    double t_s{0.0};
    std::int64_t tick{0};
    std::int64_t utime{0};                        // the tick's clock, as inputs are stamped
    std::vector<scene::RobotState*> robots;       // skinned when a frame is due
    std::vector<const bridge::RobotFeed*> feeds;  // steering and camera choice
    const scene::CollisionWorld* world{nullptr};
    const std::vector<sensors::Sensor>* sensors{nullptr};  // face scans for overlays
    std::shared_ptr<const scene::TileList> terrain;        // the terrain tiles to draw
  };
  // Moves every camera and submits the due ones to `frames` (null: none):
  // all of them when `write`, the live view's when `live`. Returns the jobs submitted.
  int Direct(const Shot& shot, FramePipeline* frames, bool write, bool live);

  // The live view's state: its camera, the keys' steering, overlay, pause, quit.
  ViewControls& controls() { return controls_; }
  const ViewControls& controls() const { return controls_; }
  const std::string& live_camera() const;

 private:
  struct CameraRun {
    const render::MountedCamera* camera;
    render::ChaseCamera chase;
    RateSchedule schedule;
    double last_s{-1.0};
  };
  // The robot's CAMERA choice, when it changed since last tick.
  void FollowCameraChoice(const Shot& shot);
  // Overlay marks for the camera's robot: its face scans, bone frames, movable actors' bounds.
  void AddOverlay(const CameraRun& run, const Shot& shot, RenderJob* job) const;

  const scene::Level& level_;
  std::vector<CameraRun> runs_;
  ViewControls controls_;
  std::string last_choice_;
};

}  // namespace sandbox::app
