#include "sensors/pose_track.h"

#include <cmath>

namespace sandbox::sensors {
namespace {

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The Lagrange basis of nodes s[0..n) and its first two derivatives at s.
struct Basis {
  std::array<double, PoseTrack::kPoses> value{}, first{}, second{};
};
Basis LagrangeBasis(const std::array<double, PoseTrack::kPoses>& nodes, int n, double s) {
  Basis basis;
  for (int j = 0; j < n; ++j) {
    // The product of (s - s_k) over k != j as coefficients c[0] + c[1] s + ...
    std::array<double, PoseTrack::kPoses> c{};
    c[0] = 1.0;
    int degree = 0;
    double denominator = 1.0;
    for (int k = 0; k < n; ++k) {
      if (k == j) continue;
      const double root = nodes[std::size_t(k)];
      for (int d = degree + 1; d > 0; --d)
        c[std::size_t(d)] = c[std::size_t(d - 1)] - root * c[std::size_t(d)];
      c[0] = -root * c[0];
      ++degree;
      denominator *= nodes[std::size_t(j)] - root;
    }
    double value = 0.0, first = 0.0, second = 0.0;
    for (int d = degree; d >= 0; --d) {
      second = second * s + first * 2.0;
      first = first * s + value;
      value = value * s + c[std::size_t(d)];
    }
    basis.value[std::size_t(j)] = value / denominator;
    basis.first[std::size_t(j)] = first / denominator;
    basis.second[std::size_t(j)] = second / denominator;
  }
  return basis;
}

}  // namespace

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d K = Hat(phi);
  if (angle < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  const double a2 = angle * angle;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(angle)) / a2 * K +
         (angle - std::sin(angle)) / (a2 * angle) * K * K;
}

void PoseTrack::Add(double t, const Eigen::Isometry3d& X) {
  if (size_ > 0 && !(t > newest_t())) size_ = 0;
  if (size_ == kPoses) {
    for (int i = 1; i < kPoses; ++i) {
      t_[std::size_t(i - 1)] = t_[std::size_t(i)];
      X_[std::size_t(i - 1)] = X_[std::size_t(i)];
    }
    --size_;
  }
  t_[std::size_t(size_)] = t;
  X_[std::size_t(size_)] = X;
  ++size_;
}

const std::vector<std::int64_t>& PoseSampler::Add(std::int64_t utime, const Eigen::Isometry3d& X) {
  times_.clear();
  if (utime < 0 || utime == last_utime_) return times_;
  const std::int64_t previous = last_utime_;
  last_utime_ = utime;
  if (utime < previous || double(utime - previous) * 1e-6 > max_gap_s_) track_.Clear();
  if (track_.size() == 0) origin_utime_ = utime;
  track_.Add(Seconds(utime), X);
  if (track_.size() < 2) return times_;
  if (rate_hz_ <= 0.0) {
    period_s_ = track_.newest_t() - track_.previous_t();
    times_.push_back(utime);
    return times_;
  }
  period_s_ = 1.0 / rate_hz_;
  // k / rate in (previous, utime], in long double: k 1e6 passes 2^53 for epoch times.
  const long double per_utime = static_cast<long double>(rate_hz_) * 1e-6L;
  const auto k_at = [&](std::int64_t u) {
    return std::int64_t(std::floor(static_cast<long double>(u) * per_utime + 1e-9L));
  };
  for (std::int64_t k = k_at(previous) + 1; k <= k_at(utime); ++k) {
    times_.push_back(
        std::llround(static_cast<long double>(k) * 1e6L / static_cast<long double>(rate_hz_)));
  }
  return times_;
}

FrameMotion PoseTrack::At(double t) const {
  const int n = size_;
  const Eigen::Isometry3d& X_n = X_[std::size_t(n - 1)];
  std::array<double, kPoses> nodes{};
  for (int i = 0; i < n; ++i) nodes[std::size_t(i)] = t_[std::size_t(i)] - newest_t();
  const Basis basis = LagrangeBasis(nodes, n, t - newest_t());
  const Eigen::Matrix3d R_nT = X_n.linear().transpose();
  Eigen::Vector3d dp = Eigen::Vector3d::Zero(), phi = Eigen::Vector3d::Zero();
  FrameMotion motion;
  Eigen::Vector3d phi_rate = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const std::size_t k = std::size_t(i);
    const Eigen::Vector3d offset = X_[k].translation() - X_n.translation();
    const Eigen::Vector3d phi_i =
        i == n - 1 ? Eigen::Vector3d::Zero() : LogSO3(R_nT * X_[k].linear());
    dp += basis.value[k] * offset;
    motion.v_W += basis.first[k] * offset;
    motion.a_W += basis.second[k] * offset;
    phi += basis.value[k] * phi_i;
    phi_rate += basis.first[k] * phi_i;
  }
  motion.p_W = X_n.translation() + dp;
  motion.R_W = X_n.linear() * ExpSO3(phi);
  motion.omega_F = RightJacobianSO3(phi) * phi_rate;
  return motion;
}

}  // namespace sandbox::sensors
