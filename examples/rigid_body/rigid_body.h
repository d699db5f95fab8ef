#pragma once
// A rigid body's 6-DOF motion under gravity and an external wrench:
// semi-implicit (symplectic) Euler with a fixed step. Velocities are updated
// first, then the pose from the new velocities, so that an external module
// differencing two published poses recovers exactly the velocities in use.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sandbox::examples {

struct RigidBodyParameters {
  double mass_kg{1.0};
  Eigen::Vector3d inertia_kgm2{
      Eigen::Vector3d::Ones()};  // principal, about the centre of mass, body axes
  Eigen::Vector3d gravity_W{0.0, 0.0, -9.81};
};

struct RigidBodyState {
  Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};  // centre of mass
  Eigen::Quaterniond R_WB{Eigen::Quaterniond::Identity()};
  Eigen::Vector3d v_W{Eigen::Vector3d::Zero()};
  Eigen::Vector3d w_B{Eigen::Vector3d::Zero()};  // angular velocity, body axes
};

// The principal inertia of a solid box of the given mass and edge lengths.
Eigen::Vector3d BoxInertia(double mass_kg, const Eigen::Vector3d& size_m);

// Advances `state` by dt under gravity, force_W and torque_W (about the
// centre of mass, world axes):
//   v += dt (F / m + g),  p += dt v
//   w += dt I^-1 (tau_B - w x I w),  R = R exp(dt w)
void Step(const RigidBodyParameters& body, double dt, const Eigen::Vector3d& force_W,
          const Eigen::Vector3d& torque_W, RigidBodyState* state);

// The velocities between two poses dt apart, as Step produced them: the
// inverse of its pose update (what a contact module does with published poses).
void VelocitiesFromPoses(const Eigen::Vector3d& p0_W, const Eigen::Quaterniond& R0_WB,
                         const Eigen::Vector3d& p1_W, const Eigen::Quaterniond& R1_WB, double dt,
                         Eigen::Vector3d* v_W, Eigen::Vector3d* w_W);

}  // namespace sandbox::examples
