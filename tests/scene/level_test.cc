// Scene files as levels: actors per node, names, frames and bad files.

#include "scene/level.h"

#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "tests/scene/load_error.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using Eigen::Vector3d;
using testing::ObjBox;
using testing::TempDir;

// A glTF file with one triangle (0,0,0), (1,0,0), (0,1,0) (glTF is Y up) used
// by every node in `nodes_json`; the scene's roots are `roots`.
std::string Gltf(const std::string& roots, const std::string& nodes_json,
                 const std::string& material = "") {
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [)" + roots +
         R"(]}], "nodes": [)" + nodes_json +
         R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0})" +
         (material.empty() ? "" : R"(, "material": 0)") + R"(}]}],)" +
         (material.empty() ? "" : R"("materials": [)" + material + "],") +
         R"("buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})";
}

void ExpectNear(const Vector3d& actual, const Vector3d& expected, const std::string& what) {
  EXPECT_LT((actual - expected).norm(), 1e-6)
      << what << ": " << actual.transpose() << " expected " << expected.transpose();
}

TEST(LevelTest, ObjObjectsBecomeActorsInWorldZUp) {
  TempDir dir;
  const auto file =
      dir.Write("two.obj", ObjBox("left", 1, 2, 3) + ObjBox("right", 1, 1, 1, 5, 0, 0, 9));
  const Level level = LoadLevel(file);
  ASSERT_EQ(level.actors.size(), 2u);
  EXPECT_EQ(level.actors[0].name, "left");
  EXPECT_EQ(level.actors[1].name, "right");
  // OBJ does not say its up axis: taken as Z up, metres.
  ExpectNear(level.actors[0].bounds_W.min(), {0, 0, 0}, "left min");
  ExpectNear(level.actors[0].bounds_W.max(), {1, 2, 3}, "left max");
  ExpectNear(level.actors[1].bounds_W.min(), {5, 0, 0}, "right min");
  EXPECT_EQ(level.num_triangles(), 24u);
  EXPECT_EQ(level.FindActor("right"), 1);
  EXPECT_EQ(level.FindActor("nobody"), -1);
  EXPECT_TRUE(level.actors[0].collision);
  EXPECT_FALSE(level.actors[0].movable);
}

TEST(LevelTest, UpAxisAndUnitOverrideForAPlainFile) {
  TempDir dir;
  const auto file = dir.Write("box.obj", ObjBox("box", 1, 2, 3));
  AssetConversion conversion;
  conversion.up = UpAxis::kPosY;
  conversion.unit_scale_m = 0.01;
  const Level level = LoadLevel(file, conversion);
  // (x, y, z) -> (x, -z, y), in centimetres.
  ExpectNear(level.actors[0].bounds_W.min(), {0, -0.03, 0}, "min");
  ExpectNear(level.actors[0].bounds_W.max(), {0.01, 0, 0.02}, "max");
}

TEST(LevelTest, GltfIsYUpAndNodeTransformsPlaceActors) {
  TempDir dir;
  const auto file = dir.Write(
      "scene.gltf",
      Gltf("0", R"({"name": "parent", "translation": [0, 5, 0], "children": [1, 2]},
                  {"name": "plain", "mesh": 0},
                  {"name": "big", "mesh": 0, "scale": [2, 2, 2], "translation": [1, 0, 0]})",
           R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 0.5]}})"));
  const Level level = LoadLevel(file);
  ASSERT_EQ(level.actors.size(), 2u);
  const Actor& plain = level.actors[static_cast<std::size_t>(level.FindActor("plain"))];
  const Actor& big = level.actors[static_cast<std::size_t>(level.FindActor("big"))];
  // glTF y = 5 is world z = 5; the triangle's glTF (0, 1, 0) is world (0, 0, 1).
  ExpectNear(plain.X_WA.translation(), {0, 0, 5}, "plain pose");
  ExpectNear(plain.bounds_W.min(), {0, 0, 5}, "plain min");
  ExpectNear(plain.bounds_W.max(), {1, 0, 6}, "plain max");
  // The scale stays in the mesh; the actor pose is rigid: the node frame's axes
  // are glTF's, so the pose turns glTF y into world z.
  ExpectNear(big.X_WA.translation(), {1, 0, 5}, "big pose");
  Eigen::Matrix3d R_WN;
  R_WN << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_TRUE(big.X_WA.linear().isApprox(R_WN, 1e-9)) << big.X_WA.linear();
  ExpectNear(big.bounds_W.max(), {3, 0, 7}, "big max");
  // Material kept for rendering.
  const int material = plain.meshes[0].material;
  ASSERT_GE(material, 0);
  EXPECT_EQ(level.materials[static_cast<std::size_t>(material)].name, "red");
  // Without an alphaMode the material is OPAQUE and glTF ignores its alpha.
  EXPECT_TRUE(level.materials[static_cast<std::size_t>(material)].base_color.isApprox(
      Eigen::Vector4f(1, 0, 0, 1)));
  EXPECT_EQ(plain.meshes[0].normals_A.size(), 3u);
}

TEST(LevelTest, DuplicateNodeNamesAreMadeUnique) {
  TempDir dir;
  const auto file = dir.Write("dup.gltf", Gltf("0, 1, 2", R"({"name": "same", "mesh": 0},
      {"name": "same", "mesh": 0, "translation": [0, 1, 0]},
      {"name": "same", "mesh": 0, "translation": [0, 2, 0]})"));
  const Level level = LoadLevel(file);
  ASSERT_EQ(level.actors.size(), 3u);
  // Several roots: assimp adds a root node, which is not part of the path.
  EXPECT_EQ(level.actors[0].name, "same");
  EXPECT_EQ(level.actors[1].name, "same#2");
  EXPECT_EQ(level.actors[2].name, "same#3");
  ExpectNear(level.actors[2].X_WA.translation(), {0, 0, 2}, "third");
}

TEST(LevelTest, FbxSaysItsAxesAndUnit) {
  // assimp's ASCII FBX writer declares UpAxis = Y and UnitScaleFactor = 1 (cm):
  // the 1 x 2 x 3 box becomes 0.01 x 0.03 x 0.02 m with (x, y, z) -> (x, -z, y).
  TempDir dir;
  const auto obj = dir.Write("box.obj", ObjBox("box", 1, 2, 3));
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(obj.string(), 0);
  ASSERT_NE(scene, nullptr);
  const auto fbx = dir.path() / "box.fbx";
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, "fbxa", fbx.string()), AI_SUCCESS) << exporter.GetErrorString();
  const Level level = LoadLevel(fbx);
  ExpectNear(level.bounds_W().min(), {0, -0.03, 0}, "min");
  ExpectNear(level.bounds_W().max(), {0.01, 0, 0.02}, "max");
}

using testing::LoadError;

TEST(LevelTest, BadFilesGiveOneClearMessage) {
  TempDir dir;
  const std::string missing = (dir.path() / "missing.glb").string();
  EXPECT_EQ(LoadError(missing), missing + ": no such file");

  const auto unsupported = dir.Write("model.xyz", "solid nothing\n");
  EXPECT_EQ(LoadError(unsupported),
            unsupported.string() + ": unsupported format '.xyz' (not a format assimp reads)");

  const auto corrupt = dir.Write("broken.glb", std::string("glTF\x02\0\0\0garbage", 15));
  EXPECT_EQ(LoadError(corrupt),
            corrupt.string() + ": its header says 1651663207 bytes, the file has 15");
  // A header that tells the truth about garbage: assimp's own error.
  const auto garbage =
      dir.Write("garbage.glb", std::string("glTF\x02\0\0\0\x14\0\0\0garbage!", 20));
  EXPECT_EQ(LoadError(garbage).rfind(garbage.string() + ": ", 0), 0u) << LoadError(garbage);

  const auto empty = dir.Write("empty.obj", "");
  EXPECT_EQ(LoadError(empty), empty.string() + ": file is empty");

  EXPECT_EQ(LoadError(dir.path()), dir.path().string() + ": is a folder, not a file");

  const auto no_meshes = dir.Write("lonely.gltf", R"({"asset": {"version": "2.0"}, "scene": 0,
      "scenes": [{"nodes": [0]}], "nodes": [{"name": "empty"}]})");
  EXPECT_EQ(LoadError(no_meshes), no_meshes.string() + ": has no triangle meshes");
}

}  // namespace
}  // namespace sandbox::scene
