#include "sensors/render/cameras.h"

#include <cmath>

namespace sandbox::render {

Eigen::Isometry3d LookAt(const Eigen::Vector3d& p_W, const Eigen::Vector3d& target_W) {
  Eigen::Vector3d x = target_W - p_W;
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x);
  if (y.norm() < 1e-9) y = Eigen::Vector3d::UnitY();  // looking straight up or down
  y.normalize();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear().col(0) = x;
  X.linear().col(1) = y;
  X.linear().col(2) = x.cross(y);
  X.translation() = p_W;
  return X;
}

Eigen::Isometry3d ChaseCamera::Update(const Eigen::Isometry3d& X_WB, double dt_s) {
  const Eigen::Vector3d forward = X_WB.linear().col(0);
  const double heading = std::atan2(forward.y(), forward.x());
  if (!started_) {
    heading_rad_ = heading;
  } else {
    // Turn the arm towards the robot's heading by the lagged fraction (shortest way).
    const double k = 1.0 - std::exp(-dt_s / std::max(config_.rotation_lag_s, 1e-6));
    heading_rad_ += k * std::remainder(heading - heading_rad_, 2.0 * M_PI);
  }
  const Eigen::Vector3d target =
      X_WB.translation() + Eigen::Vector3d(-config_.arm_length_m * std::cos(heading_rad_),
                                           -config_.arm_length_m * std::sin(heading_rad_),
                                           config_.arm_height_m);
  if (!started_) {
    p_W_ = target;
    started_ = true;
  } else {
    const double k = 1.0 - std::exp(-dt_s / std::max(config_.position_lag_s, 1e-6));
    p_W_ += k * (target - p_W_);
  }
  return LookAt(p_W_, X_WB.translation());
}

Eigen::Isometry3d TrailingPose(const Eigen::Isometry3d& X_WB, double distance_m, double height_m,
                               const TrailingCommand& command) {
  const Eigen::Vector3d forward = X_WB.linear().col(0);
  const double heading = std::atan2(forward.y(), forward.x()) + command.pan_rad;
  const double elevation = std::atan2(height_m, distance_m) + command.tilt_rad;
  const double range = std::hypot(distance_m, height_m);
  const Eigen::Vector3d offset(-range * std::cos(elevation) * std::cos(heading),
                               -range * std::cos(elevation) * std::sin(heading),
                               range * std::sin(elevation));
  return LookAt(X_WB.translation() + offset, X_WB.translation());
}

double ZoomedFov(double fov_y_rad, double zoom) {
  return 2.0 * std::atan(std::tan(0.5 * fov_y_rad) / zoom);
}

}  // namespace sandbox::render
