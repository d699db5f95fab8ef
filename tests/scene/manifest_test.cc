// Level manifests: placement of assets and every kind of bad input.

#include <gtest/gtest.h>

#include "scene/level.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using Eigen::Vector3d;
using testing::ObjBox;
using testing::TempDir;

class ManifestTest : public ::testing::Test {
 protected:
  ManifestTest() { dir_.Write("box.obj", ObjBox("box", 1, 2, 3)); }

  Level Load(const std::string& toml) { return LoadLevel(dir_.Write("level.toml", toml)); }

  // Loads and returns the error message; fails the test when loading succeeds.
  std::string Error(const std::string& toml) {
    try {
      Load(toml);
    } catch (const LevelError& error) {
      return error.what();
    }
    ADD_FAILURE() << "no error for:\n" << toml;
    return "";
  }

  std::string Manifest() const { return (dir_.path() / "level.toml").string(); }

  TempDir dir_;
};

void ExpectBounds(const Actor& actor, const Vector3d& lo, const Vector3d& hi) {
  EXPECT_TRUE((actor.bounds_W.min() - lo).norm() < 1e-6)
      << actor.name << " min " << actor.bounds_W.min().transpose() << " expected "
      << lo.transpose();
  EXPECT_TRUE((actor.bounds_W.max() - hi).norm() < 1e-6)
      << actor.name << " max " << actor.bounds_W.max().transpose() << " expected "
      << hi.transpose();
}

TEST_F(ManifestTest, PlacesScalesAndRotatesAnAsset) {
  // Box [0,1]x[0,2]x[0,3], scaled 2: [0,2]x[0,4]x[0,6]; yaw 90 maps (x, y) to (-y, x):
  // x in [-4, 0], y in [0, 2]; then moved by (10, 0, 1).
  const Level level = Load(R"(
[level]
name = "placed"
[[actor]]
name = "a"
file = "box.obj"
position = [10, 0, 1]
rpy_deg = [0, 0, 90]
scale = 2
movable = true
[[actor]]
name = "b"
file = "box.obj"
position = [10, 0, 1]
quaternion_wxyz = [0.7071067811865476, 0, 0, 0.7071067811865476]
scale = [2, 2, 2]
collision = false
)");
  ASSERT_EQ(level.actors.size(), 2u);
  EXPECT_EQ(level.name, "placed");
  for (const Actor& actor : level.actors) {
    ExpectBounds(actor, {6, 0, 1}, {10, 2, 7});
    EXPECT_EQ(actor.num_triangles(), 12u);
  }
  EXPECT_TRUE(level.actors[0].movable);
  EXPECT_TRUE(level.actors[0].collision);
  EXPECT_FALSE(level.actors[1].movable);
  EXPECT_FALSE(level.actors[1].collision);
  EXPECT_TRUE(level.actors[0].X_WA.translation().isApprox(Vector3d(10, 0, 1)));
}

TEST_F(ManifestTest, PerAxisScaleUpAxisAndUnitScale) {
  // up = "y": asset (x, y, z) becomes world (x, -z, y); unit 0.5 halves it.
  const Level level = Load(R"(
[[actor]]
name = "stretched"
file = "box.obj"
scale = [1, 2, 3]
[[actor]]
name = "y_up"
file = "box.obj"
up = "y"
unit_scale = 0.5
)");
  ExpectBounds(level.actors[0], {0, 0, 0}, {1, 4, 9});
  ExpectBounds(level.actors[1], {0, -1.5, 0}, {0.5, 0, 1});
}

TEST_F(ManifestTest, SyntaxErrorNamesFileAndLine) {
  const std::string message = Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\nscale = 1\n");
  EXPECT_NE(message.find(Manifest() + ":3:"), std::string::npos) << message;
  EXPECT_NE(message.find("TOML syntax error"), std::string::npos) << message;
}

TEST_F(ManifestTest, UnknownKeyNamesKeyAndLine) {
  const std::string message =
      Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\ncolision = false\n");
  EXPECT_NE(message.find(Manifest() + ":4: actor 'a': unknown key 'colision'"), std::string::npos)
      << message;
  EXPECT_NE(Error("[levle]\nname = \"x\"\n[[actor]]\nname = \"a\"\nfile = \"box.obj\"\n")
                .find(":1: unknown key 'levle'"),
            std::string::npos);
}

// [wind]: the mean wind at a height, its shear layer linear; mistakes named.
TEST_F(ManifestTest, WindTakesAVelocityAShearLayerAndGusts) {
  const std::string actor = "[[actor]]\nname = \"a\"\nfile = \"box.obj\"\n";
  const Level level = Load(actor +
                           "[wind]\nvelocity = [4, 0, 0]\nshear_velocity = [10, 2, 0]\n"
                           "shear_bottom_m = 100\nshear_top_m = 300\ngust_sigma_m_s = 1\n");
  ASSERT_TRUE(level.wind.has_value());
  EXPECT_EQ(level.wind->At(50.0), Vector3d(4, 0, 0));
  EXPECT_EQ(level.wind->At(200.0), Vector3d(7, 1, 0));
  EXPECT_EQ(level.wind->At(1e4), Vector3d(10, 2, 0));
  EXPECT_EQ(level.wind->gust_length_m, 533.4);
  EXPECT_FALSE(Load(actor).wind.has_value());
  EXPECT_NE(Error(actor + "[wind]\nshear_velocity = [1, 0, 0]\n")
                .find(":4: [wind]: a shear layer takes shear_velocity, shear_bottom_m and "
                      "shear_top_m"),
            std::string::npos);
  EXPECT_NE(Error(actor + "[wind]\nshear_velocity = [1, 0, 0]\nshear_bottom_m = 5\n"
                          "shear_top_m = 5\n")
                .find(":7: [wind]: 'shear_top_m' must be above 'shear_bottom_m'"),
            std::string::npos);
  EXPECT_NE(Error(actor + "[wind]\ngust_sigma_m_s = -1\n")
                .find(":5: [wind]: 'gust_sigma_m_s' must be zero or positive"),
            std::string::npos);
  EXPECT_NE(Error(actor + "[wind]\nvelocity = [1, 2]\n").find(":5: [wind]: 'velocity'"),
            std::string::npos);
  EXPECT_NE(Error(actor + "[wind]\nspeed = 3\n").find(":5: [wind]: unknown key 'speed'"),
            std::string::npos);
}

TEST_F(ManifestTest, WrongTypes) {
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\ncollision = \"yes\"\n")
                .find(":4: actor 'a': 'collision' must be true or false"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nscale = \"big\"\n")
                .find(":4: actor 'a': 'scale' must be a number"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nposition = [1, 2]\n")
                .find("'position' must be an array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = 7\nfile = \"box.obj\"\n").find("'name' must be a string"),
            std::string::npos);
  EXPECT_NE(Error("actor = 3\n").find("'actor' must be an array of tables"), std::string::npos);
}

TEST_F(ManifestTest, NegativeScaleAndNonFiniteNumbers) {
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nscale = -1\n")
                .find(Manifest() + ":4: actor 'a': 'scale' must be positive, got -1"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nposition = [0, nan, 0]\n")
                .find(":4: actor 'a': 'position' must be finite, got nan"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nscale = inf\n")
                .find("'scale' must be finite"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nquaternion_wxyz = [1, 1, 0, 0]\n")
                .find("'quaternion_wxyz' must be a unit quaternion"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nup = \"sideways\"\n")
                .find("'up' must be one of"),
            std::string::npos);
}

TEST_F(ManifestTest, MissingAndConflictingKeys) {
  EXPECT_NE(Error("[[actor]]\nfile = \"box.obj\"\n").find(":1: actor 1: 'name' is required"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\n").find("give exactly one of 'file' and 'heightmap'"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\n[[actor]]\nname = \"a\"\n"
                  "file = \"box.obj\"\n")
                .find(":4: duplicate actor name 'a': the [[actor]] on line 1 has it too"),
            std::string::npos);
  EXPECT_NE(Error("[[actor]]\nname = \"a\"\nfile = \"box.obj\"\nrpy_deg = [0, 0, 0]\n"
                  "quaternion_wxyz = [1, 0, 0, 0]\n")
                .find("not both"),
            std::string::npos);
  EXPECT_NE(Error("[level]\nname = \"empty\"\n").find("places nothing"), std::string::npos);
}

TEST_F(ManifestTest, BadAssetFilesNameManifestLineAndAsset) {
  const std::string missing = Error("\n[[actor]]\nname = \"a\"\nfile = \"nowhere.obj\"\n");
  EXPECT_NE(missing.find(Manifest() + ":2: actor 'a': "), std::string::npos) << missing;
  EXPECT_NE(missing.find("nowhere.obj: no such file"), std::string::npos) << missing;

  dir_.Write("notes.xyz", "not a model\n");
  EXPECT_NE(
      Error("[[actor]]\nname = \"a\"\nfile = \"notes.xyz\"\n").find("unsupported format '.xyz'"),
      std::string::npos);

  dir_.Write("points.obj", "v 0 0 0\nv 1 0 0\n");
  const std::string no_meshes = Error("[[actor]]\nname = \"a\"\nfile = \"points.obj\"\n");
  EXPECT_NE(no_meshes.find("points.obj: has no triangle meshes"), std::string::npos) << no_meshes;
}

}  // namespace
}  // namespace sandbox::scene
