#pragma once
// The motion of a frame from its newest poses, for the instruments that
// measure it (IMU, air data, GNSS): position, velocity and acceleration in the
// world frame and the angular rate in the frame itself, at any time between
// the poses, as the derivatives of the cubic through the four newest poses
// (fewer at the start: a line through two, a parabola through three).
//
// Positions are fitted as offsets from the newest pose; the rotation as the
// rotation vectors phi_i = Log(R_n^T R_i) from the newest attitude R_n, so
// R(t) = R_n Exp(phi(t)) and the frame's angular rate is J_r(phi) phi'(t)
// (J_r: SO(3)'s right Jacobian). The cubic's value at a pose is that pose;
// its acceleration at the newest pose is within O(h^2) of the true one for a
// smooth motion sampled every h seconds (a constant acceleration and a
// constant-axis, constant-rate rotation are exact).

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

namespace sandbox::sensors {

struct FrameMotion {
  Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};      // position, world frame
  Eigen::Vector3d v_W{Eigen::Vector3d::Zero()};      // velocity
  Eigen::Vector3d a_W{Eigen::Vector3d::Zero()};      // acceleration
  Eigen::Matrix3d R_W{Eigen::Matrix3d::Identity()};  // attitude: world from frame
  Eigen::Vector3d omega_F{Eigen::Vector3d::Zero()};  // angular rate, in the frame
};

class PoseTrack {
 public:
  static constexpr int kPoses = 4;

  // A pose at time t (seconds). A time not after the newest starts the track
  // again from this pose (a clock that restarted).
  void Add(double t, const Eigen::Isometry3d& X);
  void Clear() { size_ = 0; }

  int size() const { return size_; }
  // The newest pose's time, and the one before it (size() >= 2).
  double newest_t() const { return t_[std::size_t(size_ - 1)]; }
  double previous_t() const { return t_[std::size_t(size_ - 2)]; }

  // The motion at time t (size() >= 1): within the poses' span for the
  // accuracy above; outside it, the cubic extrapolated.
  FrameMotion At(double t) const;

 private:
  std::array<double, kPoses> t_{};
  std::array<Eigen::Isometry3d, kPoses> X_{};
  int size_{0};
};

// An instrument's clock: the poses as they come (by their time stamps) and the
// sample times each brings, k / rate_hz for every k in (previous pose, this
// pose] (without a rate, the pose's own time), none at the first pose. A pose
// whose time is not after the previous one, or more than max_gap_s after it,
// starts afresh. Times on the track count from its first pose, so epoch time
// stamps keep their microseconds.
class PoseSampler {
 public:
  PoseSampler(double rate_hz, double max_gap_s) : rate_hz_(rate_hz), max_gap_s_(max_gap_s) {}

  // A pose at time stamp `utime` (us); the sample times it brings (empty for
  // a pose already seen: the same utime again).
  const std::vector<std::int64_t>& Add(std::int64_t utime, const Eigen::Isometry3d& X);
  // The motion at a sample time.
  FrameMotion At(std::int64_t utime) const { return track_.At(Seconds(utime)); }
  // The time a sample stands for: 1 / rate_hz, or the poses' interval without a rate.
  double period_s() const { return period_s_; }

 private:
  double Seconds(std::int64_t utime) const { return double(utime - origin_utime_) * 1e-6; }

  double rate_hz_, max_gap_s_;
  PoseTrack track_;
  std::int64_t last_utime_{-1};
  std::int64_t origin_utime_{0};
  double period_s_{0.0};
  std::vector<std::int64_t> times_;
};

// SO(3)'s exponential and logarithm (rotation vector), and the right Jacobian.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& phi);
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi);

}  // namespace sandbox::sensors
