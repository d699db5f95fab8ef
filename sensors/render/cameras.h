#pragma once
// Where the cameras are: chase (a lagged spring arm behind the robot),
// trailing (a fixed offset turned by pan/tilt/zoom commands), payload
// (mounted on the robot or a bone) and fixed (a world pose). Pure pose math;
// the Renderer draws what they see. Camera frames: x forward, y left, z up.

#include <Eigen/Geometry>

namespace sandbox::render {

// A pose at `p_W` looking at `target_W`, level (its y axis horizontal).
Eigen::Isometry3d LookAt(const Eigen::Vector3d& p_W, const Eigen::Vector3d& target_W);

struct ChaseConfig {
  double arm_length_m{30.0};   // behind the robot
  double arm_height_m{8.0};    // above it
  double position_lag_s{0.3};  // time constant of the arm's end following the robot
  double rotation_lag_s{0.6};  // time constant of the arm turning with the robot's heading
};

// A spring arm: its end follows the point behind and above the robot with a
// first-order lag (exponential, so it never overshoots), and it always looks
// at the robot's origin.
class ChaseCamera {
 public:
  explicit ChaseCamera(const ChaseConfig& config) : config_(config) {}
  // Advances by dt_s towards the robot pose X_WB and returns the camera pose.
  Eigen::Isometry3d Update(const Eigen::Isometry3d& X_WB, double dt_s);

 private:
  ChaseConfig config_;
  bool started_{false};
  Eigen::Vector3d p_W_{Eigen::Vector3d::Zero()};
  double heading_rad_{0.0};
};

struct TrailingCommand {
  double pan_rad{0.0};   // about the robot's up axis, positive to the left
  double tilt_rad{0.0};  // positive: the camera rises and looks down more
  double zoom{1.0};      // > 0; 2 halves the field of view
};

// A fixed offset behind and above the robot, turned by pan and tilt, looking
// at the robot (zoom is for the field of view: ZoomedFov).
Eigen::Isometry3d TrailingPose(const Eigen::Isometry3d& X_WB, double distance_m, double height_m,
                               const TrailingCommand& command);

// The vertical field of view `zoom` times magnified: tan(fov / 2) / zoom.
double ZoomedFov(double fov_y_rad, double zoom);

}  // namespace sandbox::render
