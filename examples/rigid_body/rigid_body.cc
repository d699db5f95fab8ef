#include "examples/rigid_body/rigid_body.h"

#include <cmath>

namespace sandbox::examples {

Eigen::Vector3d BoxInertia(double mass_kg, const Eigen::Vector3d& size_m) {
  const Eigen::Vector3d s2 = size_m.cwiseProduct(size_m);
  return mass_kg / 12.0 * Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
}

void Step(const RigidBodyParameters& body, double dt, const Eigen::Vector3d& force_W,
          const Eigen::Vector3d& torque_W, RigidBodyState* state) {
  state->v_W += dt * (force_W / body.mass_kg + body.gravity_W);
  state->p_W += dt * state->v_W;
  const Eigen::Vector3d torque_B = state->R_WB.conjugate() * torque_W;
  const Eigen::Vector3d& I = body.inertia_kgm2;
  const Eigen::Vector3d& w = state->w_B;
  state->w_B += dt * (torque_B - w.cross(I.cwiseProduct(w))).cwiseQuotient(I);
  const double angle = dt * state->w_B.norm();
  if (angle > 0.0) {
    state->R_WB =
        state->R_WB * Eigen::Quaterniond(Eigen::AngleAxisd(angle, state->w_B.normalized()));
    state->R_WB.normalize();
  }
}

void VelocitiesFromPoses(const Eigen::Vector3d& p0_W, const Eigen::Quaterniond& R0_WB,
                         const Eigen::Vector3d& p1_W, const Eigen::Quaterniond& R1_WB, double dt,
                         Eigen::Vector3d* v_W, Eigen::Vector3d* w_W) {
  *v_W = (p1_W - p0_W) / dt;
  Eigen::Quaterniond delta_B = R0_WB.conjugate() * R1_WB;  // R1 = R0 exp(dt w_B)
  if (delta_B.w() < 0.0) delta_B.coeffs() *= -1.0;         // the short way round
  const Eigen::AngleAxisd turn(delta_B);
  *w_W = R0_WB * (turn.axis() * (turn.angle() / dt));
}

}  // namespace sandbox::examples
