#pragma once
// A robot's poses over the last moments on the loop's clock, for what needs
// the pose at an earlier time: a lidar sweep starts 1 / rotation_hz before
// the tick that publishes it.

#include <Eigen/Geometry>
#include <deque>
#include <utility>

namespace sandbox::sensors {

class PoseHistory {
 public:
  // Keeps at least `keep_s` seconds (and one pose before them).
  explicit PoseHistory(double keep_s = 1.0) : keep_s_(keep_s) {}

  double keep_s() const { return keep_s_; }

  // The pose at loop time t (t never decreasing).
  void Add(double t, const Eigen::Isometry3d& X) {
    if (!poses_.empty() && t <= poses_.back().first) poses_.pop_back();  // same tick again
    poses_.emplace_back(t, X);
    while (poses_.size() > 2 && poses_[1].first <= t - keep_s_) poses_.pop_front();
  }

  // The pose at time t: interpolated between the poses around it (position
  // linear, rotation spherical), the oldest before them, the newest after.
  // Identity when empty.
  Eigen::Isometry3d At(double t) const {
    if (poses_.empty()) return Eigen::Isometry3d::Identity();
    if (t <= poses_.front().first) return poses_.front().second;
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      const auto& [t1, X1] = poses_[i];
      if (t > t1) continue;
      const auto& [t0, X0] = poses_[i - 1];
      const double s = (t - t0) / (t1 - t0);
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.linear() = Eigen::Quaterniond(X0.linear())
                       .slerp(s, Eigen::Quaterniond(X1.linear()))
                       .toRotationMatrix();
      X.translation() = (1.0 - s) * X0.translation() + s * X1.translation();
      return X;
    }
    return poses_.back().second;
  }

 private:
  double keep_s_;
  std::deque<std::pair<double, Eigen::Isometry3d>> poses_;
};

}  // namespace sandbox::sensors
