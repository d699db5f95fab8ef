// The face scanner on analytic scenes: a plane, a cone, a box around the
// scanner; refresh stages; what it must never see; bad configs.

#include "sensors/face_scanner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "scene/level.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

// A level with one OBJ `text` placed at the origin.
scene::Level InlineLevel(const testing::TempDir& dir, const std::string& text) {
  dir.Write("shape.obj", text);
  return scene::LoadLevel(
      dir.Write("level.toml", "[[actor]]\nname = \"shape\"\nfile = \"shape.obj\"\n"));
}

std::string Plane(double half) {
  std::ostringstream out;
  out << "o plane\nv " << -half << " " << -half << " 0\nv " << half << " " << -half << " 0\nv "
      << half << " " << half << " 0\nv " << -half << " " << half << " 0\nf 1 2 3 4\n";
  return out.str();
}

// A cone: apex (0, 0, height), base circle of `radius` at z = 0, `segments` sides.
std::string Cone(double radius, double height, int segments) {
  std::ostringstream out;
  out << "o cone\nv 0 0 " << height << "\n";
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * M_PI * i / segments;
    out << "v " << radius * std::cos(a) << " " << radius * std::sin(a) << " 0\n";
  }
  for (int i = 0; i < segments; ++i)
    out << "f 1 " << 2 + i << " " << 2 + (i + 1) % segments << "\n";
  return out.str();
}

Isometry3d At(double x, double y, double z, double yaw_rad = 0.0) {
  return Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(yaw_rad, Vector3d::UnitZ());
}

TEST(FaceScannerTest, PlaneBelowIsHitByEveryDownRayAndNothingElse) {
  testing::TempDir dir;
  const scene::Level level = InlineLevel(dir, Plane(200));
  const scene::CollisionWorld world(level);
  FaceScannerConfig config;
  config.refresh = Refresh::kFull;
  const FaceScanner scanner(config);
  RayCaster caster(2);
  FaceScan scan = scanner.EmptyScan();
  const double h = 10.0;
  scanner.Scan(world, caster, {}, At(3, 4, h, 0.3), 7, &scan);
  ASSERT_EQ(scan.n, 51);
  for (int f = 0; f < 6; ++f) {
    const ScanFace& face = scan.faces[std::size_t(f)];
    EXPECT_EQ(face.tick, 7);
    for (std::size_t k = 0; k < face.occupancy.size(); ++k) {
      const Vector3d p = scan.PointW(f, k);
      if (f == 5) {  // -Z: every ray meets the plane at z = 0 after h metres
        ASSERT_EQ(face.occupancy[k], kOccupied) << k;
        EXPECT_NEAR(p.z(), 0.0, 1e-3);
      } else {  // the others run free to their full 25 m
        ASSERT_EQ(face.occupancy[k], kFree) << "face " << f << " point " << k;
      }
    }
  }
  // Row r, column c of -Z lies at u = -25 + c, v = -25 + r along the sensor's x and y.
  const Eigen::Matrix3d R = At(0, 0, 0, 0.3).linear();
  const Vector3d expected = Vector3d(3, 4, 0) + R * Vector3d(-25 + 7, -25 + 40, 0);
  EXPECT_LT((scan.PointW(5, 40 * 51 + 7) - expected).norm(), 1e-3);
  // The +Z face ends 25 m above the sensor.
  EXPECT_NEAR(scan.PointW(4, 0).z(), h + 25.0, 1e-4);
}

TEST(FaceScannerTest, ConeHitsFollowTheConeEquation) {
  testing::TempDir dir;
  const double radius = 20, height = 10;
  const scene::Level level = InlineLevel(dir, Cone(radius, height, 512));
  const scene::CollisionWorld world(level);
  FaceScannerConfig config;
  config.refresh = Refresh::kFull;
  config.resolution_m = 0.5;
  const FaceScanner scanner(config);
  RayCaster caster(2);
  FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, At(0, 0, 20), 0, &scan);
  int checked = 0;
  const ScanFace& down = scan.faces[5];
  for (std::size_t k = 0; k < down.occupancy.size(); ++k) {
    const Vector3d p = scan.PointW(5, k);
    const double r = std::hypot(p.x(), p.y());
    if (r > radius + 0.01) {
      EXPECT_EQ(down.occupancy[k], kFree) << r;  // beyond the base: nothing within 25 m
      continue;
    }
    if (r > radius - 0.5) continue;  // the faceted rim
    ASSERT_EQ(down.occupancy[k], kOccupied) << r;
    EXPECT_NEAR(p.z(), height * (1.0 - r / radius), 2e-3) << "r " << r;
    ++checked;
  }
  EXPECT_GT(checked, 4700);  // pi * 19.5^2 / 0.5^2 = 4778 grid points inside r < 19.5
}

TEST(FaceScannerTest, RaysStartingInsideABoxHitItsInnerWalls) {
  // Documented: a ray that starts inside a closed mesh hits its inside surface.
  testing::TempDir dir;
  const scene::Level level = InlineLevel(dir, testing::ObjBox("box", 10, 10, 10, -5, -5, -5));
  const scene::CollisionWorld world(level);
  FaceScannerConfig config;
  config.refresh = Refresh::kFull;
  const FaceScanner scanner(config);
  RayCaster caster(1);
  FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, At(0, 0, 0), 0, &scan);
  for (int f = 0; f < 6; ++f) {
    const ScanFace& face = scan.faces[std::size_t(f)];
    for (int r = 0; r < 51; ++r) {
      for (int c = 0; c < 51; ++c) {
        const std::size_t k = std::size_t(r * 51 + c);
        const bool inside = std::abs(-25 + r) < 5 && std::abs(-25 + c) < 5;
        const bool outside = std::abs(-25 + r) > 5 || std::abs(-25 + c) > 5;
        if (inside) {
          ASSERT_EQ(face.occupancy[k], kOccupied);
          EXPECT_NEAR(scan.PointW(f, k).dot(FaceAxis(f)), 5.0, 1e-4);
        } else if (outside) {
          ASSERT_EQ(face.occupancy[k], kFree);
        }
      }
    }
  }
}

// A scan keeps distances; its points, computed from them and the box, are
// the rays' own ends: the batch's origin plus start plus distance along the
// direction (float rays, as cast), in a world-aligned and a turned box.
TEST(FaceScannerTest, PointsAreTheRaysEnds) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  RayCaster caster(2);
  for (const Alignment alignment : {Alignment::kWorld, Alignment::kBody}) {
    FaceScannerConfig config;
    config.refresh = Refresh::kFull;
    config.alignment = alignment;
    config.resolution_m = 0.5;
    const FaceScanner scanner(config);
    const Eigen::Isometry3d X_WS = At(20, -25, 22, 0.5);
    FaceScan scan = scanner.EmptyScan();
    scanner.Scan(world, caster, {}, X_WS, 0, &scan);
    RayBatch rays;
    std::vector<RayGrid> grids;
    scanner.GridRays(0, X_WS, &rays, &grids);
    RayHits hits;
    caster.Cast(world, rays, {}, &hits);
    double worst_m = 0.0;
    int occupied = 0;
    for (int f = 0; f < 6; ++f) {
      for (std::size_t k = 0; k < scan.faces[std::size_t(f)].distance_m.size(); ++k) {
        const std::size_t i = grids[std::size_t(f)].first + k;
        const Vector3d end =
            rays.origin_W + (rays.start[i].cast<double>() +
                             double(hits.distance_m[i]) * rays.direction[i].cast<double>());
        worst_m = std::max(worst_m, (scan.PointW(f, k) - end).norm());
        occupied += scan.faces[std::size_t(f)].occupancy[k] == kOccupied;
      }
    }
    EXPECT_LT(worst_m, 1e-4);  // float starts, 25 m from the sensor
    EXPECT_GT(occupied, 1000);
  }
  EXPECT_TRUE(std::isnan(FaceScanner(FaceScannerConfig{}).EmptyScan().PointW(3, 17).x()));
}

TEST(FaceScannerTest, SixStageScansOneFaceATickInOrder) {
  testing::TempDir dir;
  const scene::Level level = InlineLevel(dir, Plane(100));
  const scene::CollisionWorld world(level);
  FaceScannerConfig six;
  six.refresh = Refresh::kSixStage;
  const FaceScanner scanner(six);
  RayCaster caster(1);
  FaceScan scan = scanner.EmptyScan();
  for (std::int64_t tick = 0; tick < 6; ++tick) {
    scanner.Scan(world, caster, {}, At(0, 0, 5), tick, &scan);
    for (int f = 0; f < 6; ++f) {
      const ScanFace& face = scan.faces[std::size_t(f)];
      if (f <= tick) {
        EXPECT_EQ(face.tick, f);
        EXPECT_NE(face.occupancy[0], kUnvisited);
      } else {  // not scanned yet
        EXPECT_EQ(face.tick, -1);
        for (const std::int8_t o : face.occupancy) ASSERT_EQ(o, kUnvisited);
      }
    }
  }
  // Twelve stages: half a face a tick, lower rows first.
  FaceScannerConfig twelve = six;
  twelve.refresh = Refresh::kTwelveStage;
  const FaceScanner halves(twelve);
  FaceScan half_scan = halves.EmptyScan();
  halves.Scan(world, caster, {}, At(0, 0, 5), 0, &half_scan);
  const ScanFace& first = half_scan.faces[0];
  EXPECT_NE(first.occupancy[0], kUnvisited);                     // row 0
  EXPECT_EQ(first.occupancy[std::size_t(50 * 51)], kUnvisited);  // row 50
  halves.Scan(world, caster, {}, At(0, 0, 5), 1, &half_scan);
  EXPECT_NE(first.occupancy[std::size_t(50 * 51)], kUnvisited);
  EXPECT_EQ(half_scan.faces[1].tick, -1);
}

TEST(FaceScannerTest, OwnRobotAndCollisionOffActorsAreNeverSeen) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  // ELAHA, robot 0: any of its bone groups' ids.
  auto on_robot = [&world](std::int32_t surface) {
    const scene::SurfaceEntry* entry = world.surface_ids().Find(surface);
    return entry != nullptr && entry->robot == 0;
  };
  FaceScannerConfig config;
  config.refresh = Refresh::kFull;
  const FaceScanner scanner(config);
  RayCaster caster(2);
  RayFilter own;
  own.ignore_robot = 0;
  // At the wing's centre: without the filter the wing is all around the -Z, +Z
  // faces' centre rows; with it, nothing of it is seen.
  FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, own, At(0, 0, 60), 0, &scan);
  RayBatch rays;
  rays.origin_W = Vector3d(0, 0, 60);
  for (const auto& part : scanner.DueAt(0)) scanner.AppendRays(part, At(0, 0, 60), &rays);
  RayHits with_robot, without_robot;
  caster.Cast(world, rays, {}, &with_robot);
  caster.Cast(world, rays, own, &without_robot);
  int robot_hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    robot_hits += on_robot(with_robot.surface[i]);
    ASSERT_FALSE(on_robot(without_robot.surface[i]));
  }
  EXPECT_GT(robot_hits, 20);
  // Over the lake the water (collision off) is never hit: the -Z face reaches the bed.
  scanner.Scan(world, caster, own, At(-70, -60, 8), 1, &scan);
  for (std::size_t k = 0; k < scan.faces[5].occupancy.size(); ++k) {
    if (scan.faces[5].occupancy[k] == kOccupied) {
      EXPECT_LT(scan.PointW(5, k).z(), 6.0);
    }
  }
}

TEST(FaceScannerTest, BadConfigsNameTheField) {
  auto message = [](FaceScannerConfig config) {
    try {
      FaceScanner scanner(config);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  FaceScannerConfig config;
  config.resolution_m = 0;
  EXPECT_EQ(message(config), "resolution_m must be positive, got 0");
  config.resolution_m = -1;
  EXPECT_EQ(message(config), "resolution_m must be positive, got -1");
  config.resolution_m = 0.01;
  config.half_extent_m = 100;
  EXPECT_EQ(message(config),
            "half_extent_m 100 at resolution_m 0.01 makes 6 x 20001 x 20001 = 2400240006 "
            "samples a scan, over sample_budget 2000000");
  // 25 m at 0.1 m (6 x 501 x 501) is within the default budget; at 0.05 m it
  // needs a larger one, which admits it.
  config.half_extent_m = 25;
  config.resolution_m = 0.1;
  EXPECT_EQ(message(config), "no error");
  config.resolution_m = 0.05;
  EXPECT_EQ(message(config),
            "half_extent_m 25 at resolution_m 0.05 makes 6 x 1001 x 1001 = 6012006 samples a "
            "scan, over sample_budget 2000000");
  config.sample_budget = 6012006;
  EXPECT_EQ(message(config), "no error");
  config.sample_budget = 0;
  EXPECT_EQ(message(config), "sample_budget must be 6 to 20000000, got 0");
  config.sample_budget = 1e9;  // was allowed; a scan of that takes tens of gigabytes
  EXPECT_EQ(message(config), "sample_budget must be 6 to 20000000, got 1000000000");
  config = FaceScannerConfig();
  config.half_extent_m = 25.3;
  EXPECT_NE(message(config).find("must be a whole number"), std::string::npos);
  testing::TempDir dir;
  const scene::Level level = InlineLevel(dir, Plane(10));
  const scene::CollisionWorld world(level);
  RayCaster caster(1);
  FaceScan scan;
  Isometry3d bad = At(0, 0, 1);
  bad.translation().x() = std::nan("");
  EXPECT_THROW(FaceScanner(FaceScannerConfig()).Scan(world, caster, {}, bad, 0, &scan),
               std::invalid_argument);
}

}  // namespace
}  // namespace sandbox::sensors
