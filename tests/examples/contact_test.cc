// The examples' contact module and rigid body, unit by unit: the distance
// field of the bundled box against the analytic box, the penalty law at one
// point computed by hand, symmetric contact's zero torque (also far from the
// world origin), the friction cap, and the integrator against the closed
// form of its own scheme and against pose differencing.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "examples/contact/penalty_contact.h"
#include "examples/contact/robot_shape.h"
#include "examples/rigid_body/rigid_body.h"

namespace sandbox::examples {
namespace {

const std::string kBox = std::string(SANDBOX_SOURCE_DIR) + "/assets/robots/generated/box.gltf";

// The signed distance of p from the unit cube centred at the origin.
double BoxDistance(const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = p.cwiseAbs() - Eigen::Vector3d::Constant(0.5);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

class BoxShape : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    shape_ = new SignedDistanceField(ReadRobotMesh(kBox), SignedDistanceField::Options{0.02, 0.1});
  }
  static void TearDownTestSuite() { delete shape_; }
  static SignedDistanceField* shape_;
};
SignedDistanceField* BoxShape::shape_ = nullptr;

TEST_F(BoxShape, ReadsTheBundledBoxAsAUnitCube) {
  EXPECT_NEAR((shape_->box_min() - Eigen::Vector3d::Constant(-0.5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((shape_->box_max() - Eigen::Vector3d::Constant(0.5)).norm(), 0.0, 1e-6);
}

TEST_F(BoxShape, MatchesTheAnalyticDistanceNearTheFaces) {
  // Near a face's middle the distance is linear, so trilinear sampling is exact.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> across(-0.35, 0.35), depth(-0.08, 0.08);
  for (int i = 0; i < 2000; ++i) {
    const int axis = i % 3;
    const double side = (i / 3) % 2 ? 1.0 : -1.0;
    Eigen::Vector3d p(across(random), across(random), across(random));
    p[axis] = side * (0.5 + depth(random));
    Eigen::Vector3d gradient;
    const double s = shape_->Distance(p, &gradient);
    ASSERT_NEAR(s, BoxDistance(p), 1e-6) << p.transpose();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    normal[axis] = side;
    ASSERT_NEAR((gradient.normalized() - normal).norm(), 0.0, 1e-6) << p.transpose();
  }
}

TEST_F(BoxShape, DeepInsideAndFarOutsideAreClampedToTheBand) {
  EXPECT_DOUBLE_EQ(shape_->Distance(Eigen::Vector3d::Zero(), nullptr), -0.1);
  EXPECT_DOUBLE_EQ(shape_->Distance(Eigen::Vector3d(0.0, 0.0, 0.8), nullptr), 0.1);
  EXPECT_DOUBLE_EQ(shape_->Distance(Eigen::Vector3d(5.0, 0.0, 0.0), nullptr), 0.1);  // off the grid
}

TEST_F(BoxShape, OnePointGivesTheLawsForceAndItsTorque) {
  ContactLaw law;
  law.margin_m = 0.01, law.stiffness_pa_per_m = 1e5, law.point_area_m2 = 0.0025;
  BodyMotion body;
  body.com_W = Eigen::Vector3d(3.0, -2.0, 1.0);
  ContactAccumulator contact(*shape_, law, body);
  // A ground point 4 mm inside the bottom face, 0.2 m forward and 0.1 m left of the centre.
  const Eigen::Vector3d point(3.2, -1.9, 1.0 - 0.5 + 0.004);
  contact.AddPoint(point, Eigen::Vector3f::Zero());
  const ContactWrench wrench = contact.Result();
  const double expected = 0.0025 * 1e5 * (0.01 + 0.004);  // A k (margin + depth), straight up
  EXPECT_EQ(wrench.points, 1);
  EXPECT_NEAR(wrench.force_W.z(), expected, 1e-9);
  EXPECT_NEAR(wrench.force_W.head<2>().norm(), 0.0, 1e-12);
  const Eigen::Vector3d torque = (point - body.com_W).cross(Eigen::Vector3d(0, 0, expected));
  EXPECT_NEAR((wrench.torque_W - torque).norm(), 0.0, 1e-9);
  EXPECT_NEAR((wrench.centre_of_pressure_W - point).norm(), 0.0, 1e-12);
}

TEST_F(BoxShape, FrictionOpposesSlipAndIsCappedByCoulomb) {
  ContactLaw law;
  law.damping_pa_s_per_m = 0.0, law.friction = 0.5, law.slip_damping_pa_s_per_m = 1e9;
  BodyMotion body;
  body.v_W = Eigen::Vector3d(1.0, 0.0, 0.0);  // sliding forward
  ContactAccumulator contact(*shape_, law, body);
  contact.AddPoint(Eigen::Vector3d(0.0, 0.0, -0.5), Eigen::Vector3f::Zero());  // on the bottom
  const ContactWrench wrench = contact.Result();
  EXPECT_GT(wrench.force_W.z(), 0.0);
  EXPECT_NEAR(wrench.force_W.x(), -0.5 * wrench.force_W.z(), 1e-9);
}

// A box resting on a symmetric grid of ground points: the torque is zero to
// rounding, also a thousand kilometres from the world origin where the old
// platform's torques from absolute coordinates drifted.
void ExpectNoTorqueOnASymmetricGrid(const SignedDistanceField& shape, const Eigen::Vector3d& com) {
  ContactLaw law;
  BodyMotion body;
  body.com_W = com;
  ContactAccumulator contact(shape, law, body);
  const Eigen::Vector3d origin = com;  // a face's origin: the sensor, at the robot
  for (int r = 0; r < 42; ++r) {
    for (int c = 0; c < 42; ++c) {
      contact.AddPoint(
          origin, Eigen::Vector3f(float(-1.025 + 0.05 * c), float(-1.025 + 0.05 * r), -0.495f));
    }
  }
  const ContactWrench wrench = contact.Result();
  EXPECT_EQ(wrench.points, 400);
  EXPECT_NEAR(wrench.force_W.z(), 400 * law.point_area_m2 * law.stiffness_pa_per_m * 0.015, 1e-3);
  EXPECT_LT(wrench.torque_W.norm(), 1e-12 * wrench.force_W.norm()) << wrench.torque_W.transpose();
  EXPECT_LT(wrench.force_W.head<2>().norm(), 1e-12 * wrench.force_W.norm());
}

TEST_F(BoxShape, SymmetricContactGivesZeroTorque) {
  ExpectNoTorqueOnASymmetricGrid(*shape_, Eigen::Vector3d(0.0, 0.0, 0.5));
  ExpectNoTorqueOnASymmetricGrid(*shape_, Eigen::Vector3d(1e6, -1e6, 2000.5));
}

TEST(CompensatedSum, CancelsWhereAPlainSumLosesTheSmallTerm) {
  CompensatedSum sum;
  for (const double v : {1e16, 1.0, -1e16}) sum.Add(Eigen::Vector3d::Constant(v));
  EXPECT_EQ(sum.value().x(), 1.0);
}

TEST(MeshFile, AMissingFileIsAnErrorNamingIt) {
  try {
    ReadRobotMesh("/nowhere/robot.gltf");
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nowhere/robot.gltf"), std::string::npos);
  }
}

TEST(RigidBody, FreeFallFollowsTheSchemesClosedForm) {
  RigidBodyParameters body;
  body.mass_kg = 3.0;
  RigidBodyState state;
  state.p_W = Eigen::Vector3d(1, 2, 100);
  state.v_W = Eigen::Vector3d(0.5, 0, 2);
  const double dt = 0.01;
  const int n = 250;
  for (int i = 0; i < n; ++i)
    Step(body, dt, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), &state);
  // Semi-implicit Euler: z_n = z_0 + n dt v_0 - g dt^2 n (n + 1) / 2.
  EXPECT_NEAR(state.p_W.z(), 100 + n * dt * 2 - 9.81 * dt * dt * n * (n + 1) / 2, 1e-9);
  EXPECT_NEAR(state.p_W.x(), 1 + n * dt * 0.5, 1e-12);
  EXPECT_NEAR(state.v_W.z(), 2 - 9.81 * n * dt, 1e-9);
}

TEST(RigidBody, ASpinAboutAPrincipalAxisStaysAndTurnsAtItsRate) {
  RigidBodyParameters body;
  body.gravity_W.setZero();
  body.inertia_kgm2 = BoxInertia(2.0, Eigen::Vector3d(1, 2, 3));
  RigidBodyState state;
  state.w_B = Eigen::Vector3d(0, 0, 0.5);
  for (int i = 0; i < 100; ++i)
    Step(body, 0.01, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), &state);
  EXPECT_NEAR((state.w_B - Eigen::Vector3d(0, 0, 0.5)).norm(), 0.0, 1e-15);
  const Eigen::AngleAxisd turn(state.R_WB);
  EXPECT_NEAR(turn.angle(), 0.5, 1e-12);
  EXPECT_NEAR((turn.axis() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
}

TEST(RigidBody, PoseDifferencesGiveTheVelocitiesInUse) {
  RigidBodyParameters body;
  body.inertia_kgm2 = BoxInertia(5.0, Eigen::Vector3d(1, 0.5, 0.2));
  body.mass_kg = 5.0;
  RigidBodyState state;
  state.R_WB = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  state.w_B = Eigen::Vector3d(0.3, -1.2, 2.0);
  state.v_W = Eigen::Vector3d(1, 2, 3);
  for (int i = 0; i < 20; ++i) {
    const RigidBodyState before = state;
    Step(body, 0.01, Eigen::Vector3d(1, -2, 3), Eigen::Vector3d(0.1, 0.2, -0.3), &state);
    Eigen::Vector3d v, w;
    VelocitiesFromPoses(before.p_W, before.R_WB, state.p_W, state.R_WB, 0.01, &v, &w);
    ASSERT_NEAR((v - state.v_W).norm(), 0.0, 1e-12);
    ASSERT_NEAR((w - state.R_WB * state.w_B).norm(), 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace sandbox::examples
