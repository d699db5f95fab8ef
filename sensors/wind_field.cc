#include "sensors/wind_field.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace sandbox::sensors {

DrydenGusts::DrydenGusts(double sigma_m_s, double length_m, std::uint64_t seed)
    : sigma_(sigma_m_s), length_(length_m), random_(seed) {}

Eigen::Vector3d DrydenGusts::Step(double airspeed_m_s, double dt_s) {
  if (sigma_ <= 0.0 || !(dt_s > 0.0)) return Eigen::Vector3d::Zero();
  const double speed = std::max(1.0, airspeed_m_s);
  const double T = length_ / speed, h = dt_s, e = std::exp(-h / T);
  // u: exact AR(1) with variance sigma^2.
  u_ = e * u_ + sigma_ * std::sqrt(1.0 - e * e) * normal_(random_);
  // v, w: T^2 x'' + 2 T x' + x = n, output K (x + sqrt(3) T x').
  Eigen::Matrix2d phi;
  phi << 1.0 + h / T, h, -h / (T * T), 1.0 - h / T;
  phi *= e;
  Eigen::Matrix2d A_inverse;
  A_inverse << -2.0 * T, -T * T, 1.0, 0.0;
  const Eigen::Vector2d B(0.0, 1.0 / (T * T));
  const Eigen::Vector2d G = A_inverse * (phi - Eigen::Matrix2d::Identity()) * B;
  const double noise = std::sqrt(M_PI / h);
  const double K = sigma_ * std::sqrt(length_ / (M_PI * speed));
  v_ = phi * v_ + G * (noise * normal_(random_));
  w_ = phi * w_ + G * (noise * normal_(random_));
  const double root3T = std::sqrt(3.0) * T;
  return {u_, K * (v_[0] + root3T * v_[1]), K * (w_[0] + root3T * w_[1])};
}

}  // namespace sandbox::sensors
