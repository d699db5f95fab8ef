#pragma once
// Penalty contact from scan points: every world point a scanner saw that lies
// inside the robot's shape (or within the safety margin of its surface)
// pushes the robot out with a spring-damper law, and drags it with friction.
// Forces and torques about the centre of mass are summed in a fixed order
// with compensated sums, so symmetric contact gives zero torque to rounding.
//
// The law, per point (docs/how-to/contact.md): with s the signed distance of the
// point from the robot's surface (negative inside), n the surface's outward
// normal there, v the robot's velocity at the point and A the area a scan
// point stands for (the scanner's resolution squared):
//   depth  d   = margin - s                      (contact when d > 0)
//   normal F_n = A (k d + c (v . n)), at least 0 (it pushes, never pulls)
//   slip   v_t = v - (v . n) n
//   drag   F_t = -A c_t v_t, at most mu F_n long (Coulomb)
//   force on the robot F = -F_n n + F_t, torque (p - com) x F.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "examples/contact/robot_shape.h"

namespace sandbox::examples {

struct ContactLaw {
  double margin_m{0.01};                // points this far outside the surface touch
  double stiffness_pa_per_m{1e5};       // k: pressure per metre of depth
  double damping_pa_s_per_m{5e3};       // c: pressure per m/s of approach
  double friction{0.6};                 // mu: Coulomb coefficient
  double slip_damping_pa_s_per_m{2e3};  // c_t: below the Coulomb cap
  double point_area_m2{0.0025};         // A
};

// The robot's motion: centre of mass and orientation in the world, and its
// velocities (world frame).
struct BodyMotion {
  Eigen::Vector3d com_W{Eigen::Vector3d::Zero()};
  Eigen::Quaterniond R_WB{Eigen::Quaterniond::Identity()};
  Eigen::Vector3d v_W{Eigen::Vector3d::Zero()};
  Eigen::Vector3d w_W{Eigen::Vector3d::Zero()};
};

// A sum of vectors with Neumaier's compensation: the result does not depend
// on the terms' magnitudes cancelling in a lucky order.
class CompensatedSum {
 public:
  void Add(const Eigen::Vector3d& term);
  Eigen::Vector3d value() const { return sum_ + compensation_; }

 private:
  Eigen::Vector3d sum_{Eigen::Vector3d::Zero()}, compensation_{Eigen::Vector3d::Zero()};
};

struct ContactWrench {
  Eigen::Vector3d force_W{Eigen::Vector3d::Zero()};
  Eigen::Vector3d torque_W{Eigen::Vector3d::Zero()};                     // about the centre of mass
  Eigen::Vector3d centre_of_pressure_W{Eigen::Vector3d::Constant(NAN)};  // NaN without contact
  int points{0};                                                         // scan points in contact
  double max_depth_m{0.0};
  double normal_force_n{0.0};  // sum of F_n
};

// Accumulates the contact of one pose, one scan point at a time.
class ContactAccumulator {
 public:
  ContactAccumulator(const SignedDistanceField& shape, const ContactLaw& law,
                     const BodyMotion& body);

  // One occupied scan point at origin_W + offset (a face's double origin and
  // its float offset, kept apart so that lever arms stay exact far from the
  // world origin).
  void AddPoint(const Eigen::Vector3d& origin_W, const Eigen::Vector3f& offset);

  ContactWrench Result() const;

 private:
  const SignedDistanceField& shape_;
  ContactLaw law_;
  BodyMotion body_;
  Eigen::Matrix3d R_BW_;
  CompensatedSum force_, torque_, pressure_moment_;
  double normal_sum_{0.0};
  int points_{0};
  double max_depth_{0.0};
};

}  // namespace sandbox::examples
