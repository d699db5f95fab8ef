// Lidar, ground scanner and single ray against analytic scenes.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "scene/level.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

// A level with the 400 m plane z = 0.
scene::Level PlaneLevel(const testing::TempDir& dir) {
  dir.Write("plane.obj",
            "o plane\nv -200 -200 0\nv 200 -200 0\nv 200 200 0\nv -200 200 0\nf 1 2 3 4\n");
  return scene::LoadLevel(
      dir.Write("level.toml", "[[actor]]\nname = \"plane\"\nfile = \"plane.obj\"\n"));
}

class PlaneTest : public ::testing::Test {
 protected:
  PlaneTest() : level_(PlaneLevel(dir_)), world_(level_) {}
  testing::TempDir dir_;
  scene::Level level_;
  scene::CollisionWorld world_;
  RayCaster caster_{2};
};

TEST_F(PlaneTest, LidarBeamsBelowTheHorizonHitAtHeightOverSine) {
  const Lidar lidar(LidarConfig::Uniform(16, -30, 15, 360, 100.0, 10.0));
  LidarScan scan;
  const Isometry3d X(Eigen::Translation3d(1, 2, 10));
  lidar.Sweep(world_, caster_, {}, X, X, &scan);
  ASSERT_EQ(scan.range_m.size(), 16u * 360u);
  for (int c = 0; c < 16; ++c) {
    const double e = (-30.0 + 45.0 * c / 15.0) * M_PI / 180.0;
    for (int k = 0; k < 360; k += 7) {
      const std::size_t i = std::size_t(c) * 360 + std::size_t(k);
      const double expected = e < 0 ? 10.0 / std::sin(-e) : 1e9;
      if (expected <= 100.0) {
        ASSERT_EQ(scan.hit[i], 1) << c << " " << k;
        EXPECT_NEAR(scan.range_m[i], expected, 1e-3);
        EXPECT_NEAR(scan.points_W[i].z(), 0.0, 1e-3);
      } else {
        ASSERT_EQ(scan.hit[i], 0);
        EXPECT_FLOAT_EQ(scan.range_m[i], 100.0f);
      }
    }
  }
  EXPECT_DOUBLE_EQ(scan.time_s[180], 180.0 / (360 * 10.0));
}

TEST_F(PlaneTest, LidarCastsEachStepFromThePoseAtItsTime) {
  // A beam straight down while the sensor moves 10 m along x and turns 90 degrees.
  LidarConfig config;
  config.elevations_rad = {-M_PI / 2, -M_PI / 4};
  config.azimuth_steps = 100;
  const Lidar lidar(config);
  const Isometry3d start(Eigen::Translation3d(0, 0, 10));
  const Isometry3d end =
      Eigen::Translation3d(10, 0, 10) * Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ());
  LidarScan scan;
  lidar.Sweep(world_, caster_, {}, start, end, &scan);
  for (int k = 0; k < 100; ++k) {
    const double s = k / 100.0;
    EXPECT_NEAR(scan.points_W[std::size_t(k)].x(), 10.0 * s, 1e-3)
        << k;  // channel 0, straight down
    // Channel 1 at 45 degrees down: 10 m out along azimuth 2 pi s + (pi / 2) s.
    const double a = 2 * M_PI * s + M_PI / 2 * s;
    const Vector3d expected(10.0 * s + 10.0 * std::cos(a), 10.0 * std::sin(a), 0.0);
    EXPECT_LT((scan.points_W[100 + std::size_t(k)] - expected).norm(), 1e-3) << k;
  }
}

TEST_F(PlaneTest, GroundScannerAndAltimeter) {
  GroundScannerConfig config;
  config.half_extent_m = 5;
  config.depth_m = 20;
  HeightMap map;
  GroundScanner(config).Scan(world_, caster_, {}, Vector3d(3, 4, 12), &map);
  ASSERT_EQ(map.n, 11);
  EXPECT_DOUBLE_EQ(map.corner_W.x(), -2.0);
  for (const double h : map.height_m) EXPECT_NEAR(h, 0.0, 1e-4);
  GroundScanner(config).Scan(world_, caster_, {}, Vector3d(3, 4, 25), &map);  // too high
  for (const double h : map.height_m) EXPECT_TRUE(std::isnan(h));

  const RangeReading down =
      MeasureRange({}, world_, caster_, {}, Isometry3d(Eigen::Translation3d(0, 0, 7.5)));
  EXPECT_TRUE(down.hit);
  EXPECT_NEAR(down.range_m, 7.5, 1e-4);
  EXPECT_NEAR(down.normal_W.z(), 1.0, 1e-6);
  EXPECT_TRUE(down.origin_W.isApprox(Vector3d(0, 0, 7.5)));
  EXPECT_TRUE(down.direction_W.isApprox(Vector3d(0, 0, -1)));
  RangeSensorConfig forward;
  forward.direction_S = Vector3d::UnitX();
  EXPECT_FALSE(
      MeasureRange(forward, world_, caster_, {}, Isometry3d(Eigen::Translation3d(0, 0, 1))).hit);
}

TEST(SensorConfigTest, BadConfigsNameTheField) {
  auto message = [](auto make) {
    try {
      make();
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([] { Lidar(LidarConfig::Uniform(0, -10, 10, 100)); }),
            "channels must be at least 1, got 0");
  EXPECT_EQ(message([] { Lidar(LidarConfig::Uniform(16, -10, 10, 0)); }),
            "azimuth_steps must be positive, got 0");
  EXPECT_EQ(message([] { Lidar(LidarConfig::Uniform(16, -10, 10, 100, -5)); }),
            "range_m must be positive, got -5");
  EXPECT_EQ(message([] { Lidar(LidarConfig::Uniform(4096, -10, 10, 4096)); }),
            "channels x azimuth_steps makes more than 10 million rays");
  GroundScannerConfig ground;
  ground.depth_m = 0;
  EXPECT_NE(message([&] { GroundScanner scanner(ground); }).find("depth_m must be positive"),
            std::string::npos);
  RangeSensorConfig ray;
  ray.direction_S = Vector3d(1, 1, 0);
  EXPECT_EQ(message([&] { ray.ValidateOrThrow(); }), "direction must be a unit vector");
}

}  // namespace
}  // namespace sandbox::sensors
