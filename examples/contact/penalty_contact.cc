#include "examples/contact/penalty_contact.h"

#include <algorithm>
#include <cmath>

namespace sandbox::examples {

void CompensatedSum::Add(const Eigen::Vector3d& term) {
  for (int i = 0; i < 3; ++i) {
    const double t = sum_[i] + term[i];
    compensation_[i] +=
        std::abs(sum_[i]) >= std::abs(term[i]) ? (sum_[i] - t) + term[i] : (term[i] - t) + sum_[i];
    sum_[i] = t;
  }
}

ContactAccumulator::ContactAccumulator(const SignedDistanceField& shape, const ContactLaw& law,
                                       const BodyMotion& body)
    : shape_(shape), law_(law), body_(body), R_BW_(body.R_WB.toRotationMatrix().transpose()) {}

void ContactAccumulator::AddPoint(const Eigen::Vector3d& origin_W, const Eigen::Vector3f& offset) {
  // The lever arm from offsets: (origin - com) is small, the offset is exact.
  const Eigen::Vector3d r_W = (origin_W - body_.com_W) + offset.cast<double>();
  Eigen::Vector3d gradient_B;
  const double s = shape_.Distance(R_BW_ * r_W, &gradient_B);
  const double depth = law_.margin_m - s;
  if (!(depth > 0.0) || s <= -shape_.band_m()) return;  // clear of the robot, or beyond the band
  const double gradient_norm = gradient_B.norm();
  if (!(gradient_norm > 0.0)) return;
  const Eigen::Vector3d n_W = body_.R_WB * (gradient_B / gradient_norm);
  const Eigen::Vector3d v_W = body_.v_W + body_.w_W.cross(r_W);
  const double approach = v_W.dot(n_W);
  const double normal = std::max(0.0, law_.point_area_m2 * (law_.stiffness_pa_per_m * depth +
                                                            law_.damping_pa_s_per_m * approach));
  Eigen::Vector3d F_W = -normal * n_W;
  const Eigen::Vector3d slip = v_W - approach * n_W;
  Eigen::Vector3d drag = -law_.point_area_m2 * law_.slip_damping_pa_s_per_m * slip;
  const double drag_norm = drag.norm(), cap = law_.friction * normal;
  if (drag_norm > cap) drag *= cap / drag_norm;
  F_W += drag;
  force_.Add(F_W);
  torque_.Add(r_W.cross(F_W));
  pressure_moment_.Add(normal * r_W);
  normal_sum_ += normal;
  ++points_;
  max_depth_ = std::max(max_depth_, depth);
}

ContactWrench ContactAccumulator::Result() const {
  ContactWrench wrench;
  wrench.force_W = force_.value();
  wrench.torque_W = torque_.value();
  wrench.points = points_;
  wrench.max_depth_m = max_depth_;
  wrench.normal_force_n = normal_sum_;
  if (normal_sum_ > 0.0) {
    wrench.centre_of_pressure_W = body_.com_W + pressure_moment_.value() / normal_sum_;
  }
  return wrench;
}

}  // namespace sandbox::examples
