// Conventions against hand-computed poses.

#include "bridge/translation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/geodetic.h"

namespace sandbox::bridge {
namespace {

using Eigen::Quaterniond;
using Eigen::Vector3d;

constexpr double kDeg = M_PI / 180.0;

TEST(TranslationTest, NedPositionAndAttitude) {
  Translation ned{Convention::kNed, {}};
  // 100 m north, 20 m east, 30 m up (down = -30), heading east (yaw 90), level.
  const Eigen::Isometry3d X = ned.ToWorld(Vector3d(100, 20, -30), NedAttitude(0, 0, 90 * kDeg));
  EXPECT_TRUE(X.translation().isApprox(Vector3d(20, 100, 30)));
  // The nose (body x) points east = world +x; the left wing (FLU +y) points
  // north = world +y; up stays up.
  EXPECT_TRUE((X.linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE((X.linear() * Vector3d::UnitY()).isApprox(Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((X.linear() * Vector3d::UnitZ()).isApprox(Vector3d::UnitZ(), 1e-12));
  // Heading north, pitched 10 degrees nose up: the nose points north and up.
  const Eigen::Isometry3d up = ned.ToWorld(Vector3d::Zero(), NedAttitude(0, 10 * kDeg, 0));
  EXPECT_TRUE((up.linear() * Vector3d::UnitX())
                  .isApprox(Vector3d(0, std::cos(10 * kDeg), std::sin(10 * kDeg)), 1e-12));
  // Rolled 30 degrees right wing down: body left (+y FLU) rises.
  const Eigen::Isometry3d rolled = ned.ToWorld(Vector3d::Zero(), NedAttitude(30 * kDeg, 0, 0));
  EXPECT_GT((rolled.linear() * Vector3d::UnitY()).z(), 0.49);
  // And back.
  Vector3d p;
  Quaterniond q;
  ned.FromWorld(X, &p, &q);
  EXPECT_TRUE(p.isApprox(Vector3d(100, 20, -30)));
  EXPECT_LT(q.angularDistance(NedAttitude(0, 0, 90 * kDeg)), 1e-12);
}

TEST(TranslationTest, UnrealIsLeftHandedCentimetres) {
  Translation unreal{Convention::kUnreal, {}};
  // Unreal (x fwd, y right, z up, cm): (100, 200, 300) cm is world (1, -2, 3) m.
  const Eigen::Isometry3d X = unreal.ToWorld(Vector3d(100, 200, 300), Quaterniond::Identity());
  EXPECT_TRUE(X.translation().isApprox(Vector3d(1, -2, 3)));
  // A yaw that turns x towards +y (right) in Unreal turns the nose towards world -y.
  const Quaterniond yaw_right(Eigen::AngleAxisd(90 * kDeg, Vector3d::UnitZ()));
  const Eigen::Isometry3d turned = unreal.ToWorld(Vector3d::Zero(), yaw_right);
  EXPECT_TRUE((turned.linear() * Vector3d::UnitX()).isApprox(-Vector3d::UnitY(), 1e-12));
  EXPECT_NEAR(turned.linear().determinant(), 1.0, 1e-12);
  Vector3d p;
  Quaterniond q;
  unreal.FromWorld(X, &p, &q);
  EXPECT_TRUE(p.isApprox(Vector3d(100, 200, 300)));
}

TEST(TranslationTest, GeodeticLocalTangentPlane) {
  // Origin at 47 N, 8 E, 500 m. One arc second of latitude north is the
  // meridian radius of curvature there (plus the altitude) times the step.
  const double e2 = 0.00669437999014, s47 = std::sin(47.0 * M_PI / 180.0);
  const double meridian = 6378137.0 * (1 - e2) / std::pow(1 - e2 * s47 * s47, 1.5);
  const double north_m = (meridian + 500.0) * (1.0 / 3600.0) * M_PI / 180.0;
  Translation geo{Convention::kGeodetic, {47.0, 8.0, 500.0}};
  const Eigen::Isometry3d north =
      geo.ToWorld(Vector3d(47.0 + 1.0 / 3600.0, 8.0, 500.0), NedAttitude(0, 0, 0));
  EXPECT_NEAR(north.translation().y(), north_m, 1e-3);
  EXPECT_NEAR(north.translation().x(), 0.0, 1e-6);
  EXPECT_NEAR(north.translation().z(), 0.0, 1e-3);  // curvature over 31 m: under 0.1 mm
  // Heading north: nose along world +y, tilted down by the earth's curvature
  // over 31 m (31 / 6.37e6 = 4.9e-6 rad).
  EXPECT_TRUE((north.linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitY(), 1e-5));
  EXPECT_NEAR((north.linear() * Vector3d::UnitX()).z(), -north_m / 6.37e6, 2e-7);
  // Straight up 100 m.
  EXPECT_NEAR(geo.ToWorld(Vector3d(47.0, 8.0, 600.0), NedAttitude(0, 0, 0)).translation().z(),
              100.0, 1e-6);
  // Round trip through ECEF.
  const scene::GeodeticPoint back =
      scene::EcefToGeodetic(scene::GeodeticToEcef({47.123, 8.456, 1234.5}));
  EXPECT_NEAR(back.latitude_deg, 47.123, 1e-9);
  EXPECT_NEAR(back.longitude_deg, 8.456, 1e-9);
  EXPECT_NEAR(back.height_m, 1234.5, 1e-4);
  Vector3d p;
  Quaterniond q;
  geo.FromWorld(north, &p, &q);
  EXPECT_NEAR(p.x(), 47.0 + 1.0 / 3600.0, 1e-10);
  EXPECT_LT(q.angularDistance(Quaterniond::Identity()), 1e-9);
  EXPECT_FALSE(ParseConvention("ecef").has_value());
  EXPECT_EQ(ParseConvention("ned"), Convention::kNed);
}

}  // namespace
}  // namespace sandbox::bridge
