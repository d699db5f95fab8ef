// Robot figures per tick: forward kinematics + linear-blend skinning of the
// flying wing (24 bones, ~20k vertices), FK of RecursiveSkeletons (925 nodes,
// depth 30) from ../shared/assets when present, and the update of the wing's
// collision body (its rigid pieces moved with their bones, and how far they
// stray from the skin). The reference, run in the same process, is a plain
// double-precision skinning loop (every vertex: sum of weighted Affine3d).
//
//   bench_robots [--iterations N]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <vector>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"

namespace {

namespace fs = std::filesystem;
using namespace sandbox::scene;
using Clock = std::chrono::steady_clock;

// Median over 15 batches of the time per call, in microseconds.
double MicrosecondsPerCall(int iterations, const std::function<void(int)>& work) {
  std::vector<double> batches;
  const int per_batch = std::max(1, iterations / 15);
  for (int i = 0; i < per_batch; ++i) work(i);  // warm up
  for (int b = 0; b < 15; ++b) {
    const auto start = Clock::now();
    for (int i = 0; i < per_batch; ++i) work(i);
    batches.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
                      per_batch);
  }
  std::sort(batches.begin(), batches.end());
  return batches[batches.size() / 2];
}

// The reference: FK as RobotState does, then per vertex a weighted sum of
// double Affine3d matrices applied to the double position and normal.
struct ReferenceSkinning {
  explicit ReferenceSkinning(const RobotModel& m) : model(m), X_BN(m.nodes.size()) {
    for (const SkinnedMesh& mesh : m.meshes) {
      positions.emplace_back(mesh.bind.positions_A.size());
      normals.emplace_back(mesh.bind.positions_A.size());
    }
  }
  void Update(const std::vector<Eigen::Quaterniond>& rotation) {
    for (std::size_t n = 0; n < model.nodes.size(); ++n) {
      const RobotNode& node = model.nodes[n];
      X_BN[n] =
          (node.parent < 0 ? model.X_BF : X_BN[std::size_t(node.parent)]) * node.X_PN * rotation[n];
    }
    for (std::size_t m = 0; m < model.meshes.size(); ++m) {
      const SkinnedMesh& mesh = model.meshes[m];
      for (std::size_t v = 0; v + 1 < mesh.influence_begin.size(); ++v) {
        Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
        for (std::uint32_t i = mesh.influence_begin[v]; i < mesh.influence_begin[v + 1]; ++i) {
          const SkinJoint& joint = model.joints[mesh.influence_joint[i]];
          M += mesh.influence_weight[i] * (X_BN[std::size_t(joint.node)] * joint.offset).matrix();
        }
        const Eigen::Affine3d X(M);
        positions[m][v] = X * mesh.bind.positions_A[v].cast<double>();
        normals[m][v] = (X.linear() * mesh.bind.normals_A[v].cast<double>()).normalized();
      }
    }
  }
  const RobotModel& model;
  std::vector<Eigen::Affine3d> X_BN;
  std::vector<std::vector<Eigen::Vector3d>> positions, normals;
};

// Bends the wing differently on every call so that nothing is cached.
void BendWing(RobotState* state, int i) {
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {0.0785 * std::sin(0.01 * i + b), 0.01 * std::cos(0.02 * i)};
    state->SetBone(b, values, 2);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int iterations = 3000;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--iterations") == 0 && i + 1 < argc) {
      iterations = std::max(15, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_robots [--iterations N]\n");
      return 2;
    }
  }
  const Level level = LoadLevel(fs::path(SANDBOX_SOURCE_DIR) / "assets/robots/robots.toml");
  const RobotModel& wing = level.robots.at(static_cast<std::size_t>(level.FindRobot("ELAHA")));
  RobotState state(wing);
  ReferenceSkinning reference(wing);
  std::vector<Eigen::Quaterniond> rotation(wing.nodes.size(), Eigen::Quaterniond::Identity());

  std::printf("%-44s %12s %14s %8s\n", "per tick", "us", "reference us", "ratio");
  const double ours = MicrosecondsPerCall(iterations, [&](int i) {
    BendWing(&state, i);
    state.Update();
  });
  const double ref = MicrosecondsPerCall(iterations / 4, [&](int i) {
    for (int b = 1; b <= 20; ++b) {
      rotation[std::size_t(wing.bones[std::size_t(b)].node)] =
          Eigen::AngleAxisd(0.0785 * std::sin(0.01 * i + b), Eigen::Vector3d::UnitX());
    }
    reference.Update(rotation);
  });
  std::printf("%-44s %12.1f %14.1f %7.1fx\n", "flying wing FK + skinning (24 bones, 20k vtx)", ours,
              ref, ref / ours);

  CollisionWorld world(level);
  const int robot = level.FindRobot("ELAHA");
  const double refit = MicrosecondsPerCall(iterations / 4, [&](int i) {
    BendWing(&state, i);
    state.Update();
    world.UpdateRobot(robot, state);
  });
  std::printf("%-44s %12.1f %14s %8s\n", "  + collision body (UpdateRobot)", refit, "-", "-");

  // How far the rigid collision pieces stray from the skin, bent 4.5 degrees a joint.
  RobotState rest(wing), bent(wing);
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {(b <= 10 ? 1 : -1) * 4.5 * 3.14159265358979 / 180.0, 0.0};
    bent.SetBone(b, values, 2);
  }
  bent.Update();
  const std::vector<int> node_of = DominantNodePerTriangle(wing, wing.meshes[0]);
  const auto& indices = wing.meshes[0].bind.indices;
  double worst_m = 0.0;
  for (std::size_t t = 0; t < node_of.size(); ++t) {
    const auto n = static_cast<std::size_t>(node_of[t]);
    const Eigen::Isometry3d move =
        RigidPart(bent.node_poses_B()[n]) * RigidPart(rest.node_poses_B()[n]).inverse();
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = indices[3 * t + std::size_t(k)];
      worst_m = std::max(worst_m, (move * rest.positions_B(0)[v].cast<double>() -
                                   bent.positions_B(0)[v].cast<double>())
                                      .norm());
    }
  }
  std::printf("%-44s %9.1f mm\n", "  collision pieces off the skin at 4.5 deg/joint",
              1e3 * worst_m);

  const fs::path skeletons =
      fs::path(SANDBOX_SOURCE_DIR) / "../shared/assets/recursive-skeletons/RecursiveSkeletons.glb";
  if (fs::exists(skeletons)) {
    const fs::path manifest = fs::temp_directory_path() / "sandbox-bench-skeletons.toml";
    std::ofstream(manifest) << "[[robot]]\nname = \"s\"\nfile = \"" << skeletons.string() << "\"\n";
    const Level deep = LoadLevel(manifest);
    fs::remove(manifest);
    const RobotModel& model = deep.robots.at(0);
    RobotState skeleton(model);
    ReferenceSkinning skeleton_reference(model);
    std::vector<Eigen::Quaterniond> identity(model.nodes.size(), Eigen::Quaterniond::Identity());
    const double fk = MicrosecondsPerCall(iterations, [&](int) { skeleton.Update(); });
    const double fk_ref =
        MicrosecondsPerCall(iterations / 4, [&](int) { skeleton_reference.Update(identity); });
    std::printf(
        "%-44s %12.1f %14.1f %7.1fx\n",
        ("RecursiveSkeletons FK + skin (" + std::to_string(model.nodes.size()) + " nodes)").c_str(),
        fk, fk_ref, fk_ref / fk);
  } else {
    std::printf("RecursiveSkeletons: skipped, no %s\n", skeletons.c_str());
  }
  std::printf(
      "\nmedian of 15 batches, one core; targets: wing under 50 us, skeletons under 200 us\n");
  return 0;
}
