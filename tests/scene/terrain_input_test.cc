// The terrain's inputs as an outside tester tries them: rasters that are
// FIFOs or name FIFOs, sparse giants, absurd heights, damaged imagery and
// tile-cache files, rasters across the antimeridian and past a pole, lying
// coordinate systems, and settings beyond any physical sense. Every raster is written here with
// GDAL; expected heights come from the values written, not from the terrain code.

#include <gdal.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/terrain_cache.h"
#include "scene/terrain_source.h"
#include "scene/terrain_streamer.h"
#include "tests/test_rasters.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using Eigen::Vector3d;
namespace fs = std::filesystem;
using testing::WriteRaster;

constexpr double kGround_m = 500.0;  // the flat rasters' height

// A flat elevation raster of 129 x 129 samples 0.0003 deg apart (about 33 m
// north-south) with its north-west corner at (lon0, lat0).
void WriteFlat(const fs::path& file, double lon0 = 8.0, double lat0 = 46.02,
               const std::function<double(int, int)>& height = nullptr) {
  WriteRaster(file, 129, 129, lon0, lat0, 0.0003, 1, GDT_Float32,
              [&](int c, int r, int) { return height ? height(c, r) : kGround_m; });
}

// A [[terrain]] over the flat rasters with `keys`; the tile settings below
// for those `keys` does not set.
std::string TerrainToml(const std::string& keys) {
  std::string toml = "[[terrain]]\nname = \"ground\"\nanchor = [46.0, 8.02, " +
                     std::to_string(kGround_m) + "]\n" + keys;
  for (const char* key : {"tile_samples = 32", "coarse_factor = 4", "collision_radius_m = 400",
                          "view_radius_m = 1500"}) {
    const std::string name = std::string(key).substr(0, std::string(key).find(' '));
    if (keys.find(name + " =") == std::string::npos) toml += std::string(key) + "\n";
  }
  return toml;
}

std::string LoadError(const testing::TempDir& dir, const std::string& toml) {
  try {
    LoadLevel(dir.Write("level.toml", toml));
  } catch (const LevelError& error) {
    return error.what();
  }
  return "(loaded)";
}

// Straight down from 100 m above the anchor's height at (x, y): the distance
// to the terrain, after the streamer built what is near (all of it).
struct Probe {
  explicit Probe(const Level& with) : level(with), world(with), terrain(with) {}
  std::optional<double> Down(double x, double y) {
    const Vector3d p(x, y, 100.0);
    terrain.Update({p}, t_s += 1.0, &world, TerrainStreamer::Wait::kAll);
    const auto hit = world.CastRay(p, p - Vector3d(0, 0, 1000));
    if (!hit || hit->actor != level.terrain_actor) return std::nullopt;
    return hit->distance_m;
  }
  const Level& level;
  CollisionWorld world;
  TerrainStreamer terrain;
  double t_s{0.0};
};

// The ground of a flat raster at height kGround_m lies below the tangent plane
// at the anchor by the Earth's curvature: d^2 / (2 R) at d from the anchor.
double ExpectedDown(double x, double y) { return 100.0 + (x * x + y * y) / (2.0 * 6371000.0); }

TEST(TerrainInputTest, AFifoAsARasterOrNamedByAVrtIsLeftOutAtOnce) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  ASSERT_EQ(mkfifo((dir.path() / "pipe.tif").c_str(), 0600), 0);
  dir.Write("names_pipe.vrt",
            "<VRTDataset rasterXSize=\"129\" rasterYSize=\"129\">\n"
            "  <GeoTransform>8.0, 0.0003, 0, 46.02, 0, -0.0003</GeoTransform>\n"
            "  <VRTRasterBand dataType=\"Float32\" band=\"1\">\n"
            "    <SimpleSource><SourceFilename relativeToVRT=\"1\">pipe.tif</SourceFilename>\n"
            "      <SourceBand>1</SourceBand></SimpleSource>\n"
            "  </VRTRasterBand>\n</VRTDataset>\n");
  // As elevation: left out, said; the good raster still serves.
  for (const std::string name : {"pipe.tif", "names_pipe.vrt"}) {
    const Level level = LoadLevel(
        dir.Write("level.toml", TerrainToml("elevation = [\"" + name + "\", \"flat.tif\"]\n")));
    ASSERT_EQ(level.warnings.size(), 1u) << name;
    EXPECT_NE(level.warnings[0].find("is a FIFO, not a regular file"), std::string::npos)
        << level.warnings[0];
    Probe probe(level);
    const auto down = probe.Down(100, 100);
    ASSERT_TRUE(down.has_value()) << name;
    EXPECT_NEAR(*down, ExpectedDown(100, 100), 0.05);
  }
  // As imagery: drawn without it.
  const Level imagery = LoadLevel(
      dir.Write("level.toml", TerrainToml("elevation = \"flat.tif\"\nimagery = \"pipe.tif\"\n")));
  ASSERT_EQ(imagery.warnings.size(), 1u);
  EXPECT_NE(imagery.warnings[0].find("pipe.tif: is a FIFO"), std::string::npos)
      << imagery.warnings[0];
}

TEST(TerrainInputTest, BudgetsRefuseTerrainWorkBeyondThemAtLoadNamingTheFigureAndKey) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  // A sparse imagery raster of 1,000,000 x 1,000,000 px over the same ground
  // (11 MB on disk): a fine tile's texture would resample a window of
  // about 2e10 px.
  WriteRaster(dir.path() / "giant.tif", 1000000, 1000000, 8.0, 46.02, 0.0384 / 1e6, 3, GDT_Byte,
              nullptr,
              {"TILED=YES", "BLOCKXSIZE=4096", "BLOCKYSIZE=4096", "SPARSE_OK=TRUE", "BIGTIFF=YES"});
  std::string error =
      LoadError(dir, TerrainToml("elevation = \"flat.tif\"\nimagery = \"giant.tif\"\n"));
  EXPECT_NE(error.find("giant.tif: a fine tile's texture reads a window of about"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("([level] max_imagery_window_px"), std::string::npos) << error;
  // Samples per tile, tiles near a robot, their memory.
  error = LoadError(
      dir, "[level]\nmax_tile_samples = 1000\n" + TerrainToml("elevation = \"flat.tif\"\n"));
  EXPECT_NE(error.find("tile_samples 32 makes tiles of 1089 samples, over the limit of 1000 "
                       "([level] max_tile_samples"),
            std::string::npos)
      << error;
  error = LoadError(dir, TerrainToml("elevation = \"flat.tif\"\ntile_samples = 4096\n"));
  EXPECT_NE(error.find("tile_samples 4096 makes tiles of 16785409 samples, over the limit of "
                       "1050625"),
            std::string::npos)
      << error;  // the documented maximum of tile_samples, refused by the default budget
  error = LoadError(dir, TerrainToml("elevation = \"flat.tif\"\ntile_samples = 2\n"
                                     "coarse_factor = 1\n"));
  EXPECT_NE(error.find("tiles near a robot at once"), std::string::npos) << error;
  EXPECT_NE(error.find("([level] max_terrain_tiles"), std::string::npos) << error;
  WriteRaster(dir.path() / "small.tif", 64, 64, 8.0, 46.02, 0.0384 / 64, 3, GDT_Byte,
              [](int, int, int) { return 128.0; });
  error = LoadError(dir, "[level]\nmax_terrain_mb = 1\n" +
                             TerrainToml("elevation = \"flat.tif\"\nimagery = \"small.tif\"\n"
                                         "texture_px = 4096\n"));
  EXPECT_NE(error.find("MB of tiles near a robot at once"), std::string::npos) << error;
  // A raised budget lets the same level load.
  EXPECT_EQ(LoadError(dir, "[level]\nmax_terrain_tiles = 100000\n" +
                               TerrainToml("elevation = \"flat.tif\"\ntile_samples = 2\n"
                                           "coarse_factor = 1\n")),
            "(loaded)");
}

TEST(TerrainInputTest, SettingsBeyondPhysicalSenseAreRefusedNamingTheKey) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  const std::string flat = "elevation = \"flat.tif\"\n";
  EXPECT_NE(LoadError(dir, TerrainToml(flat + "collision_radius_m = 5e12\n"))
                .find("'collision_radius_m' must be at most 20000000"),
            std::string::npos);
  EXPECT_NE(LoadError(dir, TerrainToml(flat + "view_radius_m = 5e12\n"))
                .find("'view_radius_m' must be at most"),
            std::string::npos);
  EXPECT_NE(LoadError(dir,
                      "[[terrain]]\nname = \"g\"\nelevation = \"flat.tif\"\n"
                      "anchor = [46.0, 8.02, 1e308]\n")
                .find("'anchor' height must be from -12000 to 100000 m"),
            std::string::npos);
  EXPECT_NE(LoadError(dir, TerrainToml(flat) + "[horizon]\nvisibility_m = 1e-300\n")
                .find("'visibility_m' must be at least 1 m"),
            std::string::npos);
}

TEST(TerrainInputTest, OneAbsurdHeightIsNoDataAndTheRestOfItsTileStands) {
  testing::TempDir dir;
  // -3.4e38 (an undeclared float no-data) at one sample, a bit-flipped 1e30 at another.
  WriteFlat(dir.path() / "spikes.tif", 8.0, 46.02, [](int c, int r) {
    if (c == 64 && r == 64) return -3.4e38;
    if (c == 70 && r == 60) return 1e30;
    return kGround_m;
  });
  const Level level =
      LoadLevel(dir.Write("level.toml", TerrainToml("elevation = \"spikes.tif\"\n")));
  Probe probe(level);
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{0, 0}, {150, -120}, {-300, 200}, {40, 30}}) {
    const auto down = probe.Down(x, y);
    ASSERT_TRUE(down.has_value()) << x << ", " << y;
    EXPECT_NEAR(*down, ExpectedDown(x, y), 0.05) << x << ", " << y;
  }
  const std::vector<std::string> messages = probe.terrain.TakeMessages();
  ASSERT_EQ(messages.size(), 1u);  // once for the raster, however many tiles
  EXPECT_NE(messages[0].find("spikes.tif: "), std::string::npos) << messages[0];
  EXPECT_NE(messages[0].find("beyond 12 km of the ellipsoid: taken as no data"), std::string::npos)
      << messages[0];
}

TEST(TerrainInputTest, DamagedImageryLeavesTheGroundAndIsSaidOnce) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  WriteRaster(dir.path() / "image.tif", 512, 512, 8.0, 46.02, 0.0384 / 512, 3, GDT_Byte,
              [](int c, int r, int b) { return (c * 7 + r * 3 + b * 50) % 256; },
              {"COMPRESS=DEFLATE", "TILED=YES"});
  // Cut short: the header and the tile index stand, the tiles' data does not.
  fs::resize_file(dir.path() / "image.tif", fs::file_size(dir.path() / "image.tif") / 3);
  const Level level = LoadLevel(
      dir.Write("level.toml", TerrainToml("elevation = \"flat.tif\"\nimagery = \"image.tif\"\n")));
  Probe probe(level);
  const auto down = probe.Down(-200, 150);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(*down, ExpectedDown(-200, 150), 0.05);
  const std::vector<std::string> messages = probe.terrain.TakeMessages();
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("image.tif: cannot read imagery"), std::string::npos) << messages[0];
  EXPECT_NE(messages[0].find("keep their ground and base colour"), std::string::npos)
      << messages[0];
  EXPECT_EQ(probe.terrain.figures().failed, 0);
}

TEST(TerrainInputTest, ARasterAcrossTheAntimeridianServesBothSides) {
  testing::TempDir dir;
  // Longitude 179.9 to about 180.1 (past 180), latitude 0.1 to -0.1.
  WriteRaster(dir.path() / "dateline.tif", 201, 201, 179.9, 0.1, 0.001, 1, GDT_Float32,
              [](int, int, int) { return kGround_m; });
  const Level level =
      LoadLevel(dir.Write("level.toml",
                          "[[terrain]]\nname = \"ground\"\nelevation = \"dateline.tif\"\n"
                          "anchor = [0.0, 180.0, 500.0]\ntile_samples = 32\ncoarse_factor = 4\n"
                          "collision_radius_m = 500\nview_radius_m = 2000\n"));
  ASSERT_TRUE(level.warnings.empty()) << level.warnings.front();
  Probe probe(level);
  for (const double x : {-3000.0, 0.0, 3000.0}) {  // west (+179.97), on, east (-179.97)
    const auto down = probe.Down(x, 500);
    ASSERT_TRUE(down.has_value()) << x;
    EXPECT_NEAR(*down, ExpectedDown(x, 500), 0.05) << x;
  }
  EXPECT_TRUE(probe.terrain.TakeMessages().empty());
}

TEST(TerrainInputTest, ARasterPastAPoleOrWithANonFiniteGeotransformIsLeftOutSaid) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  WriteRaster(dir.path() / "pole.tif", 64, 64, 8.0, 90.5, 0.01, 1, GDT_Float32,
              [](int, int, int) { return kGround_m; });
  const Level level =
      LoadLevel(dir.Write("level.toml", TerrainToml("elevation = [\"pole.tif\", \"flat.tif\"]\n")));
  ASSERT_EQ(level.warnings.size(), 1u);
  EXPECT_NE(level.warnings[0].find("pole.tif: it reaches latitude 90.5"), std::string::npos)
      << level.warnings[0];
  // A world file (.tfw) with a NaN pixel size beside a GeoTIFF without one of its own.
  WriteRaster(dir.path() / "nan.tif", 64, 64, 8.0, 46.0, 0.001, 1, GDT_Float32,
              [](int, int, int) { return kGround_m; });
  dir.Write("nan.tfw", "nan\n0\n0\n-0.001\n8.0\n46.0\n");
  GDALAllRegister();
  GDALDatasetH nan = GDALOpen((dir.path() / "nan.tif").c_str(), GA_Update);
  ASSERT_NE(nan, nullptr);
  double gt[6] = {8.0, std::nan(""), 0, 46.0, 0, -0.001};
  GDALSetGeoTransform(nan, gt);
  GDALClose(nan);
  const Level level2 =
      LoadLevel(dir.Write("level.toml", TerrainToml("elevation = [\"nan.tif\", \"flat.tif\"]\n")));
  ASSERT_EQ(level2.warnings.size(), 1u);
  EXPECT_NE(level2.warnings[0].find("nan.tif: "), std::string::npos) << level2.warnings[0];
  EXPECT_NE(level2.warnings[0].find("left out"), std::string::npos) << level2.warnings[0];
}

// The one warning a level gives when `name` is listed before a good raster.
std::string LeftOutWarning(const testing::TempDir& dir, const std::string& name) {
  WriteFlat(dir.path() / "flat.tif");
  const Level level = LoadLevel(
      dir.Write("level.toml", TerrainToml("elevation = [\"" + name + "\", \"flat.tif\"]\n")));
  EXPECT_EQ(level.warnings.size(), 1u);
  return level.warnings.empty() ? "" : level.warnings[0];
}

// Found by the fuzz target: a raster whose samples are a nanometre apart (its
// tile estimates were NaN), and one whose blocks claim more than 256 MB (a
// header asked GDAL for 5 GB to read 17 x 17 samples): each left out, said.
TEST(TerrainInputTest, ARasterWithoutMeasurableSpacingOrWithHugeBlocksIsLeftOutSaid) {
  testing::TempDir dir;
  WriteRaster(dir.path() / "tiny.tif", 64, 64, 8.0, 46.0, 1e-14, 1, GDT_Float32,
              [](int, int, int) { return kGround_m; });
  std::string warning = LeftOutWarning(dir, "tiny.tif");
  EXPECT_NE(warning.find("m apart at its middle, not 1 mm to 1000 km; this raster is left out"),
            std::string::npos)
      << warning;
  WriteRaster(dir.path() / "strips.tif", 70000, 1000, 8.0, 46.02, 0.0384 / 70000, 1, GDT_Float32,
              nullptr, {"BLOCKYSIZE=1000", "COMPRESS=DEFLATE", "SPARSE_OK=TRUE"});
  warning = LeftOutWarning(dir, "strips.tif");
  EXPECT_NE(warning.find("strips.tif: its blocks of 70000 x 1000 samples take 267 MB each, over "
                         "256 MB"),
            std::string::npos)
      << warning;
}

// Found by the fuzz target: a GeoTIFF whose geographic key holds EPSG:4342, a
// geocentric system; PROJ 9.1 crashes making a transformation from it. Left
// out, said, before PROJ is asked; a geographic key holding 4326 still serves.
TEST(TerrainInputTest, ARasterWhoseCoordinateSystemClaimsAnotherKindOfCodeIsLeftOutSaid) {
  testing::TempDir dir;
  const auto geographic = [](const std::string& code) {
    return "GEOGCS[\"X\",DATUM[\"D\",SPHEROID[\"GRS 1980\",6378137,298.257223563]],"
           "PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433],"
           "AUTHORITY[\"EPSG\",\"" +
           code + "\"]]";
  };
  WriteRaster(
      dir.path() / "geocentric.tif", 64, 64, 8.0, 46.0, 0.001, 1, GDT_Float32,
      [](int, int, int) { return kGround_m; }, {}, geographic("4342"));
  const std::string warning = LeftOutWarning(dir, "geocentric.tif");
  EXPECT_NE(warning.find("geocentric.tif: its coordinate system is geographic but calls itself "
                         "EPSG:4342, which is geocentric"),
            std::string::npos)
      << warning;
  WriteRaster(
      dir.path() / "honest.tif", 129, 129, 8.0, 46.02, 0.0003, 1, GDT_Float32,
      [](int, int, int) { return kGround_m; }, {}, geographic("4326"));
  const Level level =
      LoadLevel(dir.Write("level.toml", TerrainToml("elevation = [\"honest.tif\"]\n")));
  EXPECT_TRUE(level.warnings.empty()) << level.warnings[0];
  Probe probe(level);
  const auto down = probe.Down(0.0, 0.0);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(*down, ExpectedDown(0.0, 0.0), 0.05);
}

// Cache files written through the cache itself from a built tile with one
// thing wrong: each is reported, built again, and the rebuilt tile is sound.
TEST(TerrainInputTest, DamagedTileCacheFilesAreReportedAndBuiltAgain) {
  testing::TempDir dir;
  WriteFlat(dir.path() / "flat.tif");
  WriteRaster(dir.path() / "image.tif", 512, 512, 8.0, 46.02, 0.0384 / 512, 3, GDT_Byte,
              [](int c, int r, int b) { return (c + r + b * 40) % 256; });
  const Level level = LoadLevel(
      dir.Write("level.toml", TerrainToml("elevation = \"flat.tif\"\nimagery = \"image.tif\"\n"
                                          "cache = \"tiles\"\ntexture_px = 64\n")));
  const TerrainSource source(*level.terrain);
  std::vector<TileId> near;
  source.TilesNear(Vector3d(0, 0, 0), 0, 1.0, &near);
  ASSERT_FALSE(near.empty());
  const TileId id = near.front();
  const TerrainTile good = source.Build(id);
  ASSERT_EQ(TerrainCache::Problem(good, *level.terrain), "");
  ASSERT_FALSE(good.uvs.empty());
  const std::vector<std::pair<std::string, std::function<void(TerrainTile*)>>> damages = {
      {"texture of 64 x 64 px with", [](TerrainTile* t) { t->texture_rgba.resize(100); }},
      {"texture of 4096 x 4096 px where texture_px is 64",
       [](TerrainTile* t) { t->texture_width = t->texture_height = 4096; }},
      {"a position not finite", [](TerrainTile* t) { t->positions[5].x() = NAN; }},
      {"a position not finite or far out", [](TerrainTile* t) { t->positions[7].z() = 1e30f; }},
      {"normals and positions differ", [](TerrainTile* t) { t->normals.clear(); }},
      {"a uv not finite", [](TerrainTile* t) { t->uvs[3].y() = INFINITY; }},
      {"an index beyond the vertices",
       [](TerrainTile* t) { t->skirt_indices[0] = std::uint32_t(t->positions.size()); }},
      {"bounds not finite", [](TerrainTile* t) { t->bounds_W.min().y() = NAN; }},
      {"the origin not finite", [](TerrainTile* t) { t->origin_W.z() = INFINITY; }},
  };
  for (const auto& [why, damage] : damages) {
    TerrainTile bad = good;
    damage(&bad);
    TerrainCache(*level.terrain).Store(bad);
    TerrainCache::Loaded loaded = TerrainCache(*level.terrain).Load(id);
    EXPECT_FALSE(loaded.tile.has_value()) << why;
    EXPECT_NE(loaded.damage.find(".tile: " + why), std::string::npos)
        << why << " | " << loaded.damage;
    // Through the streamer: said once, built again, the ray lands.
    Probe probe(level);
    const auto down = probe.Down(0, 0);
    ASSERT_TRUE(down.has_value()) << why;
    EXPECT_NEAR(*down, ExpectedDown(0, 0), 0.05) << why;
    const auto messages = probe.terrain.TakeMessages();
    ASSERT_EQ(messages.size(), 1u) << why;
    EXPECT_NE(messages[0].find("built again from the rasters"), std::string::npos) << messages[0];
    // The rebuilt file serves the next run.
    EXPECT_TRUE(TerrainCache(*level.terrain).Load(id).tile.has_value()) << why;
  }
  // A 2.5 GB sparse file where a tile belongs: refused by its size, unread.
  const fs::path file = [&] {
    for (const auto& entry : fs::directory_iterator(dir.path() / "tiles")) return entry.path();
    return fs::path();
  }();
  ASSERT_FALSE(file.empty());
  fs::resize_file(file, std::uint64_t(2500) << 20);
  for (const auto& entry : fs::directory_iterator(dir.path() / "tiles")) {
    if (entry.path() != file) fs::remove(entry.path());
  }
  Probe probe(level);
  ASSERT_TRUE(probe.Down(0, 0).has_value());
  const auto messages = probe.terrain.TakeMessages();
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("2621440000 bytes, more than a tile of these settings takes"),
            std::string::npos)
      << messages[0];
  EXPECT_LT(fs::file_size(file), std::uint64_t(10) << 20);  // rewritten whole
}

}  // namespace
}  // namespace sandbox::scene
