// The structured face-scan kernel against the general caster on every level
// of ../shared/assets: from random poses inside each model's bounds, a 101 x
// 101 face scan sized to the model hits the same rays at the same distances in
// both.

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/ray_caster.h"

namespace sandbox::sensors {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

TEST(StructuredScanSharedAssetsTest, SameHitsAsTheGeneralCasterInEveryModel) {
  const fs::path shared = SANDBOX_SHARED_ASSETS;
  if (!fs::exists(shared)) GTEST_SKIP() << "no " << shared;
  const char* files[] = {"q3-de4th-run1/de4th_run1.pk3",
                         "vulkan-subpass-scene/subpass_scene_opaque.gltf",
                         "terrain-vulkan-samples/terrain.gltf",
                         "assimp-terrain/terrain.hmp",
                         "fox/Fox.glb",
                         "cesium-milk-truck/CesiumMilkTruck.glb",
                         "recursive-skeletons/RecursiveSkeletons.glb",
                         "px4-plane/meshes/body.dae",
                         "kuka-iiwa/visual/link_2.dae"};
  std::mt19937 random(4242);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const char* file : files) {
    const scene::Level level = scene::LoadLevel(shared / file);
    const scene::CollisionWorld world(level);
    const Eigen::AlignedBox3d box = level.bounds_W();
    FaceScannerConfig config;
    config.refresh = Refresh::kFull;
    config.half_extent_m = 0.6 * box.sizes().maxCoeff();
    config.resolution_m = config.half_extent_m / 50.0;
    const FaceScanner scanner(config);
    int hits = 0;
    for (int k = 0; k < 3; ++k) {
      double draw[7];  // in order: as arguments their order would vary by compiler
      for (double& value : draw) value = unit(random);
      const Eigen::Quaterniond q(draw[3] - 0.5, draw[4] - 0.5, draw[5] - 0.5, draw[6] - 0.5);
      const Eigen::Isometry3d X_WS =
          Eigen::Translation3d(box.min() +
                               box.sizes().cwiseProduct(Vector3d(draw[0], draw[1], draw[2]))) *
          q.normalized();
      RayCaster caster(2);
      RayHits general, structured;
      auto compare = [&](const RayBatch& rays, const char* kind) {
        int differ = 0;
        double worst_m = 0.0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          if (general.surface[i] != structured.surface[i]) {
            ++differ;
          } else {
            worst_m = std::max(worst_m,
                               std::abs(double(general.distance_m[i]) - structured.distance_m[i]));
          }
        }
        EXPECT_EQ(differ, 0) << file << ", " << kind << ", pose " << k;
        EXPECT_LE(worst_m, 1e-5) << file << ", " << kind << ", pose " << k;
      };
      RayBatch rays;
      std::vector<RayGrid> grids;
      scanner.GridRays(0, X_WS, &rays, &grids);
      caster.Cast(world, rays, {}, &general);
      caster.CastGrids(world, rays, grids, {}, &structured);
      compare(rays, "face scan");
      for (const std::int32_t surface : general.surface) hits += surface != RayHits::kNoHit;
    }
    EXPECT_GT(hits, 1000) << file;  // the scans see the model
  }
}

}  // namespace
}  // namespace sandbox::sensors
