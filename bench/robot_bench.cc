// Robot figures per tick: forward kinematics + linear-blend skinning of the
// flying wing (24 bones, ~20k vertices), FK of RecursiveSkeletons (925 nodes,
// depth 30) from ../shared/assets when present, and the update of the wing's
// collision body (its rigid pieces moved with their bones, and how far they
// stray from the skin). The reference, run in the same process, is a plain
// double-precision skinning loop (every vertex: sum of weighted Affine3d).
// Robot descriptions: forward kinematics and the collision update of a
// 7-joint arm (a generated URDF chain, and the KUKA iiwa when present) and of
// a generated 50-link chain, against Orocos KDL's recursive FK solver on the
// same chain (every segment's frame).
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
#include <string>
#include <vector>

#ifdef SANDBOX_HAVE_KDL
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#endif

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

// A chain of `links` boxes joined by revolute joints about y, z, x, y, ...,
// each 0.1 to 0.3 m above the last, written as URDF.
std::string ChainUrdf(int links) {
  std::string xml = "<robot name=\"chain\">\n";
  for (int l = 0; l < links; ++l) {
    xml += "<link name=\"l" + std::to_string(l) +
           "\"><visual><geometry><box size=\"0.05 0.05 0.1\"/></geometry></visual>"
           "<collision><geometry><box size=\"0.05 0.05 0.1\"/></geometry></collision></link>\n";
    if (l == 0) continue;
    const char* axes[] = {"0 1 0", "0 0 1", "1 0 0"};
    xml += "<joint name=\"j" + std::to_string(l) + "\" type=\"revolute\"><parent link=\"l" +
           std::to_string(l - 1) + "\"/><child link=\"l" + std::to_string(l) +
           "\"/><origin xyz=\"0 0 " + std::to_string(0.1 + 0.2 * ((l * 7) % 11) / 10.0) +
           "\" rpy=\"0.1 0 0\"/><axis xyz=\"" + axes[l % 3] +
           "\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>\n";
  }
  return xml + "</robot>\n";
}

// Per tick: new joint values, forward kinematics and the collision update;
// the reference: KDL's FK of every segment of the same chain.
void DescribedRobot(const std::string& name, const fs::path& file, int iterations) {
  const Level level = LoadLevel(file);
  const RobotModel& model = level.robots.at(0);
  RobotState state(model);
  CollisionWorld world(level);
  auto set_joints = [&](int i) {
    for (std::size_t b = 0; b < model.bones.size(); ++b) {
      const double value = 0.5 * std::sin(0.01 * i + double(b));
      state.SetBone(int(b), &value, 1);
    }
  };
  const double ours = MicrosecondsPerCall(iterations, [&](int i) {
    set_joints(i);
    state.UpdateKinematics();
    world.UpdateRobot(0, state);
  });
  const double skin = MicrosecondsPerCall(std::max(15, iterations / 20), [&](int i) {
    set_joints(i);
    state.Update();
  });
  double reference = 0.0;
#ifdef SANDBOX_HAVE_KDL
  // The chain as kdl_parser makes it from URDF: a joint about origin.R * axis
  // through origin.p, the segment's tip at the origin.
  KDL::Chain chain;
  for (const Bone& bone : model.bones) {
    const RobotNode& node = model.nodes[std::size_t(bone.node)];
    const Eigen::Matrix3d R = node.X_PN.linear();
    const Eigen::Vector3d p = node.X_PN.translation(), axis = R * bone.axes[0];
    KDL::Frame tip(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                 R(2, 1), R(2, 2)),
                   KDL::Vector(p.x(), p.y(), p.z()));
    chain.addSegment(
        KDL::Segment(node.name,
                     KDL::Joint(bone.name, KDL::Vector(p.x(), p.y(), p.z()),
                                KDL::Vector(axis.x(), axis.y(), axis.z()), KDL::Joint::RotAxis),
                     tip));
  }
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::JntArray q(chain.getNrOfJoints());
  std::vector<KDL::Frame> frames(chain.getNrOfSegments());
  reference = MicrosecondsPerCall(iterations, [&](int i) {
    for (unsigned j = 0; j < q.rows(); ++j) q(j) = 0.5 * std::sin(0.01 * i + double(j));
    fk.JntToCart(q, frames);
  });
#endif
  const std::string what = name + " (" + std::to_string(model.bones.size()) + " joints)";
  if (reference > 0.0) {
    std::printf("%-44s %12.2f %14.2f %7.2fx\n", what.c_str(), ours, reference, reference / ours);
  } else {
    std::printf("%-44s %12.2f %14s %8s\n", what.c_str(), ours, "(no KDL)", "-");
  }
  std::printf("%-44s %12.1f %14s %8s\n",
              ("  FK + skinning, " + std::to_string(model.num_vertices()) + " vtx").c_str(), skin,
              "-", "-");
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
  const fs::path folder = fs::temp_directory_path();
  for (const int links : {8, 50}) {
    const fs::path file = folder / ("sandbox-bench-chain-" + std::to_string(links) + ".urdf");
    std::ofstream(file) << ChainUrdf(links);
    DescribedRobot(links == 8 ? "7-joint URDF arm" : "50-link URDF chain", file, iterations);
    fs::remove(file);
  }
  const fs::path kuka =
      fs::path(SANDBOX_SOURCE_DIR) / "../shared/assets/kuka-iiwa/lbr_iiwa_14_r820.urdf";
  if (fs::exists(kuka)) {
    DescribedRobot("KUKA iiwa", kuka, iterations);
  } else {
    std::printf("KUKA iiwa: skipped, no %s\n", kuka.c_str());
  }
  std::printf(
      "\nmedian of 15 batches, one core; targets: wing under 50 us, skeletons under 200 us;\n"
      "descriptions: FK + collision update (UpdateKinematics, UpdateRobot) against KDL's FK\n"
      "alone; targets: 7-joint arm under 10 us, 50-link chain under 50 us\n");
  return 0;
}
