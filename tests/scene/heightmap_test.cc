// Heightmap images and Terragen terrains.

#include "scene/heightmap.h"

#include <gtest/gtest.h>

#include <cstring>

#include "scene/level.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using testing::TempDir;

TEST(HeightmapTest, PgmPlacedByManifest) {
  TempDir dir;
  // 3 x 2 pixels, 16 bit, max 1000; row 0 is the north (+y) edge.
  const unsigned short values[6] = {0, 500, 1000, 250, 750, 100};
  std::string pgm = "P5\n# test\n3 2\n1000\n";
  for (const unsigned short v : values) pgm += {char(v >> 8), char(v & 0xff)};
  dir.Write("hills.pgm", pgm);
  const Level level = LoadLevel(dir.Write("level.toml", R"(
[[actor]]
name = "hills"
heightmap = "hills.pgm"
size = [4, 2, 10]
position = [100, 0, 0]
)"));
  ASSERT_EQ(level.actors.size(), 1u);
  const Mesh& mesh = level.actors[0].meshes.at(0);
  ASSERT_EQ(mesh.positions_A.size(), 6u);
  EXPECT_EQ(mesh.num_triangles(), 4u);
  // Centred on the actor: x in [-2, 2] step 2, y = +1 (row 0) and -1 (row 1).
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      const Eigen::Vector3f& p = mesh.positions_A[std::size_t(row * 3 + col)];
      EXPECT_FLOAT_EQ(p.x(), -2.0f + 2.0f * col);
      EXPECT_FLOAT_EQ(p.y(), 1.0f - 2.0f * row);
      EXPECT_FLOAT_EQ(p.z(), values[row * 3 + col] / 1000.0f * 10.0f);
    }
  }
  EXPECT_NEAR(level.actors[0].bounds_W.min().x(), 98.0, 1e-9);
  EXPECT_NEAR(level.actors[0].bounds_W.max().z(), 10.0, 1e-6);
  // Upward-facing triangles.
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    const Eigen::Vector3f a = mesh.positions_A[mesh.indices[3 * t]];
    const Eigen::Vector3f b = mesh.positions_A[mesh.indices[3 * t + 1]];
    const Eigen::Vector3f c = mesh.positions_A[mesh.indices[3 * t + 2]];
    EXPECT_GT((b - a).cross(c - a).z(), 0.0f) << "triangle " << t;
  }
}

// Terragen: SIZE 2 (3 x 3 points), SCAL 10 10 2, heightscale 256, baseheight 1.
std::string Terragen(const short heights[9]) {
  std::string out = "TERRAGENTERRAIN ";
  auto i16 = [&](int v) { out += {char(v & 0xff), char((v >> 8) & 0xff)}; };
  auto f32 = [&](float v) {
    char bytes[4];
    std::memcpy(bytes, &v, 4);
    out.append(bytes, 4);
  };
  out += "SIZE", i16(2), i16(0);
  out += "SCAL", f32(10), f32(10), f32(2);
  out += "ALTW", i16(256), i16(1);
  for (int i = 0; i < 9; ++i) i16(heights[i]);
  out += "EOF ";
  return out;
}

TEST(HeightmapTest, TerragenRowsRunSouthToNorth) {
  TempDir dir;
  const short heights[9] = {0, 256, 512, -256, 0, 0, 0, 0, 768};
  const Level level = LoadLevel(dir.Write("land.ter", Terragen(heights)));
  const Actor& actor = level.actors.at(0);
  // Elevation = (baseheight + h * heightscale / 65536) * SCAL z = (1 + h / 256) * 2.
  auto expected_z = [&](int i) { return (1.0 + heights[i] / 256.0) * 2.0; };
  Eigen::AlignedBox3d box = actor.bounds_W;
  EXPECT_NEAR(box.min().x(), 0.0, 1e-9);
  EXPECT_NEAR(box.max().x(), 20.0, 1e-9);
  EXPECT_NEAR(box.max().y(), 20.0, 1e-9);
  // File point i = file_row * 3 + col lies at x = 10 col, y = 10 file_row.
  int found = 0;
  for (const Eigen::Vector3f& p : actor.meshes.at(0).positions_A) {
    const Eigen::Vector3d p_W = actor.X_WA * p.cast<double>();
    const int col = int(std::lround(p_W.x() / 10)), file_row = int(std::lround(p_W.y() / 10));
    EXPECT_NEAR(p_W.z(), expected_z(file_row * 3 + col), 1e-5) << col << ", " << file_row;
    ++found;
  }
  EXPECT_EQ(found, 9);
}

TEST(HeightmapTest, BrokenTerragenIsAnError) {
  TempDir dir;
  const short heights[9] = {};
  std::string cut = Terragen(heights);
  cut.resize(cut.size() - 10);
  const auto file = dir.Write("cut.ter", cut);
  try {
    LoadLevel(file);
    FAIL() << "no error";
  } catch (const LevelError& error) {
    EXPECT_EQ(std::string(error.what()), file.string() + ": height grid is cut short");
  }
}

}  // namespace
}  // namespace sandbox::scene
