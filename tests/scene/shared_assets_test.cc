// Every model of ../shared/assets loads with the right size and orientation.
// Expected sizes come from each asset's STATS.txt (assimp's own bounding box,
// in file units and axes), the URDF and the SDF, converted by hand.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

fs::path Shared(const std::string& relative) { return fs::path(SANDBOX_SHARED_ASSETS) / relative; }

class SharedAssetsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(SANDBOX_SHARED_ASSETS)) {
      GTEST_SKIP() << "no " << SANDBOX_SHARED_ASSETS
                   << " (the shared test assets sit beside the repository on the "
                      "development machines only)";
    }
  }
};

// Loads, builds the Bullet world and checks the level's size to `tolerance_m`.
Level ExpectSize(const fs::path& file, const Vector3d& size_m, double tolerance_m,
                 const AssetConversion& conversion = {}) {
  Level level = LoadLevel(file, conversion);
  const CollisionWorld world(level);
  EXPECT_GT(world.num_collision_objects(), 0);
  const Vector3d size = level.bounds_W().sizes();
  EXPECT_LT((size - size_m).cwiseAbs().maxCoeff(), tolerance_m)
      << file << ": size " << size.transpose() << ", expected " << size_m.transpose();
  return level;
}

TEST_F(SharedAssetsTest, Quake3MapHasRealTrianglesOnceRebuiltAndIsZUpInInches) {
  // STATS: 3520 x 1536 x 4096 units, Z up; 1 unit = 0.0254 m.
  const Level level =
      ExpectSize(Shared("q3-de4th-run1/de4th_run1.pk3"), Vector3d(3520, 1536, 4096) * 0.0254, 0.01);
  EXPECT_EQ(level.actors.size(), 61u);
  // assimp 5.2.5 leaves the faces' indices wrong (repeats: zero-area triangles,
  // and 3 out of range); they are rebuilt, once, with one warning.
  ASSERT_EQ(level.warnings.size(), 1u);
  EXPECT_NE(level.warnings[0].find("rebuilt the faces of"), std::string::npos) << level.warnings[0];
  std::size_t zero_area = 0;
  double area_m2 = 0.0;
  for (const Actor& actor : level.actors) {
    for (const Mesh& mesh : actor.meshes) {
      for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Eigen::Vector3f a = mesh.positions_A[mesh.indices[t]];
        const double area = 0.5 * double((mesh.positions_A[mesh.indices[t + 1]] - a)
                                             .cross(mesh.positions_A[mesh.indices[t + 2]] - a)
                                             .norm());
        zero_area += area < 1e-8;
        area_m2 += area;
      }
    }
  }
  // The file's own slivers (collinear corners of brush faces) are 19; before the
  // rebuild nearly every triangle had zero area.
  EXPECT_LT(zero_area, level.num_triangles() / 100);
  // At least its walls: the box's four sides.
  EXPECT_GT(area_m2, 2.0 * (89.4 + 39.0) * 104.0);
  // Unnamed children get stable generated names.
  EXPECT_GE(level.FindActor("node0"), 0);
  EXPECT_EQ(level.num_triangles(), 15051u);  // every face of the file, none dropped
  // Rays from outside towards the middle hit the map's outer surfaces.
  const CollisionWorld world(level);
  const Eigen::AlignedBox3d box = level.bounds_W();
  for (const Vector3d& from :
       {Vector3d(-200, 0, 50), Vector3d(200, 0, 50), Vector3d(0, -200, 50), Vector3d(0, 0, 300)}) {
    const auto hit = world.CastRay(from, box.center());
    ASSERT_TRUE(hit.has_value()) << from.transpose();
    EXPECT_TRUE(box.exteriorDistance(hit->point_W) < 0.01) << hit->point_W.transpose();
  }
}

// A bit flipped in the map's compressed data: assimp's zip reader fails its
// own check (ai_assert) on the CRC, which used to abort the process; now the
// import fails with that check's text, and the program goes on.
TEST_F(SharedAssetsTest, ABitFlippedQuake3MapIsAnErrorNotAnAbort) {
  const fs::path map = Shared("q3-de4th-run1/de4th_run1.pk3");
  std::ifstream in(map, std::ios::binary);
  std::ostringstream contents;
  contents << in.rdbuf();
  std::string bytes = contents.str();
  ASSERT_GT(bytes.size(), 500000u);
  bytes[500000] = char(bytes[500000] ^ 0x10);  // inside the .bsp's deflated data
  testing::TempDir dir;
  const fs::path flipped = dir.Write("flipped.pk3", bytes);
  try {
    LoadLevel(flipped);
    FAIL() << "the flipped map loaded";
  } catch (const LevelError& error) {
    EXPECT_EQ(std::string(error.what())
                  .rfind(flipped.string() + ": assimp could not read it: assimp's check "
                                            "'unzCloseCurrentFile(zip_handle) == UNZ_OK' failed",
                         0),
              0u)
        << error.what();
  }
}

TEST_F(SharedAssetsTest, GltfModelsAreYUp) {
  // STATS sizes (x, y, z) in glTF axes become world (x, z, y).
  ExpectSize(Shared("cesium-man/CesiumMan.glb"), {1.14, 0.31, 1.51}, 0.01);
  ExpectSize(Shared("rigged-simple/RiggedSimple.glb"), {2, 2, 9.15}, 0.01);
  ExpectSize(Shared("rigged-figure/RiggedFigure.glb"), {1.18, 0.33, 1.45}, 0.01);
  ExpectSize(Shared("fox/Fox.glb"), {25.2, 154.7, 79.0}, 0.1);
  ExpectSize(Shared("simple-skin/SimpleSkin.gltf"), {1, 0, 2}, 0.01);
  ExpectSize(Shared("cesium-milk-truck/CesiumMilkTruck.glb"), {2.79, 4.87, 2.58}, 0.01);
  ExpectSize(Shared("terrain-vulkan-samples/terrain.gltf"), {2, 2, 0.289}, 0.002);
  ExpectSize(Shared("vulkan-subpass-scene/subpass_scene_opaque.gltf"), {22, 22, 10.2}, 0.01);
  ExpectSize(Shared("vulkan-subpass-scene/subpass_scene_transparent.gltf"), {16.1, 16.1, 9.7},
             0.02);
  // A person stands on the ground: feet at z = 0, head up.
  const Level man = LoadLevel(Shared("cesium-man/CesiumMan.glb"));
  EXPECT_NEAR(man.bounds_W().min().z(), 0.0, 0.01);
  EXPECT_EQ(man.textures.size(), 1u);  // the embedded skin texture
}

TEST_F(SharedAssetsTest, DeepHierarchyGivesOneActorPerMeshNode) {
  const Level level =
      ExpectSize(Shared("recursive-skeletons/RecursiveSkeletons.glb"), {10, 10, 90}, 0.01);
  EXPECT_GT(level.actors.size(), 1u);
  for (const Actor& actor : level.actors)
    EXPECT_EQ(level.FindActor(actor.name), &actor - &level.actors[0]);
}

TEST_F(SharedAssetsTest, ColladaUpAxisMatchesTheZUpCollisionMeshes) {
  // The URDF uses each link's visual .dae and collision .stl in the same frame:
  // with <up_axis> honoured their bounds agree (to the coarser STL's detail).
  for (const std::string link :
       {"base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "link_7"}) {
    const Level visual = LoadLevel(Shared("kuka-iiwa/visual/" + link + ".dae"));
    const Level collision = LoadLevel(Shared("kuka-iiwa/collision/" + link + ".stl"));
    const Eigen::AlignedBox3d a = visual.bounds_W(), b = collision.bounds_W();
    EXPECT_LT((a.min() - b.min()).cwiseAbs().maxCoeff(), 0.02) << link;
    EXPECT_LT((a.max() - b.max()).cwiseAbs().maxCoeff(), 0.02) << link;
  }
}

TEST_F(SharedAssetsTest, KukaArmPlacedByManifestStandsAboutOnePointThreeMetresTall) {
  const Level level = LoadLevel(fs::path(SANDBOX_SOURCE_DIR) / "tests/data/kuka_iiwa.toml");
  ASSERT_EQ(level.actors.size(), 8u);
  const Eigen::AlignedBox3d box = level.bounds_W();
  EXPECT_NEAR(box.min().z(), 0.0, 0.01);
  EXPECT_NEAR(box.max().z(), 1.18 + 0.126, 0.03);    // flange at joint a7 + tool0 offset
  EXPECT_LT(box.sizes().head<2>().maxCoeff(), 0.3);  // a straight arm
  EXPECT_TRUE(level.actors[7].movable);
}

TEST_F(SharedAssetsTest, Px4ModelsInTheirSdfUnits) {
  // SketchUp Collada, Z up, inches: STATS (Y-up after assimp) 7.6 x 2.6 x 11.0.
  ExpectSize(Shared("px4-plane/meshes/body.dae"), {7.63, 11.03, 2.62}, 0.02);
  ExpectSize(Shared("px4-iris/meshes/iris.stl"), {0.30, 0.48, 0.11}, 0.01);
  for (const char* part : {"left_aileron", "right_aileron", "left_flap", "right_flap", "elevators",
                           "rudder", "propeller_cw", "propeller_ccw"}) {
    const Level level = LoadLevel(Shared(std::string("px4-plane/meshes/") + part + ".dae"));
    EXPECT_GT(level.num_triangles(), 0u) << part;
  }
  // Heightmap through a manifest, as the SDF sizes it: 80 x 80 m, at most 2 m high.
  const Level ground =
      LoadLevel(fs::path(SANDBOX_SOURCE_DIR) / "tests/data/px4_uneven_ground.toml");
  const Vector3d size = ground.bounds_W().sizes();
  EXPECT_NEAR(size.x(), 80.0, 1e-6);
  EXPECT_NEAR(size.y(), 80.0, 1e-6);
  EXPECT_GT(size.z(), 0.1);
  EXPECT_LE(ground.bounds_W().max().z(), 2.0 + 1e-6);
  EXPECT_EQ(ground.num_triangles(), 512u * 512u * 2u);
}

TEST_F(SharedAssetsTest, Terrains) {
  // 3DGS HMP: STATS 160 x 160 x 40.
  ExpectSize(Shared("assimp-terrain/terrain.hmp"), {160, 160, 40}, 0.01);
  // Terragen (assimp 5.2.5 fails on it; read natively): 257 x 257 points, 30 m apart.
  // Its header: heightscale 33, baseheight 13, SCAL 30 m, so every elevation lies in
  // (13 +- 32768 * 33 / 65536) * 30 m = [-105, 885] m.
  const Level ter = LoadLevel(Shared("assimp-terrain/RealisticTerrain.ter"));
  EXPECT_EQ(ter.num_triangles(), 256u * 256u * 2u);
  const Eigen::AlignedBox3d box = ter.bounds_W();
  EXPECT_NEAR(box.sizes().x(), 7680.0, 1e-3);
  EXPECT_NEAR(box.sizes().y(), 7680.0, 1e-3);
  EXPECT_GE(box.min().z(), -105.0);
  EXPECT_LE(box.max().z(), 885.0);
  EXPECT_GT(box.sizes().z(), 100.0);
}

// Declares `file` as a robot whose bone map is the one bone `bone` (quaternions).
Level LoadAsRobot(const testing::TempDir& dir, const fs::path& file, const std::string& bone) {
  return LoadLevel(dir.Write("robot.toml", "[[robot]]\nname = \"r\"\nfile = \"" + file.string() +
                                               "\"\nbones = [\"" + bone + "\"]\n"));
}

TEST_F(SharedAssetsTest, RotatingANamedBoneMovesItsVerticesByTheRotatedOffset) {
  const std::pair<const char*, const char*> cases[] = {
      {"cesium-man/CesiumMan.glb", "Skeleton_neck_joint_2"},
      {"rigged-figure/RiggedFigure.glb", "arm_joint_L_3"},
      {"fox/Fox.glb", "b_Tail03_014"}};
  for (const auto& [asset, bone_name] : cases) {
    SCOPED_TRACE(asset);
    testing::TempDir dir;
    const Level level = LoadAsRobot(dir, Shared(asset), bone_name);
    const RobotModel& model = level.robots.at(0);
    const RobotState rest(model);
    // At rest the skin is exactly the static import of the file (the bind pose).
    const Level still = LoadLevel(Shared(asset));
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3f& p : rest.positions_B(0)) box.extend(p.cast<double>());
    EXPECT_LT((box.min() - still.bounds_W().min()).norm(), 1e-4);
    EXPECT_LT((box.max() - still.bounds_W().max()).norm(), 1e-4);

    // Turn the bone 30 degrees about an oblique axis of its rest frame.
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.5235987755982988, Vector3d(1, 2, 3).normalized()));
    const double values[4] = {q.w(), q.x(), q.y(), q.z()};
    RobotState posed(model);
    ASSERT_TRUE(posed.SetBone(0, values, 4));
    posed.Update();
    // A vertex weighted fully to the bone moves by X_B,bone R X_B,bone^-1.
    const int node = model.bones[0].node;
    const Eigen::Affine3d X = rest.node_poses_B()[static_cast<std::size_t>(node)];
    const Eigen::Affine3d moved = X * q * X.inverse();
    const SkinnedMesh& mesh = model.meshes.at(0);
    int checked = 0, still_vertices = 0;
    for (std::size_t v = 0; v + 1 < mesh.influence_begin.size(); ++v) {
      if (mesh.influence_begin[v + 1] - mesh.influence_begin[v] != 1) continue;
      const int joint_node = model.joints[mesh.influence_joint[mesh.influence_begin[v]]].node;
      const Vector3d before = rest.positions_B(0)[v].cast<double>();
      const Vector3d after = posed.positions_B(0)[v].cast<double>();
      if (joint_node == node) {
        EXPECT_LT((after - moved * before).norm(), 1e-4 * std::max(1.0, box.sizes().norm()));
        ++checked;
      } else {
        // Vertices on bones that are not below the turned one stay put.
        bool below = false;
        for (int n = joint_node; n >= 0; n = model.nodes[static_cast<std::size_t>(n)].parent) {
          below |= n == node;
        }
        if (!below) {
          EXPECT_LT((after - before).norm(), 1e-5 * std::max(1.0, box.sizes().norm()));
          ++still_vertices;
        }
      }
    }
    EXPECT_GT(checked, 10);
    EXPECT_GT(still_vertices, 0);
  }
}

}  // namespace
}  // namespace sandbox::scene
