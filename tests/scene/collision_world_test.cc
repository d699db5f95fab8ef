// The query-only Bullet world: hits against analytic heights, channels,
// movable actors, the floating origin and Bullet's mesh limits.

#include "scene/collision_world.h"

#include <gtest/gtest.h>

#include <chrono>

#include "assets/generators/sample_terrain.h"
#include "scene/level.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

namespace sample = assets::sample;
using Eigen::Vector3d;

// The generator stores heights as float.
double GridHeight(int col, int row) {
  return static_cast<float>(sample::TerrainHeight(sample::GridX(col), sample::GridY(row)));
}

class SampleLevelTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    level_ = new Level(LoadLevel(testing::SampleLevel()));
    world_ = new CollisionWorld(*level_);
  }
  static void TearDownTestSuite() {
    delete world_;
    delete level_;
  }

  // Casts straight down at (x, y); returns the hit if it is on the terrain.
  static std::optional<RayHit> DownOnTerrain(double x, double y) {
    auto hit = world_->CastRay({x, y, 200.0}, {x, y, -100.0});
    if (!hit || hit->actor != level_->FindActor("terrain")) return std::nullopt;
    return hit;
  }

  static Level* level_;
  static CollisionWorld* world_;
};
Level* SampleLevelTest::level_ = nullptr;
CollisionWorld* SampleLevelTest::world_ = nullptr;

TEST_F(SampleLevelTest, VerticalRaysHitTheGeneratorsHeightToOneMillimetre) {
  int checked = 0, blocked = 0;
  for (int row = 1; row < sample::kTerrainPoints - 1; row += 7) {
    for (int col = 1; col < sample::kTerrainPoints - 1; col += 7) {
      // At a grid point the surface is the analytic height.
      const double x = sample::GridX(col), y = sample::GridY(row);
      // Inside the cell south-east of it, triangle (sw, se, ne) with weights (0.2, 0.5, 0.3):
      // the plane through the three analytic corner heights.
      const int south = row + 1, east = col + 1;
      const double xi = 0.2 * x + 0.5 * sample::GridX(east) + 0.3 * sample::GridX(east);
      const double yi = 0.2 * sample::GridY(south) + 0.5 * sample::GridY(south) + 0.3 * y;
      const double zi = 0.2 * GridHeight(col, south) + 0.5 * GridHeight(east, south) +
                        0.3 * GridHeight(east, row);
      for (const auto& [px, py, pz] :
           {std::tuple{x, y, GridHeight(col, row)}, std::tuple{xi, yi, zi}}) {
        const auto hit = DownOnTerrain(px, py);
        if (!hit) {
          ++blocked;  // a rock or building stands there
          continue;
        }
        EXPECT_NEAR(hit->point_W.z(), pz, 1e-3) << "at " << px << ", " << py;
        EXPECT_NEAR(hit->distance_m, 200.0 - pz, 1e-3);
        EXPECT_GT(hit->normal_W.z(), 0.5);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1500);
  EXPECT_LT(blocked, checked / 20);
}

TEST_F(SampleLevelTest, WaterIsDrawnButRaysPassToTheLakeBed) {
  // The lake centre (-70, -60) lies below the water level; the water actor has collision off.
  const auto hit = world_->CastRay({-70, -60, 100}, {-70, -60, -100});
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->actor, level_->FindActor("terrain"));
  EXPECT_NEAR(hit->point_W.z(), sample::TerrainHeight(-70, -60), 0.05);
  EXPECT_LT(hit->point_W.z(), sample::kWaterLevel_m);
  EXPECT_FALSE(level_->actors[static_cast<std::size_t>(level_->FindActor("water"))].collision);
}

TEST_F(SampleLevelTest, TowerIsHollowWithADoor) {
  // A horizontal ray through the door (segments 0-1 on the east side, 0-4 m above
  // the base) meets the inside of the far wall: outer radius 6 m, wall 1 m,
  // centre (-30, 45, 7.76).
  const Vector3d centre(-30, 45, 7.76 + 2.0);
  const auto hit = world_->CastRay(centre + Vector3d(7, 0.5, 0), centre + Vector3d(-7, 0.5, 0));
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->actor, level_->FindActor("tower"));
  EXPECT_NEAR(hit->point_W.x(), -30 - 5.0, 0.1);  // inner face of the west wall
  // Through a wall block instead of the door: the outer face.
  const auto wall = world_->CastRay(centre + Vector3d(0, 7, 0), centre);
  ASSERT_TRUE(wall.has_value());
  EXPECT_NEAR(wall->point_W.y(), 45 + 6.0, 0.1);
}

TEST_F(SampleLevelTest, ChannelsMovableActorsAndIgnoring) {
  CollisionWorld world(*level_);
  const int gate = level_->FindActor("gate");
  const Vector3d above_gate(5, -35, 30);  // the gate's beam is over its origin
  const auto down = world.CastRay(above_gate, above_gate - Vector3d(0, 0, 60));
  ASSERT_TRUE(down.has_value());
  EXPECT_EQ(down->actor, gate);
  // Static channel only: the gate (movable) is not seen.
  const auto static_only = world.CastRay(above_gate, above_gate - Vector3d(0, 0, 60), kWorldStatic);
  ASSERT_TRUE(static_only.has_value());
  EXPECT_EQ(static_only->actor, level_->FindActor("terrain"));
  // Ignoring the gate gives the same.
  EXPECT_EQ(world.CastRay(above_gate, above_gate - Vector3d(0, 0, 60), kAllGroups, gate)->actor,
            level_->FindActor("terrain"));
  // Robot channel only: nothing in the level.
  EXPECT_FALSE(world.CastRay(above_gate, above_gate - Vector3d(0, 0, 60), kRobot).has_value());

  // Move the gate 50 m east: the old spot shows terrain, the new one the gate.
  Eigen::Isometry3d X_WG = level_->actors[static_cast<std::size_t>(gate)].X_WA;
  X_WG.translation() += Vector3d(50, 0, 20);  // above the rising ground
  world.SetActorPose(gate, X_WG);
  EXPECT_EQ(world.CastRay(above_gate, above_gate - Vector3d(0, 0, 60))->actor,
            level_->FindActor("terrain"));
  const auto moved =
      world.CastRay(above_gate + Vector3d(50, 0, 30), above_gate + Vector3d(50, 0, -60));
  ASSERT_TRUE(moved.has_value());
  EXPECT_EQ(moved->actor, gate);
  EXPECT_NEAR(moved->point_W.z(), 13.22 + 20 + 5.2, 1e-3);  // top of the beam

  // Static actors cannot be moved; bad poses are refused and the last one stays.
  EXPECT_THROW(world.SetActorPose(level_->FindActor("wall"), X_WG), std::invalid_argument);
  Eigen::Isometry3d bad = X_WG;
  bad.translation().x() = std::nan("");
  EXPECT_THROW(world.SetActorPose(gate, bad), std::invalid_argument);
  EXPECT_TRUE(world.actor_pose(gate).isApprox(X_WG));
  EXPECT_THROW(world.SetActorPose(99, X_WG), std::invalid_argument);

  // Placed by name, as external publishers address actors.
  X_WG.translation() = Vector3d(-100, 100, 60);
  world.SetActorPose("gate", X_WG);
  EXPECT_TRUE(world.actor_pose(gate).isApprox(X_WG));
  EXPECT_EQ(world.CastRay({-100, 100, 80}, {-100, 100, 0})->actor, gate);
  EXPECT_THROW(world.SetActorPose("no such gate", X_WG), std::invalid_argument);
}

TEST(CollisionWorldTest, FloatingOriginKeepsMillimetresFarAway) {
  // A box 5000 km east: in float, 5e6 m is only resolved to 0.5 m.
  testing::TempDir dir;
  dir.Write("box.obj", testing::ObjBox("box", 2, 2, 2, -1, -1, 0));
  const Level level = LoadLevel(dir.Write("far.toml", R"(
[[actor]]
name = "far"
file = "box.obj"
position = [5000000.123, 2000000.456, 100.789]
)"));
  CollisionWorld world(level);
  world.SetOrigin({5000000, 2000000, 0});
  const Vector3d top(5000000.123 + 0.3, 2000000.456 - 0.2, 102.789);
  const auto hit = world.CastRay(top + Vector3d(0, 0, 10), top - Vector3d(0, 0, 10));
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT((hit->point_W - top).norm(), 1e-3) << hit->point_W.transpose();
  const Vector3d side(5000000.123 + 1.0, 2000000.456, 101.5);
  const auto east = world.CastRay(side + Vector3d(10, 0, 0), side - Vector3d(1, 0, 0));
  ASSERT_TRUE(east.has_value());
  EXPECT_NEAR(east->point_W.x(), side.x(), 1e-3);
}

// A flat grid of `cols` x `rows` cells (two triangles each) at z = 0.
Mesh FlatGrid(int cols, int rows, float x0) {
  Mesh mesh;
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) mesh.positions_A.emplace_back(x0 + float(c), float(r), 0.0f);
  }
  mesh.normals_A.assign(mesh.positions_A.size(), Eigen::Vector3f::UnitZ());
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const auto a = std::uint32_t(r * (cols + 1) + c), b = a + 1, d = a + std::uint32_t(cols + 1);
      mesh.indices.insert(mesh.indices.end(), {a, b, d + 1, a, d + 1, d});
    }
  }
  return mesh;
}

TEST(CollisionWorldTest, MeshOverTwoToTheTwentyOneTrianglesIsSplit) {
  Level level;
  Actor actor;
  actor.name = "huge";
  actor.meshes.push_back(FlatGrid(1030, 1024, 0.0f));  // 2,109,440 triangles > 2^21
  ASSERT_GT(actor.num_triangles(), std::size_t{1} << 21);
  level.actors.push_back(std::move(actor));
  CollisionWorld world(level);
  EXPECT_EQ(world.num_parts(), 2);
  // The last triangles live in the second part.
  const auto hit = world.CastRay({1029.5, 1023.5, 5}, {1029.5, 1023.5, -5});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point_W.z(), 0.0, 1e-6);
  EXPECT_TRUE(world.CastRay({0.5, 0.5, 5}, {0.5, 0.5, -5}).has_value());
}

TEST(CollisionWorldTest, MoreThan1024PartsUseSeveralShapes) {
  Level level;
  Actor actor;
  actor.name = "many";
  for (int i = 0; i < 1500; ++i) actor.meshes.push_back(FlatGrid(1, 1, 2.0f * float(i)));
  level.actors.push_back(std::move(actor));
  CollisionWorld world(level);
  EXPECT_EQ(world.num_parts(), 1500);
  EXPECT_EQ(world.num_collision_objects(), 2);
  for (const int i : {0, 1023, 1024, 1499}) {
    const double x = 2.0 * i + 0.5;
    const auto hit = world.CastRay({x, 0.5, 1}, {x, 0.5, -1});
    ASSERT_TRUE(hit.has_value()) << "mesh " << i;
    EXPECT_EQ(hit->actor, 0);
  }
  EXPECT_FALSE(world.CastRay({1.5, 0.5, 1}, {1.5, 0.5, -1}).has_value());  // gap between meshes
}

}  // namespace
}  // namespace sandbox::scene

namespace sandbox::scene {
namespace {

// Four thousand movable boxes at one spot: the world keeps no overlapping
// pairs (it never collides anything), so it is built and torn down at once.
// Bullet's default pair cache made 8 million pairs here and took 36 s to
// remove the actors one by one; this one needs 0.3 s, and the bound holds
// on a machine thirty times slower (or under the sanitizers).
TEST(CollisionWorldTest, ThousandsOfActorsAtOneSpotComeAndGoAtOnce) {
  testing::TempDir dir;
  dir.Write("box.obj", testing::ObjBox("box", 1, 1, 1));
  std::string manifest;
  for (int i = 0; i < 4000; ++i) {
    manifest += "[[actor]]\nname = \"a" + std::to_string(i) +
                "\"\nfile = \"box.obj\"\n"
                "movable = true\n";
  }
  const Level level = LoadLevel(dir.Write("many.toml", manifest));
  ASSERT_EQ(level.actors.size(), 4000u);
  const auto start = std::chrono::steady_clock::now();
  {
    CollisionWorld world(level);
    // Still a world: a ray through the spot hits one of them.
    ASSERT_TRUE(world.CastRay({0.5, 0.5, 10.0}, {0.5, 0.5, -10.0}).has_value());
    world.SetActorPose(17, Eigen::Isometry3d(Eigen::Translation3d(50, 0, 0)));
    const auto moved = world.CastRay({50.5, 0.5, 10.0}, {50.5, 0.5, -10.0});
    ASSERT_TRUE(moved.has_value());
    EXPECT_EQ(moved->actor, 17);
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

}  // namespace
}  // namespace sandbox::scene
