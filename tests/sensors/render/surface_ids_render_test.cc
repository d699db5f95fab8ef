// Surface ids through two independent paths: the ray caster's samples (the
// collision world's rigid pieces) and the renderer's segmentation image (the
// skinned meshes on the GPU), along the same rays, with two bent wings, the
// terrain and the tower in view.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "app/images.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/ray_caster.h"
#include "sensors/render/cameras.h"
#include "sensors/render/renderer.h"
#include "tests/test_util.h"

namespace sandbox::render {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

std::string Generated(const std::string& file) {
  return std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/generated/" + file;
}

std::string Wing(const std::string& name) {
  return "[[robot]]\nname = \"" + name + "\"\nfile = \"" + std::string(SANDBOX_SOURCE_DIR) +
         "/assets/robots/generated/flying_wing.gltf" +
         "\"\nbones = [\"root\", \"R1\", \"R2\", \"R3\", \"R4\", \"R5\", \"R6\", \"R7\", \"R8\", "
         "\"R9\", \"R10\", \"L1\", \"L2\", \"L3\", \"L4\", \"L5\", \"L6\", \"L7\", \"L8\", "
         "\"L9\", \"L10\", \"E1\", \"E2\", \"E3\"]\n"
         "rotation = \"angles\"\nangle_axes = [\"x\", \"y\"]\n"
         "[robot.bone_axes]\nE1 = [\"y\"]\nE2 = [\"y\"]\nE3 = [\"y\"]\n";
}

TEST(SurfaceIdsRenderTest, RaySamplesNameWhatTheSegmentationImageShowsAlongTheSameRays) {
  testing::TempDir dir;
  const scene::Level level = scene::LoadLevel(dir.Write(
      "level.toml", "[[actor]]\nname = \"terrain\"\nfile = \"" + Generated("terrain.gltf") +
                        "\"\n[[actor]]\nname = \"tower\"\nfile = \"" + Generated("tower.gltf") +
                        "\"\nposition = [-30, 45, 7.76]\n" + Wing("A") + Wing("B")));
  ASSERT_EQ(level.robots.size(), 2u);
  // A straight ahead, B beside it, rolled, its wing bent up by 0.1 rad a joint.
  std::vector<std::unique_ptr<scene::RobotState>> states;
  for (int r = 0; r < 2; ++r) {
    states.push_back(std::make_unique<scene::RobotState>(level.robots[std::size_t(r)]));
    Isometry3d X = Isometry3d::Identity();
    X.translation() = r == 0 ? Vector3d(0, 0, 40) : Vector3d(6, 14, 42);
    if (r == 1) X.linear() = Eigen::AngleAxisd(0.2, Vector3d::UnitX()).toRotationMatrix();
    std::vector<double> bones(45, 0.0);
    for (int b = 1; b <= 20; ++b) bones[std::size_t(2 * b)] = r == 1 ? (b <= 10 ? 0.1 : -0.1) : 0;
    ASSERT_TRUE(states.back()->SetPose(X));
    ASSERT_TRUE(states.back()->SetBones(bones));
    states.back()->Update();
  }
  scene::CollisionWorld world(level);
  for (int r = 0; r < 2; ++r) world.UpdateRobot(r, *states[std::size_t(r)]);

  CameraView view;
  view.width = 320, view.height = 240;
  view.X_WC = LookAt(Vector3d(-12, -20, 50), Vector3d(3, 7, 40));
  RenderSettings settings;
  settings.images = kSegmentationImage;
  const std::unique_ptr<Renderer> renderer = MakeRenderer();
  renderer->SetLevel(level, app::OpenCvTextureDecoder());
  Frame frame;
  renderer->Render(view, {}, {states[0].get(), states[1].get()}, settings, &frame);
  ASSERT_EQ(frame.segment.size(), std::size_t(view.width * view.height));

  // A ray through every pixel's centre, as a lidar casts them.
  sensors::RayBatch rays;
  rays.origin_W = view.X_WC.translation();
  const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
  for (int row = 0; row < view.height; ++row) {
    for (int column = 0; column < view.width; ++column) {
      const Vector3d d_C(1.0, -(column + 0.5 - 0.5 * view.width) / f,
                         -(row + 0.5 - 0.5 * view.height) / f);
      rays.start.emplace_back(0.f, 0.f, 0.f);
      rays.direction.push_back((view.X_WC.linear() * d_C.normalized()).cast<float>());
      rays.length_m.push_back(2000.f);
    }
  }
  sensors::RayCaster caster(2);
  sensors::RayHits hits;
  caster.Cast(world, rays, {}, &hits);

  const std::vector<scene::SurfaceEntry> table = world.SurfaceTable();
  std::map<std::int32_t, const scene::SurfaceEntry*> by_id;
  for (const scene::SurfaceEntry& entry : table) by_id[entry.id] = &entry;
  int same = 0;
  std::map<std::string, int> robot_samples;  // by robot name
  std::map<std::string, int> bones_of_b;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    same += frame.segment[i] == std::uint32_t(hits.surface[i]);
    if (hits.surface[i] == sensors::RayHits::kNoHit) continue;
    const auto found = by_id.find(hits.surface[i]);
    ASSERT_NE(found, by_id.end()) << "ray " << i << " id " << hits.surface[i];
    const scene::SurfaceEntry& entry = *found->second;
    if (entry.robot < 0) continue;
    ++robot_samples[entry.robot_name];
    EXPECT_EQ(entry.name, entry.robot_name + "/" + entry.bone_name);
    if (entry.robot_name == "B") ++bones_of_b[entry.bone_name];
  }
  EXPECT_GE(same, 0.995 * double(rays.size())) << same << " of " << rays.size();
  EXPECT_GT(robot_samples["A"], 300);
  EXPECT_GT(robot_samples["B"], 300);
  EXPECT_GE(bones_of_b.size(), 5u);                     // the root and bones along both half-wings
  EXPECT_GT(bones_of_b["R10"] + bones_of_b["L10"], 0);  // the tips
}

}  // namespace
}  // namespace sandbox::render
