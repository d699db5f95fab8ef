// The structured face-scan kernel (RayCaster::CastGrids) against the general
// caster (RayCaster::Cast) on the same rays: every ray hits or misses in both,
// at the same distance, on the same body. Random poses and orientations, a
// bent robot, and meshes whose vertices lie exactly on the rays.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/face_scanner.h"
#include "sensors/lidar.h"
#include "sensors/ray_caster.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

struct Difference {
  int rays{0}, hits{0}, hit_differs{0}, surface_differs{0}, normal_differs{0};
  double worst_m{0.0};
};

// The general caster's hits against a structured kernel's on the same rays.
Difference Differences(const RayHits& general, const RayHits& structured) {
  Difference difference;
  difference.rays = int(general.size());
  for (std::size_t i = 0; i < general.size(); ++i) {
    const bool hit = general.surface[i] != RayHits::kNoHit;
    difference.hits += hit;
    if (hit != (structured.surface[i] != RayHits::kNoHit)) {
      ++difference.hit_differs;
      continue;
    }
    difference.surface_differs += general.surface[i] != structured.surface[i];
    // Unit and facing in both (the structured kernel's square root to 2 ulps).
    difference.normal_differs += !((general.normal_W[i] - structured.normal_W[i]).norm() <= 1e-6f);
    difference.worst_m = std::max(
        difference.worst_m, std::abs(double(general.distance_m[i]) - structured.distance_m[i]));
  }
  return difference;
}

// A full scan's rays from X_WS cast both ways.
Difference CompareKernels(const scene::CollisionWorld& world, const FaceScannerConfig& config,
                          const Isometry3d& X_WS, const RayFilter& filter = {}) {
  FaceScannerConfig full = config;
  full.refresh = Refresh::kFull;
  const FaceScanner scanner(full);
  RayBatch rays;
  std::vector<RayGrid> grids;
  scanner.GridRays(0, X_WS, &rays, &grids);
  RayCaster caster(2);
  RayHits general, structured, again;
  caster.Cast(world, rays, filter, &general);
  caster.CastGrids(world, rays, grids, filter, &structured);
  // Again, the bands now cut and ordered by what each face took (as for a
  // scanner's next scan): the same hits.
  caster.CastGrids(world, rays, grids, filter, &again);
  // Into arrays of the caller's own (RayGrid::into), a block's rows apart:
  // bit for bit what the hits got.
  RayHits into;
  into.distance_m.assign(rays.size(), -1.0f);
  into.surface.assign(rays.size(), -1);
  into.normal_W.assign(rays.size(), Eigen::Vector3f::Constant(-1.0f));
  std::vector<RayGrid> own = grids;
  for (RayGrid& grid : own) {
    grid.into = {into.distance_m.data() + grid.first, into.surface.data() + grid.first,
                 into.normal_W.data() + grid.first};
  }
  RayHits unused;
  caster.CastGrids(world, rays, own, filter, &unused);
  EXPECT_EQ(unused.size(), 0u);  // every block had its own: the hits untouched
  EXPECT_EQ(into.distance_m, again.distance_m);
  EXPECT_EQ(into.surface, again.surface);
  EXPECT_TRUE(into.normal_W == again.normal_W);
  Difference difference = Differences(general, structured);
  const Difference second = Differences(general, again);
  difference.hit_differs += second.hit_differs;
  difference.surface_differs += second.surface_differs;
  difference.normal_differs += second.normal_differs;
  difference.worst_m = std::max(difference.worst_m, second.worst_m);
  return difference;
}

// `ties`: rays meet several triangles at one distance (through shared
// vertices), where each kernel keeps the first it tests: the normals may
// then differ, nothing else.
void ExpectSame(const Difference& difference, const std::string& where, bool ties = false) {
  EXPECT_EQ(difference.hit_differs, 0) << where;
  EXPECT_EQ(difference.surface_differs, 0) << where;
  EXPECT_LE(difference.worst_m, 1e-5) << where;  // 0.01 mm
  if (!ties) {
    EXPECT_EQ(difference.normal_differs, 0) << where;
  }
}

// A pose in the box, turned at random; the same on every compiler (the draws
// are taken in order, not as arguments, whose order of evaluation varies).
Isometry3d RandomPose(std::mt19937& random, const Eigen::AlignedBox3d& box) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double draw[7];
  for (double& value : draw) value = unit(random);
  const Vector3d p = box.min() + box.sizes().cwiseProduct(Vector3d(draw[0], draw[1], draw[2]));
  const Eigen::Quaterniond q(draw[3] - 0.5, draw[4] - 0.5, draw[5] - 0.5, draw[6] - 0.5);
  return Eigen::Translation3d(p) * q.normalized();
}

// The sample level's wing at (10, 20, 40), its joints bent 0.3 rad at most.
bool BendTheWing(const scene::Level& level, scene::CollisionWorld* world) {
  scene::RobotState wing(level.robots[0]);
  if (!wing.SetPose(Isometry3d(Eigen::Translation3d(10, 20, 40)))) return false;
  std::vector<double> bones = wing.bone_values();
  for (std::size_t b = 0; b < bones.size(); ++b) bones[b] = 0.3 * std::sin(double(b) + 1.0);
  if (!wing.SetBones(bones)) return false;
  wing.Update();
  world->UpdateRobot(0, wing);
  return true;
}

TEST(StructuredScanTest, SameHitsAsTheGeneralCasterOnTheSampleLevelFromRandomPoses) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  std::mt19937 random(20261124);
  const Eigen::AlignedBox3d valley(Vector3d(-150, -150, 5), Vector3d(150, 150, 60));
  int hits = 0;
  for (int k = 0; k < 12; ++k) {
    FaceScannerConfig config;
    config.alignment = k % 3 == 2 ? Alignment::kWorld : Alignment::kBody;
    config.resolution_m = k % 2 == 0 ? 1.0 : 0.25;
    config.half_extent_m = k % 2 == 0 ? 25.0 : 10.0;
    const Isometry3d X_WS = RandomPose(random, valley);
    const Difference difference = CompareKernels(world, config, X_WS);
    ExpectSame(difference, "pose " + std::to_string(k));
    hits += difference.hits;
  }
  EXPECT_GT(hits, 10000);  // the scans see the valley, not only the sky
}

TEST(StructuredScanTest, SameHitsOnABentRobotSeenFromBesideIt) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  scene::CollisionWorld world(level);
  ASSERT_TRUE(BendTheWing(level, &world));
  FaceScannerConfig config;
  config.resolution_m = 0.2;
  config.half_extent_m = 15.0;
  std::mt19937 random(7);
  const Eigen::AlignedBox3d near_wing(Vector3d(0, 14, 36), Vector3d(20, 26, 44));
  int robot_hits = 0;
  for (int k = 0; k < 4; ++k) {
    const Isometry3d X_WS = RandomPose(random, near_wing);
    ExpectSame(CompareKernels(world, config, X_WS), "pose " + std::to_string(k));
    // The wing is in view: the general caster hits it.
    RayFilter only_robots;
    only_robots.group_mask = scene::kRobot;
    robot_hits += CompareKernels(world, config, X_WS, only_robots).hits;
  }
  EXPECT_GT(robot_hits, 1000);
  // Its own scanner never sees it, in both kernels alike.
  RayFilter own;
  own.ignore_robot = 0;
  ExpectSame(CompareKernels(world, config, Isometry3d(Eigen::Translation3d(10, 20, 40)), own),
             "own robot ignored");
}

// A terrain of 1 m squares with integer corners, scanned at whole metres: the
// rays run exactly through its vertices and along its edges, where the
// watertight rules decide (docs/reference/sensors.md).
TEST(StructuredScanTest, SameHitsWhereRaysRunThroughVerticesAndAlongEdges) {
  testing::TempDir dir;
  {
    std::ofstream obj(dir.path() / "grid.obj");
    const int n = 80;
    for (int r = 0; r <= n; ++r) {
      for (int c = 0; c <= n; ++c) {
        obj << "v " << c - 40 << " " << r - 40 << " " << ((r * 7 + c * 3) % 5 == 0 ? 1 : 0) << "\n";
      }
    }
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const int a = r * (n + 1) + c + 1, b = a + 1, d = a + n + 1, e = d + 1;
        obj << "f " << a << " " << b << " " << e << "\nf " << a << " " << e << " " << d << "\n";
      }
    }
    std::ofstream(dir.path() / "level.toml") << "[[actor]]\nname = \"grid\"\nfile = \"grid.obj\"\n";
  }
  const scene::Level level = scene::LoadLevel(dir.path() / "level.toml");
  const scene::CollisionWorld world(level);
  FaceScannerConfig config;
  config.alignment = Alignment::kWorld;
  int hits = 0;
  for (const Vector3d& p : {Vector3d(0, 0, 5), Vector3d(3, -2, 0), Vector3d(-7, 11, 1)}) {
    const Difference difference =
        CompareKernels(world, config, Isometry3d(Eigen::Translation3d(p)));
    // Through a vertex or along an edge, each kernel keeps the first triangle
    // it meets: the normals may differ there.
    ExpectSame(difference, "at " + std::to_string(p.x()) + ", " + std::to_string(p.y()), true);
    hits += difference.hits;
  }
  EXPECT_GT(hits, 2 * 51 * 51);
}

// Two actors made of the same file lie one in the other: every ray meets
// both at one distance, and each kernel, whatever order it meets their
// triangles in (the static actors share one hierarchy), reports the actor
// listed first.
TEST(StructuredScanTest, ATieBetweenActorsGoesToTheFirstInEveryKernel) {
  testing::TempDir dir;
  {
    std::ofstream obj(dir.path() / "floor.obj");
    const int n = 40;
    for (int r = 0; r <= n; ++r) {
      for (int c = 0; c <= n; ++c) obj << "v " << c - 20 << " " << r - 20 << " 0\n";
    }
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const int a = r * (n + 1) + c + 1, b = a + 1, d = a + n + 1, e = d + 1;
        obj << "f " << a << " " << b << " " << e << "\nf " << a << " " << e << " " << d << "\n";
      }
    }
    std::ofstream(dir.path() / "level.toml")
        << "[[actor]]\nname = \"first\"\nfile = \"floor.obj\"\n"
        << "[[actor]]\nname = \"second\"\nfile = \"floor.obj\"\n";
  }
  const scene::Level level = scene::LoadLevel(dir.path() / "level.toml");
  const scene::CollisionWorld world(level);
  ASSERT_EQ(level.FindActor("first"), 0);
  RayCaster caster(2);
  FaceScannerConfig face;
  face.refresh = Refresh::kFull;
  face.alignment = Alignment::kWorld;
  face.half_extent_m = 8.0;
  face.resolution_m = 0.4;
  RayBatch face_rays;
  std::vector<RayGrid> grids;
  FaceScanner(face).GridRays(0, Isometry3d(Eigen::Translation3d(0.1, 0.2, 3.0)), &face_rays,
                             &grids);
  const LidarConfig lidar = LidarConfig::Uniform(16, -60, -10, 256, 40.0);
  const Isometry3d X_WS(Eigen::Translation3d(0.3, -0.2, 4.0));
  const RayBatch lidar_rays = Lidar(lidar).Rays(X_WS, X_WS);
  RayHits hits;
  auto expect_first = [&](const char* kernel) {
    int on_floor = 0, second = 0;
    const std::int32_t second_id = world.surface_ids().actor(1);
    for (const std::int32_t surface : hits.surface) {
      on_floor += surface != RayHits::kNoHit, second += surface == second_id;
    }
    EXPECT_GT(on_floor, 1000) << kernel;
    EXPECT_EQ(second, 0) << kernel;
  };
  caster.Cast(world, face_rays, {}, &hits);
  expect_first("Cast, face scan");
  caster.CastGrids(world, face_rays, grids, {}, &hits);
  expect_first("CastGrids");
  caster.Cast(world, lidar_rays, {}, &hits);
  expect_first("Cast, sweep");
}

TEST(StructuredScanTest, BadBlocksAreRefused) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  const FaceScanner scanner(FaceScannerConfig{});
  RayBatch rays;
  const FaceScanner::Part part{0, 0, scanner.config().points_per_side()};
  scanner.AppendRays(part, Isometry3d::Identity(), &rays);
  RayGrid grid = scanner.GridOf(part, Isometry3d::Identity(), 0);
  RayCaster caster(1);
  RayHits hits;
  grid.rows -= 1;
  EXPECT_THROW(caster.CastGrids(world, rays, {grid}, {}, &hits), std::invalid_argument);
  grid.rows += 1;
  grid.direction *= 2.0f;
  EXPECT_THROW(caster.CastGrids(world, rays, {grid}, {}, &hits), std::invalid_argument);
  grid.direction /= 2.0f;
  grid.length_m = -1.0f;
  EXPECT_THROW(caster.CastGrids(world, rays, {grid}, {}, &hits), std::invalid_argument);
  grid.length_m = rays.length_m[0];
  // An `into` without the normals the hits ask for.
  std::vector<float> distance(rays.size());
  std::vector<std::int32_t> surface(rays.size());
  grid.into.distance_m = distance.data(), grid.into.surface = surface.data();
  EXPECT_THROW(caster.CastGrids(world, rays, {grid}, {}, &hits), std::invalid_argument);
  hits.with_normals = false;
  caster.CastGrids(world, rays, {grid}, {}, &hits);  // enough without normals
  EXPECT_EQ(hits.size(), 0u);
  hits.with_normals = true;
  grid.into = {};
  caster.CastGrids(world, rays, {grid}, {}, &hits);  // restored: cast
  EXPECT_EQ(hits.size(), rays.size());
}

}  // namespace
}  // namespace sandbox::sensors
