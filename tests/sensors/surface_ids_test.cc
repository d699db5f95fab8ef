// What a sample hit: each actor's samples in a face scan of the whole sample
// level equal a scan of a world holding that actor alone; normals on a plane
// of known tilt; the id table names the actors, the robots' bone groups and
// the terrain tiles as they come and go.

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <sstream>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/terrain_tile.h"
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/ray_caster.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

Isometry3d At(double x, double y, double z, double yaw = 0.0) {
  Isometry3d X(Eigen::AngleAxisd(yaw, Vector3d::UnitZ()));
  X.translation() = Vector3d(x, y, z);
  return X;
}

TEST(SurfaceIdsTest, EachActorsSamplesEqualAScanOfThatActorAlone) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  FaceScannerConfig config;
  config.refresh = Refresh::kFull;
  config.resolution_m = 0.5;
  const FaceScanner scanner(config);
  RayCaster caster(2);
  RayFilter own;
  own.ignore_robot = 0;
  // Beside the tower, over the rocks and at the lake's edge (as ../shared's
  // levels are not needed: the sample level has five collision actors).
  const std::vector<Isometry3d> poses = {At(-25, 40, 12, 0.3), At(10, -5, 6, 1.1),
                                         At(-60, -50, 6, -0.4)};
  std::set<std::int32_t> seen;
  int compared = 0;
  for (const Isometry3d& X_WS : poses) {
    FaceScan all = scanner.EmptyScan();
    scanner.Scan(world, caster, own, X_WS, 0, &all);
    for (std::size_t a = 0; a < level.actors.size(); ++a) {
      if (!level.actors[a].collision) continue;
      const std::int32_t id = world.surface_ids().actor(int(a));
      scene::Level alone = level;  // the same actors, only actor a with collision
      for (std::size_t b = 0; b < alone.actors.size(); ++b) alone.actors[b].collision = b == a;
      alone.robots.clear();
      const scene::CollisionWorld alone_world(alone);
      FaceScan one = scanner.EmptyScan();
      scanner.Scan(alone_world, caster, {}, X_WS, 0, &one);
      for (int f = 0; f < 6; ++f) {
        const ScanFace& full = all.faces[std::size_t(f)];
        const ScanFace& only = one.faces[std::size_t(f)];
        for (std::size_t k = 0; k < full.surface.size(); ++k) {
          if (full.surface[k] != id) continue;
          seen.insert(id);
          ASSERT_EQ(only.surface[k], id) << level.actors[a].name << " face " << f << " k " << k;
          ASSERT_NEAR(only.distance_m[k], full.distance_m[k], 1e-4)
              << level.actors[a].name << " face " << f << " k " << k;
          ++compared;
        }
      }
    }
  }
  EXPECT_GE(seen.size(), 3u);
  EXPECT_GT(compared, 10000);
}

TEST(SurfaceIdsTest, NormalsOfAPlaneOfKnownTilt) {
  // A 40 m square tilted 25 degrees about x and then turned 40 about z.
  testing::TempDir dir;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(25.0 * M_PI / 180.0, Vector3d::UnitX()))
                                .toRotationMatrix();
  std::ostringstream obj;
  obj.precision(17);
  for (const auto& [u, v] : {std::pair{-20, -20}, {20, -20}, {20, 20}, {-20, 20}}) {
    const Vector3d p = R * Vector3d(u, v, 0);
    obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  obj << "f 1 2 3\nf 1 3 4\n";
  dir.Write("plane.obj", obj.str());
  const scene::Level level = scene::LoadLevel(dir.Write(
      "level.toml", "[[actor]]\nname = \"slope\"\nfile = \"plane.obj\"\nposition = [0, 0, 0]\n"));
  const scene::CollisionWorld world(level);
  const Vector3d normal = R * Vector3d::UnitZ();  // up the slope's face
  RayCaster caster(2);
  const std::int32_t slope = world.surface_ids().actor(0);

  FaceScannerConfig face;
  face.refresh = Refresh::kFull;
  face.normals = true;
  face.half_extent_m = 6.0;
  face.resolution_m = 0.25;
  FaceScan scan = FaceScanner(face).EmptyScan();
  FaceScanner(face).Scan(world, caster, {}, At(0.3, -0.2, 3.0, 0.5), 0, &scan);
  int checked = 0, from_below = 0;
  for (int face_index = 0; face_index < 6; ++face_index) {
    const ScanFace& f = scan.faces[std::size_t(face_index)];
    ASSERT_EQ(f.normal_W.size(), f.surface.size());
    // The normal faces the ray: rays that start under the slope meet its underside.
    const Vector3d direction = f.X_WB.linear() * FaceAxis(face_index);
    const Vector3d facing = normal.dot(direction) < 0 ? normal : -normal;
    from_below += facing.z() < 0;
    for (std::size_t k = 0; k < f.surface.size(); ++k) {
      if (f.surface[k] == RayHits::kNoHit) {
        EXPECT_EQ(f.normal_W[k], Eigen::Vector3f::Zero());
        continue;
      }
      ASSERT_EQ(f.surface[k], slope);
      EXPECT_LT((f.normal_W[k].cast<double>() - facing).norm(), 1e-4) << face_index << " " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(from_below, 0);

  LidarConfig lidar = LidarConfig::Uniform(16, -60, -5, 360, 40.0);
  lidar.normals = true;
  LidarScan sweep;
  Lidar(lidar).Sweep(world, caster, {}, At(0, 0, 4), At(0, 0, 4), &sweep);
  int beams = 0;
  for (std::size_t i = 0; i < sweep.surface.size(); ++i) {
    if (sweep.surface[i] != slope) continue;
    EXPECT_LT((sweep.normal_W[i].cast<double>() - normal).norm(), 1e-4) << i;
    ++beams;
  }
  EXPECT_GT(beams, 1000);

  GroundScannerConfig ground;
  ground.normals = true;
  ground.half_extent_m = 5.0;
  HeightMap map;
  GroundScanner(ground).Scan(world, caster, {}, Vector3d(0, 0, 10), &map);
  for (std::size_t i = 0; i < map.surface.size(); ++i) {
    ASSERT_EQ(map.surface[i], slope) << i;
    EXPECT_LT((map.normal_W[i].cast<double>() - normal).norm(), 1e-4) << i;
  }
}

TEST(SurfaceIdsTest, TheTableNamesActorsRobotBonesAndTilesAsTheyComeAndGo) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  const std::vector<scene::SurfaceEntry> table = world.SurfaceTable();
  // Ids 1, 2, ... in order: the actors, the horizon, each robot's bone map.
  std::size_t bones = 0;
  for (const scene::RobotModel& robot : level.robots) bones += robot.bones.size();
  ASSERT_EQ(table.size(), level.actors.size() + 1 + bones);
  for (std::size_t k = 0; k < table.size(); ++k) EXPECT_EQ(table[k].id, std::int32_t(k + 1));
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    EXPECT_EQ(table[a].kind, "actor");
    EXPECT_EQ(table[a].name, level.actors[a].name);
    EXPECT_EQ(table[a].actor, int(a));
  }
  const scene::SurfaceEntry& root = table[level.actors.size() + 1];
  EXPECT_EQ(root.kind, "robot");
  EXPECT_EQ(root.robot, 0);
  EXPECT_EQ(root.robot_name, level.robots[0].name);
  EXPECT_EQ(root.bone_name, level.robots[0].bones[0].name);
  EXPECT_EQ(world.surface_revision(), 0u);
}

TEST(SurfaceIdsTest, ATerrainTileKeepsItsIdWhenItLeavesAndComesBack) {
  scene::Level level = scene::LoadLevel(testing::SampleLevel());
  level.terrain_actor = level.FindActor("terrain");  // its tiles belong to it
  scene::CollisionWorld world(level);
  auto tile = std::make_shared<scene::TerrainTile>();
  tile->id = {0, 0, 3, 4};
  tile->origin_W = Vector3d(100, 200, 500);  // above everything else
  tile->positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
  tile->indices = {0, 1, 2, 0, 2, 3};
  RayCaster caster(1);
  RayBatch ray;
  ray.origin_W = Vector3d(101, 202, 600);
  ray.start = {Eigen::Vector3f::Zero()};
  ray.direction = {-Eigen::Vector3f::UnitZ()};
  ray.length_m = {1000.f};
  RayHits hits;
  const std::int32_t expected = world.surface_ids().first_tile();
  for (int round = 0; round < 2; ++round) {
    world.AddTile(scene::CollisionWorld::PrepareTile(tile));
    EXPECT_EQ(world.surface_revision(), std::uint64_t(2 * round + 1));
    caster.Cast(world, ray, {}, &hits);
    EXPECT_EQ(hits.surface[0], expected);
    EXPECT_FLOAT_EQ(hits.distance_m[0], 100.f);
    const std::vector<scene::SurfaceEntry> table = world.SurfaceTable();
    ASSERT_EQ(table.back().id, expected);
    EXPECT_EQ(table.back().kind, "tile");
    EXPECT_EQ(table.back().name, "terrain/0/3,4");
    EXPECT_EQ(table.back().actor, level.terrain_actor);
    ASSERT_TRUE(world.RemoveTile(tile->id.key()));
    EXPECT_EQ(world.SurfaceTable().size(), table.size() - 1);
    caster.Cast(world, ray, {}, &hits);
    EXPECT_NE(hits.surface[0], expected);
  }
}

}  // namespace
}  // namespace sandbox::sensors
