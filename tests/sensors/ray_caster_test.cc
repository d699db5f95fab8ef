// The batched caster against Bullet's own rayTest, analytic heights, filters
// and thread counts.

#include "sensors/ray_caster.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <random>

#include "assets/generators/sample_terrain.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/face_scanner.h"
#include "sensors/walk_stack.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

class RayCasterTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    level_ = new scene::Level(scene::LoadLevel(testing::SampleLevel()));
    world_ = new scene::CollisionWorld(*level_);
  }
  static void TearDownTestSuite() {
    delete world_;
    delete level_;
  }
  static scene::Level* level_;
  static scene::CollisionWorld* world_;
};
scene::Level* RayCasterTest::level_ = nullptr;
scene::CollisionWorld* RayCasterTest::world_ = nullptr;

// Random rays over the valley, from 0-80 m up, in every direction, 5-300 m long.
RayBatch RandomRays(int n, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> xy(-180.f, 180.f), z(0.f, 80.f), unit(-1.f, 1.f),
      length(5.f, 300.f);
  RayBatch rays;
  rays.origin_W = Vector3d(3.0, -2.0, 10.0);
  for (int i = 0; i < n; ++i) {
    Vector3f d(unit(random), unit(random), unit(random));
    if (d.norm() < 0.1f) d = Vector3f::UnitZ();
    rays.start.emplace_back(xy(random), xy(random), z(random));
    rays.direction.push_back(d.normalized());
    rays.length_m.push_back(length(random));
  }
  return rays;
}

// The kernel SANDBOX_RAY_KERNEL names is the one in use (ctest runs the ray
// tests once on each kernel the machine can run).
TEST(RayKernelTest, TheKernelAskedForIsTheOneInUse) {
  const char* asked = std::getenv("SANDBOX_RAY_KERNEL");
  if (asked == nullptr) GTEST_SKIP() << "SANDBOX_RAY_KERNEL is not set";
  EXPECT_STREQ(RayCaster::kernel(), asked);
}

TEST_F(RayCasterTest, AgreesWithBulletsRayTest) {
  const RayBatch rays = RandomRays(20000, 7);
  RayCaster caster(2);
  RayHits hits;
  caster.Cast(*world_, rays, {}, &hits);
  int mismatches = 0, hits_count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Vector3d from = rays.origin_W + rays.start[i].cast<double>();
    const Vector3d to = from + double(rays.length_m[i]) * rays.direction[i].cast<double>();
    const auto expected = world_->CastRay(from, to);
    if (expected.has_value() != (hits.surface[i] != RayHits::kNoHit)) {
      ++mismatches;  // grazing an edge or a silhouette can go either way
      continue;
    }
    if (!expected) {
      EXPECT_EQ(hits.distance_m[i], rays.length_m[i]);
      continue;
    }
    ++hits_count;
    EXPECT_NEAR(hits.distance_m[i], expected->distance_m, 1e-3)
        << "ray " << i << " surface " << hits.surface[i] << " bullet actor " << expected->actor
        << " robot " << expected->robot << " from " << from.transpose() << " dir "
        << rays.direction[i].transpose();
    // The id names what Bullet says was hit (the level's table).
    const scene::SurfaceEntry* entry = world_->surface_ids().Find(hits.surface[i]);
    ASSERT_NE(entry, nullptr) << "ray " << i;
    EXPECT_EQ(entry->actor, expected->actor) << "ray " << i;
    EXPECT_EQ(entry->robot, expected->robot) << "ray " << i;
    EXPECT_GT(hits.normal_W[i].cast<double>().dot(expected->normal_W), 0.999) << "ray " << i;
  }
  EXPECT_GT(hits_count, 5000);
  EXPECT_LE(mismatches, 2);
}

// The sample level's static actors share one hierarchy (scene::MergedStatic);
// a filter that leaves one of them out still sees the others as Bullet does.
TEST_F(RayCasterTest, IgnoringAStaticActorAgreesWithBullet) {
  const int tower = level_->FindActor("tower");
  ASSERT_GE(tower, 0);
  // Rays from around the tower towards it, many of which it stops.
  RayBatch rays;
  rays.origin_W = Vector3d(-30, 45, 15);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(-1.f, 1.f);
  for (int i = 0; i < 4000; ++i) {
    const Vector3f start(20.f * unit(random), 20.f * unit(random), 10.f * unit(random) + 5.f);
    rays.start.push_back(start);
    rays.direction.push_back(
        (-start + Vector3f(3.f * unit(random), 3.f * unit(random), 0.f)).normalized());
    rays.length_m.push_back(60.f);
  }
  RayFilter ignore;
  ignore.ignore_actor = tower;
  RayCaster caster(2);
  RayHits seen, ignored;
  caster.Cast(*world_, rays, {}, &seen);
  caster.Cast(*world_, rays, ignore, &ignored);
  int on_tower = 0, mismatches = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    on_tower += seen.surface[i] == world_->surface_ids().actor(tower);
    ASSERT_NE(ignored.surface[i], world_->surface_ids().actor(tower)) << "ray " << i;
    const Vector3d from = rays.origin_W + rays.start[i].cast<double>();
    const Vector3d to = from + 60.0 * rays.direction[i].cast<double>();
    const auto expected = world_->CastRay(from, to, scene::kAllGroups, tower);
    if (expected.has_value() != (ignored.surface[i] != RayHits::kNoHit)) {
      ++mismatches;  // grazing an edge can go either way
      continue;
    }
    if (expected) {
      EXPECT_NEAR(ignored.distance_m[i], expected->distance_m, 1e-3) << "ray " << i;
    }
  }
  EXPECT_GT(on_tower, 1000);
  EXPECT_LE(mismatches, 2);
}

TEST_F(RayCasterTest, VerticalRaysHitTheAnalyticTerrain) {
  namespace sample = assets::sample;
  RayBatch rays;
  std::vector<double> expected_z;
  for (int row = 3; row < sample::kTerrainPoints; row += 9) {
    for (int col = 3; col < sample::kTerrainPoints; col += 9) {
      const double x = sample::GridX(col), y = sample::GridY(row);
      rays.start.emplace_back(float(x), float(y), 0.f);
      rays.direction.push_back(-Vector3f::UnitZ());
      rays.length_m.push_back(300.f);
      expected_z.push_back(double(float(sample::TerrainHeight(x, y))));
    }
  }
  rays.origin_W = Vector3d(0, 0, 200);
  RayCaster caster(1);
  RayHits hits;
  RayFilter only_terrain;
  only_terrain.group_mask = scene::kWorldStatic;
  caster.Cast(*world_, rays, only_terrain, &hits);
  const int terrain = level_->FindActor("terrain");
  int checked = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (hits.surface[i] != world_->surface_ids().actor(terrain)) continue;  // a rock, the wall, ...
    EXPECT_NEAR(200.0 - hits.distance_m[i], expected_z[i], 1e-3);
    ++checked;
  }
  EXPECT_GT(checked, int(rays.size()) * 9 / 10);
}

TEST_F(RayCasterTest, FiltersAndThreadCountsChangeNothingElse) {
  const RayBatch rays = RandomRays(5000, 11);
  RayHits one, two, no_robot, static_only;
  RayCaster single(1), pair(2);
  single.Cast(*world_, rays, {}, &one);
  pair.Cast(*world_, rays, {}, &two);
  EXPECT_EQ(one.surface, two.surface);
  EXPECT_EQ(one.distance_m, two.distance_m);
  // Water has collision off: never hit.
  const int water = world_->surface_ids().actor(level_->FindActor("water"));
  for (const int surface : one.surface) EXPECT_NE(surface, water);
  // Ignoring the robot or keeping only static actors never shows them.
  auto robot_body = [](std::int32_t surface) {
    const scene::SurfaceEntry* entry = world_->surface_ids().Find(surface);
    return entry != nullptr && entry->robot == 0;
  };
  RayFilter ignore;
  ignore.ignore_robot = 0;
  pair.Cast(*world_, rays, ignore, &no_robot);
  RayFilter statics;
  statics.group_mask = scene::kWorldStatic;
  pair.Cast(*world_, rays, statics, &static_only);
  const int gate = world_->surface_ids().actor(level_->FindActor("gate"));
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_FALSE(robot_body(no_robot.surface[i]));
    EXPECT_FALSE(robot_body(static_only.surface[i]));
    EXPECT_NE(static_only.surface[i], gate);
  }
}

// A caster keeps the world's objects between casts while the world stays as
// it was: after each change (a movable actor placed, the robot moved and
// bent, the floating origin moved) it casts what a new caster casts.
TEST_F(RayCasterTest, OneCasterFollowsEveryChangeOfTheWorld) {
  scene::CollisionWorld world(*level_);
  const RayBatch rays = RandomRays(20000, 13);
  RayCaster kept(2);
  RayHits before, after, fresh;
  kept.Cast(world, rays, {}, &before);
  scene::RobotState robot(level_->robots[0]);
  Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
  X_WB.translation() = Vector3d(10, 5, 25);
  ASSERT_TRUE(robot.SetPose(X_WB));
  std::vector<double> bones(std::size_t(level_->robots[0].num_values), 0.0);
  for (int b = 1; b <= 20; ++b) bones[std::size_t(2 * b)] = 0.1;
  ASSERT_TRUE(robot.SetBones(bones));
  robot.Update();
  Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
  X_WG.translation() = Vector3d(-20, 30, 12);
  const std::vector<std::function<void()>> changes = {
      [&] { world.SetActorPose("gate", X_WG); }, [&] { world.UpdateRobot(0, robot); },
      [&] { world.SetOrigin(Vector3d(500, -300, 20)); }};
  for (std::size_t c = 0; c < changes.size(); ++c) {
    changes[c]();
    kept.Cast(world, rays, {}, &after);
    RayCaster(2).Cast(world, rays, {}, &fresh);
    EXPECT_EQ(after.surface, fresh.surface) << "change " << c;
    EXPECT_EQ(after.distance_m, fresh.distance_m) << "change " << c;
    int changed = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      changed +=
          after.surface[i] != before.surface[i] || after.distance_m[i] != before.distance_m[i];
    }
    if (c < 2) {
      EXPECT_GT(changed, 0) << "change " << c << " moved nothing the rays see";
    }
    before = after;
  }
}

// Rays that all start at one point (a still lidar's sweep: the wide kernels
// share each triangle's work between a packet's rays then) get the same bits
// as when each shares its packet with rays from elsewhere: on the terrain,
// the buildings and a bent robot (objects placed off the identity), and
// along rays aimed at the triangles' corners.
TEST_F(RayCasterTest, RaysFromOnePointGetTheHitsTheyGetAmongRaysFromElsewhere) {
  scene::CollisionWorld world(*level_);
  scene::RobotState robot(level_->robots[0]);
  Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
  X_WB.translation() = Vector3d(10, 5, 25);
  ASSERT_TRUE(robot.SetPose(X_WB));
  std::vector<double> bones(std::size_t(level_->robots[0].num_values), 0.0);
  for (int b = 1; b <= 20; ++b) bones[std::size_t(2 * b)] = 0.15;
  ASSERT_TRUE(robot.SetBones(bones));
  robot.Update();
  world.UpdateRobot(0, robot);
  std::mt19937 random(29);
  std::uniform_real_distribution<float> unit(-1.f, 1.f);
  const std::vector<Vector3d> points = {{10, 5, 31}, {4, -3, 26}, {-40, 60, 8}, {120, -90, 40}};
  RayCaster caster(2);
  int hits = 0, robot_hits = 0;
  for (const Vector3d& point : points) {
    RayBatch alone;
    alone.origin_W = point;
    // Rays in every direction, and rays through grid points of the valley
    // floor and the robot's box, where edges and corners lie.
    for (int i = 0; i < 4000; ++i) {
      Vector3f d(unit(random), unit(random), unit(random));
      if (d.norm() < 0.1f) d = -Vector3f::UnitZ();
      alone.direction.push_back(d.normalized());
    }
    for (int x = -20; x <= 20; ++x) {
      for (int y = -20; y <= 20; ++y) {
        const Vector3f to =
            (Vector3d(10 + 0.5 * x, 5 + 0.5 * y, 24 + 0.1 * ((x + y) % 7)) - point).cast<float>();
        if (to.norm() > 1e-3f) alone.direction.push_back(to.normalized());
        const Vector3f down = (Vector3d(4.0 * x, 4.0 * y, 0.0) - point).cast<float>();
        alone.direction.push_back(down.normalized());
      }
    }
    alone.start.assign(alone.direction.size(), Vector3f::Zero());
    alone.length_m.assign(alone.direction.size(), 400.f);
    // Each ray again, with one from elsewhere after it.
    RayBatch mixed;
    mixed.origin_W = point;
    for (std::size_t i = 0; i < alone.size(); ++i) {
      for (const Vector3f& start : {Vector3f::Zero().eval(), Vector3f(0.37f, -0.21f, 0.5f)}) {
        mixed.start.push_back(start);
        mixed.direction.push_back(alone.direction[i]);
        mixed.length_m.push_back(alone.length_m[i]);
      }
    }
    RayHits one_point, among_others;
    caster.Cast(world, alone, {}, &one_point);
    caster.Cast(world, mixed, {}, &among_others);
    for (std::size_t i = 0; i < alone.size(); ++i) {
      const std::size_t j = 2 * i;
      ASSERT_EQ(one_point.surface[i], among_others.surface[j]) << "ray " << i;
      ASSERT_EQ(one_point.distance_m[i], among_others.distance_m[j]) << "ray " << i;
      ASSERT_EQ(one_point.normal_W[i], among_others.normal_W[j]) << "ray " << i;
      if (one_point.surface[i] == RayHits::kNoHit) continue;
      ++hits;
      const scene::SurfaceEntry* entry = world.surface_ids().Find(one_point.surface[i]);
      robot_hits += entry != nullptr && entry->robot == 0;
    }
  }
  // The rays meet the world and the robot's pieces.
  EXPECT_GT(hits, 10000);
  EXPECT_GT(robot_hits, 300);
}

}  // namespace
}  // namespace sandbox::sensors

namespace sandbox::sensors {
namespace {

// Back-to-back jobs of very different sizes: each chunk runs once, for its
// own job, and no thread touches a job after RunParallel has returned (a
// late worker once took a chunk of the next job for the job it woke for).
TEST(RunParallelTest, EveryChunkRunsOnceForItsOwnJob) {
  RayCaster caster(4);
  constexpr int kJobs = 20000;
  std::vector<std::vector<int>> runs(kJobs);
  for (int j = 0; j < kJobs; ++j) {
    const int chunks = j % 2 == 0 ? 1 : 1 + j % 64;
    runs[j].assign(chunks, 0);
    std::vector<int>* mine = &runs[j];
    caster.RunParallel(chunks, [mine](int chunk) { ++(*mine)[chunk]; });
    runs[j].push_back(-1);  // moves the storage: a late writer hits freed memory
  }
  int wrong = 0;
  for (int j = 0; j < kJobs; ++j) {
    const std::vector<int>& counts = runs[j];
    for (std::size_t c = 0; c + 1 < counts.size(); ++c) wrong += counts[c] != 1;
  }
  EXPECT_EQ(wrong, 0);
}

TEST(WalkStackTest, GrowsPastItsPlaceAndGivesEveryEntryBack) {
  WalkStack<int, 4> stack;
  for (int i = 0; i < 1000; ++i) stack.Push(i);
  EXPECT_TRUE(stack.on_heap());
  EXPECT_EQ(stack.size(), 1000);
  for (int i = 999; i >= 0; --i) ASSERT_EQ(stack.Pop(), i);
  EXPECT_TRUE(stack.empty());
}

// An axis-aligned room, 12 x 12 x 8 m from (-6, -6, 0), with a 2 m pillar
// from (1, 1, 0) to (3, 3, 8), as OBJ boxes (whole-metre corners, exact in float).
scene::Level Room(const testing::TempDir& dir) {
  dir.Write("room.obj", testing::ObjBox("room", 12, 12, 8, -6, -6, 0) +
                            testing::ObjBox("pillar", 2, 2, 8, 1, 1, 0, 9));
  return scene::LoadLevel(
      dir.Write("room.toml", "[[actor]]\nname = \"room\"\nfile = \"room.obj\"\n"));
}

// The first hit of a ray on the room's box faces, computed here in double
// from the rules (docs/reference/sensors.md): faces are closed rectangles; a ray lying
// in a face's plane does not hit it; one whose origin lies on a face hits it
// at 0; a ray running along a face's upper bound on an axis it does not move
// along misses it (past its origin); nothing at or beyond the ray's length.
// Returns the length for none.
double ExpectedHit(const Vector3d& o, const Vector3d& d, double length) {
  struct Box {
    Vector3d lo, hi;
  };
  const Box boxes[2] = {{{-6, -6, 0}, {6, 6, 8}}, {{1, 1, 0}, {3, 3, 8}}};
  double best = length;
  for (const Box& box : boxes) {
    for (int axis = 0; axis < 3; ++axis) {
      for (const double plane : {box.lo[axis], box.hi[axis]}) {
        if (d[axis] == 0.0) continue;  // parallel: in the plane or not, no hit
        const double t = (plane - o[axis]) / d[axis];
        if (t < 0.0 || t >= best) continue;
        const Vector3d p = o + t * d;
        bool inside = true;
        for (int k = 0; k < 3; ++k) {
          if (k == axis) continue;
          inside = inside && p[k] >= box.lo[k] && p[k] <= box.hi[k];
          // Along an upper bound (a zero component counts as a tiny positive
          // one): the ray leaves the face at once, so only its origin is on it.
          if (d[k] == 0.0 && p[k] == box.hi[k] && t > 0.0) inside = false;
        }
        if (inside) best = t;
      }
    }
  }
  return best;
}

TEST(RayRulesTest, GrazingAndOriginRulesHoldInAnAxisAlignedRoom) {
  testing::TempDir dir;
  const scene::Level level = Room(dir);
  const scene::CollisionWorld world(level);
  RayCaster caster(2);
  struct Case {
    Vector3d at;
    double resolution_m, half_extent_m;
  };
  // At whole metres in the room; on its +x wall (origins on a surface, rays
  // along the wall's plane); on the pillar's corner edge.
  for (const Case& c : {Case{{0, 0, 2}, 0.25, 6}, Case{{6, 1, 3}, 0.5, 8}, Case{{3, 3, 4}, 0.5, 5},
                        Case{{-2, 1, 0}, 0.25, 4}}) {
    SCOPED_TRACE(::testing::PrintToString(c.at.transpose()));
    FaceScannerConfig config;
    config.refresh = Refresh::kFull;
    config.resolution_m = c.resolution_m;
    config.half_extent_m = c.half_extent_m;
    const FaceScanner scanner(config);
    RayBatch rays;
    rays.origin_W = c.at;
    for (const auto& part : scanner.DueAt(0)) {
      scanner.AppendRays(part, Eigen::Isometry3d(Eigen::Translation3d(c.at)), &rays);
    }
    RayHits hits;
    caster.Cast(world, rays, {}, &hits);
    int in_plane = 0, on_surface = 0, mismatches = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Vector3d o = c.at + rays.start[i].cast<double>();
      const Vector3d d = rays.direction[i].cast<double>();
      const double expected = ExpectedHit(o, d, rays.length_m[i]);
      const bool expect_hit = expected < rays.length_m[i];
      const bool hit = hits.surface[i] != RayHits::kNoHit;
      if (hit != expect_hit || (hit && std::abs(hits.distance_m[i] - expected) > 1e-5)) {
        if (++mismatches <= 5) {
          ADD_FAILURE() << "ray from " << o.transpose() << " along " << d.transpose() << ": "
                        << (hit ? "hit at " + std::to_string(hits.distance_m[i]) : "miss")
                        << ", expected "
                        << (expect_hit ? "hit at " + std::to_string(expected) : "miss");
        }
      }
      on_surface += expect_hit && expected == 0.0;
      for (int axis = 0; axis < 3; ++axis) {
        in_plane += d[axis] == 0.0 && (o[axis] == -6 || o[axis] == 6 || o[axis] == 1 ||
                                       o[axis] == 3 || o[axis] == 0 || o[axis] == 8);
      }
    }
    EXPECT_EQ(mismatches, 0);
    // The cases do exercise the rules.
    EXPECT_GT(in_plane, 20);
    if (c.at.x() == 6 || c.at == Vector3d(3, 3, 4)) {
      EXPECT_GT(on_surface, 20);
    }
  }
}

}  // namespace
}  // namespace sandbox::sensors
