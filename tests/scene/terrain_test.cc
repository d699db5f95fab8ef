// Terrain from elevation rasters (the bundled highlands' GeoTIFF): where poses
// land, precision far from the origin and high above it, streaming over a
// long flight, the chase camera's steadiness at altitude, bad input. The
// raster is read here with GDAL directly, not through the terrain code.

#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "assets/generators/highlands_terrain.h"
#include "bridge/example_flight.h"
#include "bridge/translation.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/terrain_source.h"
#include "scene/terrain_streamer.h"
#include "sensors/face_scanner.h"
#include "sensors/render/cameras.h"
#include "sensors/render/renderer.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;
namespace hl = assets::highlands;

std::string Generated(const std::string& file) {
  return std::string(SANDBOX_SOURCE_DIR) + "/assets/highlands/generated/" + file;
}

// A manifest with the highlands' terrain and `extra` tables.
std::string TerrainToml(const std::string& extra = "", const std::string& terrain_keys = "") {
  return "[[terrain]]\nname = \"highlands\"\nelevation = \"" + Generated("elevation.tif") +
         "\"\nanchor = [46.5, 8.2, 450.0]\ncollision_radius_m = 1500\nview_radius_m = 8000\n" +
         terrain_keys + extra;
}

// The raster as GDAL gives it, read here: a sample's height and its WGS84 place.
struct RasterProbe {
  GDALDatasetH dataset{nullptr};
  double gt[6]{};
  OGRSpatialReferenceH crs{nullptr}, wgs84{nullptr};
  OGRCoordinateTransformationH to_lonlat{nullptr};
  RasterProbe() {
    GDALAllRegister();
    dataset = GDALOpen(Generated("elevation.tif").c_str(), GA_ReadOnly);
    EXPECT_NE(dataset, nullptr);
    GDALGetGeoTransform(dataset, gt);
    crs = OSRClone(GDALGetSpatialRef(dataset));
    wgs84 = OSRNewSpatialReference(nullptr);
    OSRSetWellKnownGeogCS(wgs84, "WGS84");
    OSRSetAxisMappingStrategy(crs, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(wgs84, OAMS_TRADITIONAL_GIS_ORDER);
    to_lonlat = OCTNewCoordinateTransformation(crs, wgs84);
  }
  ~RasterProbe() {
    OCTDestroyCoordinateTransformation(to_lonlat);
    OSRDestroySpatialReference(crs);
    OSRDestroySpatialReference(wgs84);
    GDALClose(dataset);
  }
  double Height(int col, int row) const {
    float h = 0.f;
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, 1), GF_Read, col, row, 1, 1, &h, 1, 1,
                           GDT_Float32, 0, 0),
              CE_None);
    return h;
  }
  // (latitude, longitude) of the sample's centre.
  Eigen::Vector2d LatLon(int col, int row) const {
    double x = gt[0] + (col + 0.5) * gt[1] + (row + 0.5) * gt[2];
    double y = gt[3] + (col + 0.5) * gt[4] + (row + 0.5) * gt[5];
    EXPECT_TRUE(OCTTransform(to_lonlat, 1, &x, &y, nullptr));
    return {y, x};
  }
};

bridge::Translation Geodetic() {
  bridge::Translation geo;
  geo.convention = bridge::Convention::kGeodetic;
  geo.origin = {hl::kAnchorLatitude_deg, hl::kAnchorLongitude_deg, hl::kAirfieldHeight_m};
  return geo;
}

TEST(TerrainTest, AGeodeticPoseLandsOnTheTerrainWhereTheRasterSays) {
  testing::TempDir dir;
  const Level level = LoadLevel(dir.Write("level.toml", TerrainToml()));
  ASSERT_TRUE(level.warnings.empty()) << level.warnings.front();
  CollisionWorld world(level);
  TerrainStreamer terrain(level);
  const RasterProbe raster;
  // Samples: the airfield, 100 km east of it, 45 km north-east, 50 km south.
  for (const auto& [col, row] :
       std::vector<std::pair<int, int>>{{333, 2000}, {3666, 2000}, {1833, 500}, {2000, 3666}}) {
    const Eigen::Vector2d lat_lon = raster.LatLon(col, row);
    const double height = raster.Height(col, row);
    // 50 m above the sample, level: the bridge's geodetic pose convention.
    const Isometry3d X_WB = Geodetic().ToWorld(Vector3d(lat_lon.x(), lat_lon.y(), height + 50.0),
                                               bridge::NedAttitude(0, 0, 0));
    const Vector3d p = X_WB.translation(), down = X_WB.linear() * Vector3d(0, 0, -1);
    terrain.Update({p}, 0.0, &world, TerrainStreamer::Wait::kFine);
    world.SetOrigin(p.array().round().matrix());  // as the loop keeps it
    const auto hit = world.CastRay(p, p + 100.0 * down);
    ASSERT_TRUE(hit.has_value()) << col << ", " << row;
    EXPECT_EQ(hit->actor, level.terrain_actor);
    EXPECT_NEAR(hit->distance_m, 50.0, 2e-3)
        << "sample " << col << ", " << row << " at (" << p.transpose() << ")";
  }
  EXPECT_TRUE(terrain.TakeMessages().empty());
}

// Möller-Trumbore in double: the distance along `d` (unit) from `o`, or +inf.
double Intersect(const Vector3d& o, const Vector3d& d, const Vector3d& a, const Vector3d& b,
                 const Vector3d& c) {
  const Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-12) return INFINITY;
  const Vector3d s = o - a;
  const double u = s.dot(p) / det;
  const Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9) return INFINITY;
  const double t = e2.dot(q) / det;
  return t >= 0.0 ? t : INFINITY;
}

struct Triangle {
  Vector3d a, b, c;
};

// The -Z face of a full scan at X_WS against `triangles` in double: the
// largest distance between a scanned hit and the reference on the same ray.
double WorstDownwardError(const sensors::FaceScan& scan, const Isometry3d& X_WS,
                          const std::vector<Triangle>& triangles, int* occupied) {
  const sensors::ScanFace& face = scan.faces[5];
  const int n = scan.n;
  const Vector3d down = X_WS.linear() * Vector3d(0, 0, -1);
  double worst = 0.0;
  *occupied = 0;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const std::size_t k = std::size_t(r * n + c);
      if (face.occupancy[k] != sensors::kOccupied) continue;
      ++*occupied;
      // The ray: through (u, v) of the sensor's x-y plane, along its -z.
      const Vector3d o = X_WS * Vector3d(-25.0 + c, -25.0 + r, 25.0);
      double t = INFINITY;
      for (const Triangle& tri : triangles)
        t = std::min(t, Intersect(o, down, tri.a, tri.b, tri.c));
      EXPECT_TRUE(std::isfinite(t)) << "ray " << r << ", " << c << " has no reference hit";
      if (std::isfinite(t)) worst = std::max(worst, (scan.PointW(5, k) - (o + t * down)).norm());
    }
  }
  return worst;
}

TEST(TerrainTest, FaceScanHitsAt20kmUpAnd100kmOutAgreeWithDoublePrecisionToAMillimetre) {
  testing::TempDir dir;
  // A 40 m plate (two triangles), movable, to meet the scanner at 20 km.
  dir.Write("plate.obj", "v -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\nf 1 2 3\nf 1 3 4\n");
  const Level level = LoadLevel(dir.Write(
      "level.toml",
      TerrainToml("[[actor]]\nname = \"plate\"\nfile = \"plate.obj\"\nmovable = true\n")));
  CollisionWorld world(level);
  TerrainStreamer terrain(level);
  sensors::FaceScannerConfig config;
  config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner scanner(config);
  sensors::RayCaster caster(2);
  sensors::FaceScan scan = scanner.EmptyScan();

  // 1. 20 km up, 100 km east: the plate 12 m below the scanner, tilted.
  const Isometry3d X_WS =
      Eigen::Translation3d(100000.0, 0.0, 20000.0) * Eigen::AngleAxisd(0.3, Vector3d::UnitZ());
  const Isometry3d X_WP =
      Eigen::Translation3d(100002.0, -3.0, 19988.0) * Eigen::AngleAxisd(0.4, Vector3d::UnitZ()) *
      Eigen::AngleAxisd(0.1, Vector3d::UnitX()) * Eigen::AngleAxisd(-0.05, Vector3d::UnitY());
  world.SetActorPose("plate", X_WP);
  terrain.Update({X_WS.translation()}, 0.0, &world, TerrainStreamer::Wait::kFine);
  world.SetOrigin(X_WS.translation().array().round().matrix());
  scanner.Scan(world, caster, {}, X_WS, 1, &scan);
  const Vector3d corners[4] = {{-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}};
  const std::vector<Triangle> plate = {{X_WP * corners[0], X_WP * corners[1], X_WP * corners[2]},
                                       {X_WP * corners[0], X_WP * corners[2], X_WP * corners[3]}};
  int occupied = 0;
  const double plate_error = WorstDownwardError(scan, X_WS, plate, &occupied);
  EXPECT_GT(occupied, 1000);
  EXPECT_LT(plate_error, 1e-3);

  // 2. Low over the terrain 100 km east: the tiles' triangles, in double from their origins.
  const RasterProbe raster;
  const Eigen::Vector2d lat_lon = raster.LatLon(3666, 2000);
  const Vector3d ground =
      Geodetic()
          .ToWorld(Vector3d(lat_lon.x(), lat_lon.y(), raster.Height(3666, 2000)),
                   bridge::NedAttitude(0, 0, 0))
          .translation();
  const Isometry3d X_WL = Eigen::Translation3d(ground + Vector3d(0, 0, 10.0)) *
                          Eigen::AngleAxisd(-0.7, Vector3d::UnitZ());
  world.SetActorPose("plate", Eigen::Translation3d(0, 0, -1e4) * Isometry3d::Identity());
  terrain.Update({X_WL.translation()}, 1.0, &world, TerrainStreamer::Wait::kFine);
  world.SetOrigin(X_WL.translation().array().round().matrix());
  scanner.Scan(world, caster, {}, X_WL, 2, &scan);
  std::vector<Triangle> near;
  for (const auto& tile : *terrain.drawn()) {
    if (tile->id.lod != 0) continue;
    for (std::size_t t = 0; t < tile->indices.size(); t += 3) {
      Vector3d v[3];
      for (int k = 0; k < 3; ++k) {
        v[k] = tile->origin_W + tile->positions[tile->indices[t + std::size_t(k)]].cast<double>();
      }
      if ((v[0] - X_WL.translation()).head<2>().norm() < 120.0) near.push_back({v[0], v[1], v[2]});
    }
  }
  ASSERT_GT(near.size(), 8u);
  const double terrain_error = WorstDownwardError(scan, X_WL, near, &occupied);
  EXPECT_GT(occupied, 2000);
  EXPECT_LT(terrain_error, 1e-3);
  std::cout << "worst hit error: plate at 20 km " << plate_error * 1e3 << " mm, terrain 100 km out "
            << terrain_error * 1e3 << " mm\n";
}

TEST(TerrainTest, ALongFlightStreamsTilesWithBoundedMemory) {
  testing::TempDir dir;
  const Level level = LoadLevel(dir.Write("level.toml", TerrainToml()));
  const TerrainSpec& spec = *level.terrain;
  CollisionWorld world(level);
  TerrainStreamer terrain(level);
  const TerrainSource source(spec);  // to name the tiles each place needs
  const double tile_m = source.fine_tile_m(), coarse_m = tile_m * spec.coarse_factor;
  std::size_t bound = 0;
  // The highlands flight at 10 Hz: 100 km east, from the ground to 20 km.
  for (int k = 0; k <= 3400; ++k) {
    const double t = 0.1 * k;
    sandbox_msgs::robot_pose_t pose;
    sandbox_msgs::bone_values_t bones;
    bridge::HighlandsFlight(t, k, 0, &pose, &bones);
    const Vector3d p(pose.position[0], pose.position[1], pose.position[2]);
    terrain.Update({p}, t, &world, TerrainStreamer::Wait::kFine);
    // Every fine tile within the collision radius is in the world now.
    std::vector<TileId> needed;
    source.TilesNear(p, 0, spec.collision_radius_m - 0.05 * spec.collision_radius_m, &needed);
    std::set<std::uint64_t> drawn;
    for (const auto& tile : *terrain.drawn()) drawn.insert(tile->id.key());
    for (const TileId& id : needed) {
      ASSERT_TRUE(drawn.count(id.key()))
          << "t = " << t << " s: fine tile " << id.tx << ", " << id.ty << " is missing";
    }
    // What may be kept: fine tiles within a tile past the radius of here and of
    // where the prefetch looks, coarse ones within a coarse tile past the view radius.
    std::vector<TileId> keep;
    const Vector3d ahead = p + spec.prefetch_s * Vector3d(bridge::kHighlandsSpeed_mps, 0, 0);
    source.TilesNear(p, 0, spec.collision_radius_m + tile_m + 0.05 * spec.collision_radius_m,
                     &keep);
    source.TilesNear(ahead, 0, spec.collision_radius_m + tile_m + 0.05 * spec.collision_radius_m,
                     &keep);
    source.TilesNear(p, 1, spec.view_radius_m + coarse_m, &keep);
    std::sort(keep.begin(), keep.end());
    keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
    bound = std::max(bound, keep.size());
  }
  const TerrainStreamer::Figures f = terrain.figures();
  std::cout << f.built << " tiles built (" << f.fine_built << " fine), " << f.dropped
            << " dropped, peak " << f.peak_resident_tiles << " tiles (bound " << bound << "), "
            << (f.peak_resident_bytes >> 20) << " MB\n";
  EXPECT_EQ(f.failed, 0);
  EXPECT_LE(std::size_t(f.peak_resident_tiles), bound);
  EXPECT_GT(f.fine_built, 3 * f.peak_resident_tiles / 2);  // tiles came and went
  EXPECT_GT(f.dropped, f.built / 2);
  EXPECT_LT(f.peak_resident_bytes, std::size_t(120) << 20);
  EXPECT_TRUE(terrain.TakeMessages().empty());
}

TEST(TerrainTest, TheChaseCameraHoldsTheWingSteadyAt20kmAnd100km) {
  const Level level = LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/highlands/level.toml");
  RobotState wing(level.robots.front());
  TerrainStreamer terrain(level);
  auto renderer = render::MakeRenderer();
  renderer->SetLevel(level, {});
  render::ChaseCamera chase({});
  render::CameraView view;
  view.far_m = 8e5;
  // The flight past 100 km at 20 km (t = 333 s), a frame every 1/30 s after 3 s of following.
  std::vector<Eigen::Vector2d> centres;
  for (int k = 0; k < 100; ++k) {
    const double t = 330.0 + k / 30.0;
    sandbox_msgs::robot_pose_t pose;
    sandbox_msgs::bone_values_t bones;
    bridge::HighlandsFlight(t, k, 0, &pose, &bones);
    const Eigen::Quaterniond q(pose.orientation[0], pose.orientation[1], pose.orientation[2],
                               pose.orientation[3]);
    ASSERT_TRUE(wing.SetPose(
        Eigen::Translation3d(pose.position[0], pose.position[1], pose.position[2]) * q));
    ASSERT_TRUE(wing.SetBones(bones.values));
    wing.Update();
    view.X_WC = chase.Update(wing.pose(), 1.0 / 30.0);
    if (k < 90) continue;
    if (k == 90) {
      terrain.Update({wing.pose().translation()}, t, nullptr, TerrainStreamer::Wait::kAll);
      renderer->SetTerrain(terrain.drawn());
    }
    render::Frame frame;
    renderer->Render(view, {}, {&wing}, {}, &frame);
    // The wing's pixels: everything nearer than 200 m (the ground is 20 km below).
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int count = 0;
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        if (frame.depth_m[std::size_t(y * frame.width + x)] < 200.f)
          sum += Eigen::Vector2d(x, y), ++count;
      }
    }
    ASSERT_GT(count, 40) << "the wing is not in view";
    centres.push_back(sum / count);
  }
  ASSERT_FALSE(terrain.drawn()->empty());
  double worst = 0.0;
  for (std::size_t i = 1; i < centres.size(); ++i) {
    worst = std::max(worst, (centres[i] - centres[i - 1]).norm());
  }
  std::cout << "wing centre moved at most " << worst << " px between frames\n";
  EXPECT_LT(worst, 0.5);
}

TEST(TerrainTest, BadRastersAreLeftOutWithTheirReasonAndTheRestServes) {
  testing::TempDir dir;
  dir.Write("text.tif", "this is no raster\n");
  // A raster without georeferencing: 4 x 4 samples, no geotransform, no CRS.
  GDALAllRegister();
  const std::string bare = (dir.path() / "bare.tif").string();
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), bare.c_str(), 4, 4, 1, GDT_Float32, nullptr);
  ASSERT_NE(dataset, nullptr);
  GDALClose(dataset);
  const Level level = LoadLevel(dir.Write(
      "level.toml", "[[terrain]]\nname = \"t\"\nelevation = [\"text.tif\", \"bare.tif\", \"" +
                        Generated("elevation.tif") + "\"]\nanchor = [46.5, 8.2, 450.0]\n"));
  ASSERT_EQ(level.warnings.size(), 2u);
  EXPECT_NE(level.warnings[0].find("text.tif"), std::string::npos) << level.warnings[0];
  EXPECT_NE(level.warnings[0].find("left out"), std::string::npos) << level.warnings[0];
  EXPECT_NE(level.warnings[1].find("bare.tif: it has no georeferencing"), std::string::npos)
      << level.warnings[1];
  // The good raster serves; a robot beyond it is reported once, and again only after it returns.
  CollisionWorld world(level);
  TerrainStreamer terrain(level);
  terrain.Update({Vector3d(500, 0, 10)}, 0.0, &world, TerrainStreamer::Wait::kFine);
  EXPECT_GT(world.num_tiles(), 0);
  std::vector<std::string> messages = terrain.TakeMessages();
  EXPECT_EQ(messages.size(), 2u);  // the two rasters left out
  for (double x : {-30000.0, -31000.0, -32000.0}) {
    terrain.Update({Vector3d(x, 0, 10)}, 1.0 - x / 1000.0, &world, TerrainStreamer::Wait::kFine);
  }
  messages = terrain.TakeMessages();
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("robot 0 at (-30000, 0) m is beyond every elevation raster"),
            std::string::npos)
      << messages[0];
}

TEST(TerrainTest, TheTileCacheGivesBackTheSameTilesAndAFolderThatCannotBeMadeIsSaidOnce) {
  testing::TempDir dir;
  const Level level = LoadLevel(dir.Write("level.toml", TerrainToml("", "cache = \"tiles\"\n")));
  auto tiles_at = [&](const Level& with, const Vector3d& p, TerrainStreamer::Figures* figures,
                      std::vector<std::string>* messages) {
    CollisionWorld world(with);
    TerrainStreamer terrain(with);
    terrain.Update({p}, 0.0, &world, TerrainStreamer::Wait::kAll);
    *figures = terrain.figures();
    *messages = terrain.TakeMessages();
    return terrain.drawn();
  };
  TerrainStreamer::Figures first, second;
  std::vector<std::string> messages;
  const auto built = tiles_at(level, Vector3d(20000, 5000, 0), &first, &messages);
  EXPECT_TRUE(messages.empty());
  EXPECT_EQ(first.from_cache, 0);
  ASSERT_GT(first.built, 4);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path() / "tiles"),
                          std::filesystem::directory_iterator{}),
            first.built);
  const auto read = tiles_at(level, Vector3d(20000, 5000, 0), &second, &messages);
  EXPECT_EQ(second.from_cache, second.built);
  ASSERT_EQ(read->size(), built->size());
  for (std::size_t t = 0; t < read->size(); ++t) {
    const TerrainTile &a = *(*built)[t], &b = *(*read)[t];
    EXPECT_EQ(a.id.key(), b.id.key());
    EXPECT_EQ(a.origin_W, b.origin_W);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.indices, b.indices);
    EXPECT_EQ(a.skirt_indices, b.skirt_indices);
    EXPECT_EQ(a.block_first, b.block_first);
  }
  // A damaged file is built again, not read.
  const auto first_file = *std::filesystem::directory_iterator(dir.path() / "tiles");
  std::filesystem::resize_file(first_file.path(), 100);
  tiles_at(level, Vector3d(20000, 5000, 0), &second, &messages);
  EXPECT_EQ(second.from_cache, second.built - 1);
  // A cache "folder" that is a file: said once, tiles built all the same.
  dir.Write("taken", "a file\n");
  const Level blocked =
      LoadLevel(dir.Write("blocked.toml", TerrainToml("", "cache = \"taken/tiles\"\n")));
  const auto without = tiles_at(blocked, Vector3d(20000, 5000, 0), &second, &messages);
  EXPECT_EQ(without->size(), built->size());
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("terrain cache " + (dir.path() / "taken/tiles").string() +
                             " cannot be made"),
            std::string::npos)
      << messages[0];
}

TEST(TerrainTest, ManifestMistakesNameTheKey) {
  testing::TempDir dir;
  auto error_of = [&](const std::string& text) {
    try {
      LoadLevel(dir.Write("level.toml", text));
    } catch (const LevelError& error) {
      return std::string(error.what());
    }
    return std::string("(loaded)");
  };
  EXPECT_NE(
      error_of("[[terrain]]\nname = \"t\"\nelevation = \"x.tif\"\n").find("'anchor' is required"),
      std::string::npos);
  EXPECT_NE(error_of(TerrainToml("", "coarse_factor = 7\n")).find("multiple of 'coarse_factor'"),
            std::string::npos);
  EXPECT_NE(
      error_of("[[terrain]]\nname = \"t\"\nanchor = [0, 0, 0]\n").find("'elevation' is required"),
      std::string::npos);
  EXPECT_NE(error_of("[[terrain]]\nname = \"t\"\nelevation = \"x.tif\"\nanchor = [0, 0, 0]\n"
                     "view_radius_m = 10\n")
                .find("'view_radius_m' must not be below"),
            std::string::npos);
}

}  // namespace
}  // namespace sandbox::scene
