// The lidar as hardware reports: intensity by the documented law, and the
// seeded imperfections measured against their settings on a flat wall whose
// exact ranges follow from geometry alone.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/lidar.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double kWall_m = 20.0;  // the wall's plane: x = 20, facing -x

// A level of one wall, 400 m square, in the plane x = 20.
scene::Level WallLevel(const testing::TempDir& dir, const std::string& extra = "") {
  dir.Write("wall.obj",
            "v 20 -200 -200\nv 20 200 -200\nv 20 200 200\nv 20 -200 200\nf 1 2 3\nf 1 3 4\n");
  return scene::LoadLevel(
      dir.Write("level.toml", "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n" + extra));
}

// 64 x 8192 beams, +-30 degrees: about a third of them (the front) meet the wall.
LidarConfig Dense() { return LidarConfig::Uniform(64, -30, 30, 8192, 200.0); }

// The wall's exact range along beam i: 20 / d.x.
double ExactRange(const RayBatch& rays, std::size_t i) {
  return kWall_m / double(rays.direction[i].x());
}

TEST(LidarNoiseTest, RangeNoiseAndDropoutMatchTheirSettingsOnAFlatWall) {
  testing::TempDir dir;
  const scene::Level level = WallLevel(dir);
  const scene::CollisionWorld world(level);
  LidarConfig config = Dense();
  config.noise.range_sigma_m = 0.05;
  config.noise.dropout_probability = 0.1;
  config.noise.seed = 7;
  const Lidar lidar(config);
  const Isometry3d X_WS = Isometry3d::Identity();
  const RayBatch rays = lidar.Rays(X_WS, X_WS);
  RayCaster caster(2);
  LidarScan scan;
  lidar.Sweep(world, caster, {}, X_WS, X_WS, &scan, 3);
  double sum = 0.0, sum2 = 0.0;
  int on_wall = 0, lost = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!(rays.direction[i].x() > 0.15f)) continue;  // beams that meet the wall
    ++on_wall;
    if (!scan.hit[i]) {
      ++lost;
      EXPECT_EQ(scan.range_m[i], 200.f);
      EXPECT_EQ(scan.surface[i], 0);
      continue;
    }
    const double error = double(scan.range_m[i]) - ExactRange(rays, i);
    sum += error, sum2 += error * error;
  }
  ASSERT_GT(on_wall, 100000);
  const int kept = on_wall - lost;
  const double mean = sum / kept, sigma = std::sqrt(sum2 / kept - mean * mean);
  EXPECT_NEAR(sigma, 0.05, 0.03 * 0.05) << on_wall << " beams on the wall";
  EXPECT_NEAR(mean, 0.0, 0.001);
  EXPECT_NEAR(double(lost) / on_wall, 0.1, 0.005);
}

TEST(LidarNoiseTest, SigmaGrowsWithRangeAndRangesAreQuantisedAndCutBelowTheMinimum) {
  testing::TempDir dir;
  const scene::Level level = WallLevel(dir);
  const scene::CollisionWorld world(level);
  LidarConfig config = Dense();
  config.noise.range_sigma_per_m = 0.002;  // 4 cm at 20 m, 4.6 cm at 23 m
  config.noise.range_step_m = 0.01;
  config.noise.min_range_m = 23.0;  // beams more than 29.6 degrees off the wall's normal pass
  const Lidar lidar(config);
  const Isometry3d X_WS = Isometry3d::Identity();
  const RayBatch rays = lidar.Rays(X_WS, X_WS);
  RayCaster caster(2);
  LidarScan scan;
  lidar.Sweep(world, caster, {}, X_WS, X_WS, &scan);
  double sum2 = 0.0, expected2 = 0.0;
  int kept = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!(rays.direction[i].x() > 0.15f)) continue;
    const double exact = ExactRange(rays, i);
    EXPECT_EQ(bool(scan.hit[i]), exact >= 23.0) << i;
    if (!scan.hit[i]) continue;
    const double r = scan.range_m[i];
    EXPECT_NEAR(r / 0.01, std::round(r / 0.01), 1e-3) << r;  // a whole number of steps
    const double error = r - exact;
    sum2 += error * error, expected2 += std::pow(0.002 * exact, 2) + 0.01 * 0.01 / 12;
    ++kept;
  }
  ASSERT_GT(kept, 20000);
  EXPECT_NEAR(std::sqrt(sum2 / kept), std::sqrt(expected2 / kept),
              0.03 * std::sqrt(expected2 / kept));
}

TEST(LidarNoiseTest, IntensityFollowsReflectivityIncidenceAndRange) {
  testing::TempDir bright_dir, dark_dir;
  const scene::Level bright = WallLevel(bright_dir, "reflectivity = 0.8\n");
  const scene::Level dark = WallLevel(dark_dir, "reflectivity = 0.2\n");
  const scene::CollisionWorld bright_world(bright), dark_world(dark);
  LidarConfig config = LidarConfig::Uniform(8, -20, 20, 720, 200.0);
  config.intensity_reference_m = 25.0;  // nearer than 25 m: no falloff
  const Lidar lidar(config);
  const Isometry3d X_WS = Isometry3d::Identity();
  const RayBatch rays = lidar.Rays(X_WS, X_WS);
  RayCaster caster(1);
  LidarScan a, b;
  lidar.Sweep(bright_world, caster, {}, X_WS, X_WS, &a);
  lidar.Sweep(dark_world, caster, {}, X_WS, X_WS, &b);
  int checked = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!a.hit[i]) {
      EXPECT_EQ(a.intensity[i], 0.f);
      continue;
    }
    // Lambertian: the incidence cosine is the beam's x (the wall's normal is -x).
    const double cosine = double(rays.direction[i].x()), r = ExactRange(rays, i);
    const double falloff = std::min(1.0, 25.0 * 25.0 / (r * r));
    EXPECT_NEAR(a.intensity[i], 0.8 * cosine * falloff, 1e-5) << i;
    EXPECT_NEAR(a.intensity[i] / b.intensity[i], 4.0, 1e-4) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(LidarNoiseTest, OneSeedGivesTheSameBytesOnAnyThreadsAnotherSeedOtherBytes) {
  testing::TempDir dir;
  const scene::Level level = WallLevel(dir);
  const scene::CollisionWorld world(level);
  LidarConfig config = LidarConfig::Uniform(16, -15, 15, 1024, 200.0);
  config.noise.range_sigma_m = 0.02;
  config.noise.dropout_probability = 0.05;
  config.noise.seed = 11;
  const Isometry3d X_WS = Isometry3d::Identity();
  RayCaster one(1), two(2);
  LidarScan first, second, other_seed, other_sweep;
  Lidar(config).Sweep(world, one, {}, X_WS, X_WS, &first, 5);
  Lidar(config).Sweep(world, two, {}, X_WS, X_WS, &second, 5);
  Lidar(config).Sweep(world, two, {}, X_WS, X_WS, &other_sweep, 6);
  config.noise.seed = 12;
  Lidar(config).Sweep(world, one, {}, X_WS, X_WS, &other_seed, 5);
  EXPECT_EQ(first.range_m, second.range_m);
  EXPECT_EQ(first.hit, second.hit);
  EXPECT_EQ(first.intensity, second.intensity);
  EXPECT_NE(first.range_m, other_seed.range_m);
  EXPECT_NE(first.range_m, other_sweep.range_m);
}

// One wall of two materials (x = 20; y < 0 "Bright", y > 0 "Dark"): each
// beam's intensity takes its own material's reflectivity, from the manifest
// or, without it, from the material's colour (OBJ colours are sRGB).
TEST(LidarNoiseTest, EachMaterialOfAnActorHasItsOwnReflectivity) {
  auto sweep_of = [](const std::string& extra, const std::string& toml_tail, LidarScan* scan,
                     RayBatch* rays, std::vector<scene::SurfaceEntry>* table) {
    testing::TempDir dir;
    dir.Write("wall.mtl", "newmtl Bright\nKd 0.8 0.8 0.8\nnewmtl Dark\nKd 0.2 0.3 0.1\n");
    dir.Write("wall.obj",
              "mtllib wall.mtl\nv 20 -200 -200\nv 20 0 -200\nv 20 0 200\nv 20 -200 200\n"
              "v 20 200 -200\nv 20 200 200\ng bright\nusemtl Bright\nf 1 2 3\nf 1 3 4\n"
              "g dark\nusemtl Dark\nf 2 5 6\nf 2 6 3\n");
    dir.Write("post.obj", "v -30 -1 -5\nv -30 1 -5\nv -30 1 5\nf 1 2 3\n");
    const scene::Level level = scene::LoadLevel(dir.Write(
        "level.toml", "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n" + extra + toml_tail));
    const scene::CollisionWorld world(level);
    LidarConfig config = LidarConfig::Uniform(8, -20, 20, 720, 200.0);
    config.intensity_reference_m = 25.0;
    const Lidar lidar(config);
    *rays = lidar.Rays(Isometry3d::Identity(), Isometry3d::Identity());
    RayCaster caster(2);
    lidar.Sweep(world, caster, {}, Isometry3d::Identity(), Isometry3d::Identity(), scan);
    *table = world.SurfaceTable();
  };
  auto srgb = [](double c) { return std::pow((c + 0.055) / 1.055, 2.4); };
  const double bright = 0.2126 * srgb(0.8) + 0.7152 * srgb(0.8) + 0.0722 * srgb(0.8);
  const double dark = 0.2126 * srgb(0.2) + 0.7152 * srgb(0.3) + 0.0722 * srgb(0.1);
  for (const auto& [extra, expect_bright, expect_dark] :
       {std::tuple{std::string(), bright, dark},
        {"material_reflectivity = { Bright = 0.9, Dark = 0.1 }\n", 0.9, 0.1},
        {"reflectivity = 0.3\nmaterial_reflectivity = { Dark = 0.15 }\n", 0.3, 0.15}}) {
    // Alone, and beside a second static actor (behind the sensor): then the
    // caster walks one hierarchy merged over both.
    for (const std::string tail : {"", "[[actor]]\nname = \"post\"\nfile = \"post.obj\"\n"}) {
      LidarScan scan;
      RayBatch rays;
      std::vector<scene::SurfaceEntry> table;
      sweep_of(extra, tail, &scan, &rays, &table);
      int checked[2] = {0, 0};
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!scan.hit[i]) continue;
        const double y = scan.points_W[i].y();
        if (std::abs(y) < 0.01 || scan.points_W[i].x() < 0) continue;  // the seam, the post
        const double cosine = double(rays.direction[i].x()), range = ExactRange(rays, i);
        const double falloff = std::min(1.0, 25.0 * 25.0 / (range * range));
        const double r = y < 0 ? expect_bright : expect_dark;
        EXPECT_NEAR(scan.intensity[i], r * cosine * falloff, 1e-5) << extra << " beam " << i;
        ++checked[y > 0];
      }
      EXPECT_GT(checked[0], 500) << extra;
      EXPECT_GT(checked[1], 500) << extra;
      // The table gives the actor's mean over its triangles (two of each).
      ASSERT_GE(table.size(), 1u);
      EXPECT_NEAR(table[0].reflectivity, (expect_bright + expect_dark) / 2.0, 1e-6) << extra;
    }
  }
  // A material the file does not have is refused, naming the line and what it has.
  LidarScan scan;
  RayBatch rays;
  std::vector<scene::SurfaceEntry> table;
  try {
    sweep_of("material_reflectivity = { Shiny = 0.9 }\n", "", &scan, &rays, &table);
    ADD_FAILURE() << "an unknown material was taken";
  } catch (const scene::LevelError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("level.toml:4: "), std::string::npos) << what;
    EXPECT_NE(what.find("'Shiny'"), std::string::npos) << what;
    EXPECT_NE(what.find("'Bright', 'Dark'"), std::string::npos) << what;
  }
}

// A cone of four sub-rays over the edge of a near wall (x = 20, y < -0.2) in
// front of a far one (x = 40): its first return is the near wall's, its last
// the far one's, each the mean range and the summed brightness of its
// sub-rays. Sub-ray j of a beam at azimuth a (elevation 0) is, by the
// documented cone, at azimuth a + h (j = 1), a - h (j = 3), or at azimuth a
// and elevation +-h (j = 0, 2); where each meets the walls is plain geometry.
TEST(LidarNoiseTest, ADivergentBeamOverAnEdgeGivesTheNearFirstAndTheFarLastReturn) {
  testing::TempDir dir;
  dir.Write("near.obj",
            "v 20 -50 -50\nv 20 -0.2 -50\nv 20 -0.2 50\nv 20 -50 50\nf 1 2 3\nf 1 3 4\n");
  dir.Write("far.obj",
            "v 40 -200 -200\nv 40 200 -200\nv 40 200 200\nv 40 -200 200\nf 1 2 3\nf 1 3 4\n");
  const scene::Level level = scene::LoadLevel(
      dir.Write("level.toml",
                "[[actor]]\nname = \"near\"\nfile = \"near.obj\"\nreflectivity = 0.5\n"
                "[[actor]]\nname = \"far\"\nfile = \"far.obj\"\nreflectivity = 0.5\n"));
  const scene::CollisionWorld world(level);
  LidarConfig config = LidarConfig::Uniform(1, 0, 0, 3600, 200.0);
  const double h = 1.0 * M_PI / 180.0;  // half of a 2 degree cone
  config.divergence.rays = 4;
  config.divergence.angle_rad = 2.0 * h;
  RayCaster caster(2);
  LidarScan scan;
  Lidar(config).Sweep(world, caster, {}, Isometry3d::Identity(), Isometry3d::Identity(), &scan);
  ASSERT_EQ(scan.last_range_m.size(), 3600u);
  int straddling = 0, whole = 0;
  for (int k = 0; k < 3600; ++k) {
    const double a = 2.0 * M_PI * k / 3600;
    if (std::abs(std::remainder(a, 2.0 * M_PI)) > 10.0 * M_PI / 180.0) continue;
    // Each sub-ray's azimuth and the x of its direction.
    const double azimuth[4] = {a, a + h, a, a - h};
    const double x[4] = {std::cos(h) * std::cos(a), std::cos(a + h), std::cos(h) * std::cos(a),
                         std::cos(a - h)};
    double sum[2] = {0, 0}, brightness[2] = {0, 0};
    int count[2] = {0, 0};
    bool near_edge = false;
    for (int j = 0; j < 4; ++j) {
      const double y_at_near = 20.0 * std::tan(azimuth[j]);
      near_edge |= std::abs(y_at_near + 0.2) < 1e-3;
      const int wall = y_at_near < -0.2 ? 0 : 1;
      const double r = (wall == 0 ? 20.0 : 40.0) / x[j];
      sum[wall] += r, ++count[wall];
      brightness[wall] += 0.5 * x[j] * std::min(1.0, 100.0 / (r * r)) / 4.0;
    }
    if (near_edge) continue;
    const std::size_t i = std::size_t(k);
    ASSERT_TRUE(scan.hit[i]) << k;
    const int first = count[0] > 0 ? 0 : 1, last = count[1] > 0 ? 1 : 0;
    EXPECT_NEAR(scan.range_m[i], sum[first] / count[first], 1e-4) << k;
    EXPECT_NEAR(scan.last_range_m[i], sum[last] / count[last], 1e-4) << k;
    EXPECT_EQ(scan.surface[i], first + 1) << k;  // actor a is surface 1 + a
    EXPECT_EQ(scan.last_surface[i], last + 1) << k;
    const double together = brightness[0] + brightness[1];
    EXPECT_NEAR(scan.intensity[i], first == last ? together : brightness[first], 1e-6) << k;
    EXPECT_NEAR(scan.last_intensity[i], first == last ? together : brightness[last], 1e-6) << k;
    // Both returns lie on the beam's axis.
    EXPECT_NEAR((scan.points_W[i] - scan.range_m[i] * Vector3d(std::cos(a), std::sin(a), 0)).norm(),
                0.0, 1e-4);
    EXPECT_NEAR(
        (scan.last_points_W[i] - scan.last_range_m[i] * Vector3d(std::cos(a), std::sin(a), 0))
            .norm(),
        0.0, 1e-4);
    (first != last ? straddling : whole)++;
  }
  EXPECT_GE(straddling, 15);  // 2 degrees of 0.1 degree steps, minus the edge's own
  EXPECT_GT(whole, 150);
}

TEST(LidarNoiseTest, BadSettingsAreRefusedAtLoadNamingTheLineAndField) {
  testing::TempDir dir;
  dir.Write("wall.obj", "v 20 -2 -2\nv 20 2 -2\nv 20 2 2\nf 1 2 3\n");
  auto error_of = [&dir](const std::string& toml) -> std::string {
    try {
      MakeRobotSensors(scene::LoadLevel(dir.Write("level.toml", toml)));
    } catch (const scene::LevelError& error) {
      return error.what();
    }
    return "";
  };
  const std::string reflectivity =
      error_of("[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\nreflectivity = 1.5\n");
  EXPECT_NE(reflectivity.find("level.toml:4: "), std::string::npos) << reflectivity;
  EXPECT_NE(reflectivity.find("'reflectivity' must be 0 to 1"), std::string::npos) << reflectivity;
  const std::string by_material = error_of(
      "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n\nmaterial_reflectivity = { Rock = -0.5 "
      "}\n");
  EXPECT_NE(by_material.find("level.toml:5: "), std::string::npos) << by_material;
  EXPECT_NE(by_material.find("'material_reflectivity.Rock' must be 0 to 1"), std::string::npos)
      << by_material;
  const std::string robot = "[[robot]]\nname = \"W\"\nfile = \"" + std::string(SANDBOX_SOURCE_DIR) +
                            "/assets/robots/generated/flying_wing.gltf\"\nbones = [\"root\"]\n"
                            "[[robot.sensor]]\nname = \"l\"\ntype = \"lidar\"\n";
  // The key's own line (the sensor table's keys start at line 8), or the
  // table's (line 5) for a key that is missing.
  for (const auto& [line, field, at] :
       {std::tuple{"dropout_probability = 1.5", "dropout_probability", 8},
        {"range_noise_sigma_m = -0.1", "range_noise_sigma_m", 8},
        {"dropout_below_intensity = -1", "dropout_below_intensity", 8},
        {"min_range_m = -2", "min_range_m", 8},
        {"divergence_rays = 1\ndivergence_deg = 0.2", "divergence_rays", 8},
        {"divergence_rays = 4\ndivergence_deg = 0", "divergence_deg", 9},
        {"divergence_rays = 4", "divergence_deg", 5}}) {
    const std::string error = error_of(robot + line + "\n");
    EXPECT_NE(error.find("level.toml:" + std::to_string(at) + ": "), std::string::npos) << error;
    EXPECT_NE(error.find(field), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace sandbox::sensors
