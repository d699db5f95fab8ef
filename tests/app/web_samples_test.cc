#include "app/web_samples.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/collision_world.h"
#include "scene/robot_state.h"
#include "tests/test_util.h"

namespace sandbox::app {
namespace {

using sensors::MountedSensor;
using sensors::Sensor;

// The wing over the sample terrain with one sensor of each kind, each run once.
class WebSamplesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::filesystem::path assets = std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets";
    level_ = scene::LoadLevel(dir_.Write(
        "level.toml",
        "[[actor]]\nname = \"terrain\"\nfile = \"" +
            (assets / "sample/generated/terrain.gltf").string() +
            "\"\n[[robot]]\nname = \"W\"\nfile = \"" +
            (assets / "robots/generated/flying_wing.gltf").string() +
            "\"\nbones = [\"root\"]\nposition = [10, -20, 40]\nrpy_deg = [0, 10, 30]\n"
            "[[robot.sensor]]\nname = \"box\"\ntype = \"face\"\nrefresh = \"full\"\n"
            "resolution_m = 2\nhalf_extent_m = 40\n"
            "[[robot.sensor]]\nname = \"below\"\ntype = \"ground\"\n"
            "[[robot.sensor]]\nname = \"spin\"\ntype = \"lidar\"\nchannels = 16\n"
            "azimuth_steps = 256\nrpy_deg = [0, 20, 0]\n"
            "[[robot.sensor]]\nname = \"alt\"\ntype = \"ray\"\nrange_m = 200\n"));
    mounted_ = sensors::MakeRobotSensors(level_);
    const scene::CollisionWorld world(level_);
    sensors::RayCaster caster(1);
    const scene::RobotState state(level_.robots[0]);
    sensors::RayFilter filter;
    filter.ignore_robot = 0;
    for (const MountedSensor& m : mounted_) {
      sensors_.emplace_back(m);
      sensors_.back().Run({world, caster, filter, m.Pose(state), state.pose(), nullptr, 0.0, 0});
    }
  }

  testing::TempDir dir_;
  scene::Level level_;
  std::vector<MountedSensor> mounted_;
  std::vector<Sensor> sensors_;
  const Eigen::Vector3d origin_{8.0, -16.0, 0.0};
};

Eigen::Vector3d Point(const web::StreamState::Samples& samples, std::size_t i,
                      const Eigen::Vector3d& origin) {
  return origin + Eigen::Vector3d(samples.xyz[3 * i], samples.xyz[3 * i + 1], samples.xyz[3 * i + 2]);
}

TEST_F(WebSamplesTest, AFaceScansSamplesAreItsVisitedPointsWithWhatTheyHit) {
  const auto& scan = std::get<sensors::FaceScan>(sensors_[0].output());
  const web::StreamState::Samples samples = ViewSamples(sensors_[0], "W", origin_, 1'000'000);
  EXPECT_EQ(samples.robot, "W");
  EXPECT_EQ(samples.sensor, "box");
  EXPECT_EQ(samples.type, "face");
  std::size_t i = 0, hits = 0;
  for (int f = 0; f < 6; ++f) {
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    for (std::size_t k = 0; k < face.occupancy.size(); ++k, ++i) {
      ASSERT_LT(i, samples.hit.size());
      EXPECT_LT((Point(samples, i, origin_) - scan.PointW(f, k)).norm(), 1e-4);
      EXPECT_EQ(samples.hit[i], face.occupancy[k] == sensors::kOccupied ? 1 : 0);
      EXPECT_EQ(samples.surface[i], face.surface[k]);
      hits += samples.hit[i];
    }
  }
  EXPECT_EQ(i, samples.hit.size());  // a full scan: every sample visited
  EXPECT_EQ(samples.xyz.size(), 3 * i);
  EXPECT_GT(hits, 100u);  // the terrain below
  // Over a budget, every k-th: at most the budget, spread over all faces.
  const web::StreamState::Samples thin = ViewSamples(sensors_[0], "W", origin_, 1000);
  EXPECT_LE(thin.hit.size(), 1000u);
  EXPECT_GT(thin.hit.size(), 900u);
}

TEST_F(WebSamplesTest, GroundLidarAndRangeSamplesAreTheirPoints) {
  const auto& map = std::get<sensors::HeightMap>(sensors_[1].output());
  const web::StreamState::Samples ground = ViewSamples(sensors_[1], "W", origin_, 1'000'000);
  std::size_t with_ground = 0;
  for (const double h : map.height_m) with_ground += std::isfinite(h);
  ASSERT_EQ(ground.hit.size(), with_ground);
  ASSERT_GT(with_ground, 0u);
  // The first with ground: at its row and column, at its height.
  std::size_t k = 0;
  while (!std::isfinite(map.height_m[k])) ++k;
  const Eigen::Vector3d expected(map.corner_W.x() + double(k % std::size_t(map.n)) * map.resolution_m,
                                 map.corner_W.y() + double(k / std::size_t(map.n)) * map.resolution_m,
                                 map.height_m[k]);
  EXPECT_LT((Point(ground, 0, origin_) - expected).norm(), 1e-4);
  EXPECT_EQ(ground.surface[0], map.surface[k]);

  const auto& lidar = std::get<sensors::LidarScan>(sensors_[2].output());
  const web::StreamState::Samples all = ViewSamples(sensors_[2], "W", origin_, 1'000'000);
  ASSERT_EQ(all.hit.size(), lidar.points_W.size());
  for (std::size_t i = 0; i < lidar.points_W.size(); i += 97) {
    EXPECT_LT((Point(all, i, origin_) - lidar.points_W[i]).norm(), 1e-4);
    EXPECT_EQ(all.hit[i], lidar.hit[i]);
    EXPECT_EQ(all.surface[i], lidar.surface[i]);
  }
  const web::StreamState::Samples thin = ViewSamples(sensors_[2], "W", origin_, 1000);
  EXPECT_LE(thin.hit.size(), 1000u);
  EXPECT_LT((Point(thin, 1, origin_) - lidar.points_W[(lidar.points_W.size() + 999) / 1000]).norm(),
            1e-4);

  const auto& range = std::get<sensors::RangeReading>(sensors_[3].output());
  const web::StreamState::Samples ray = ViewSamples(sensors_[3], "W", origin_, 1000);
  ASSERT_EQ(ray.hit.size(), 1u);
  EXPECT_EQ(ray.hit[0], range.hit ? 1 : 0);
  EXPECT_TRUE(range.hit);  // 40 m over the terrain, looking down
  EXPECT_LT((Point(ray, 0, origin_) - range.point_W).norm(), 1e-4);
}

}  // namespace
}  // namespace sandbox::app
