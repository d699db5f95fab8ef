#include "app/pose_command.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "app/bone_values.h"
#include "app/command_line.h"
#include "app/defaults.h"
#include "app/loaded_level.h"
#include "scene/level.h"
#include "scene/robot_state.h"

namespace sandbox::app {
namespace {

namespace fs = std::filesystem;
using scene::RobotModel;
using scene::RobotState;

const char* kUsage =
    "usage: sandbox pose [LEVEL] [--robot NAME] [--robot-pose X,Y,Z[,ROLL,PITCH,YAW]]\n"
    "                    [--bones FILE|LIST] [--isolate] --out MESH.ply\n"
    "  LEVEL         a level manifest with [[robot]] tables (default: the sample level)\n"
    "  --robot       which robot (default: the first)\n"
    "  --robot-pose  world position in metres, roll/pitch/yaw in degrees (default: spawn pose)\n"
    "  --bones       bone values, entries 'BONE V1 [V2 ...]' separated by ';' or new lines,\n"
    "                BONE a name or bone-map index; angles in degrees, quaternions w x y z;\n"
    "                or a file with one entry a line ('#' starts a comment)\n"
    "  --out         the posed mesh (ASCII PLY, world frame); bone frames go to\n"
    "                MESH.bones.csv beside it\n"
    "  --isolate     read a manifest's files apart first (scene files always are)\n";

void WritePly(const fs::path& file, const RobotState& state) {
  const RobotModel& model = state.model();
  std::ofstream out(file);
  out << "ply\nformat ascii 1.0\ncomment sandbox pose: robot " << model.name
      << ", world frame, metres\nelement vertex " << model.num_vertices()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\nelement face "
      << model.num_triangles() << "\nproperty list uchar int vertex_indices\nend_header\n";
  const Eigen::Matrix3d R = state.pose().linear();
  out << std::setprecision(7);
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const auto& positions = state.positions_B(static_cast<int>(m));
    const auto& normals = state.normals_B(static_cast<int>(m));
    for (std::size_t v = 0; v < positions.size(); ++v) {
      const Eigen::Vector3d p = state.pose() * positions[v].cast<double>();
      const Eigen::Vector3d n = R * normals[v].cast<double>();
      out << p.x() << " " << p.y() << " " << p.z() << " " << n.x() << " " << n.y() << " " << n.z()
          << "\n";
    }
  }
  std::size_t base = 0;
  for (const auto& mesh : model.meshes) {
    const auto& indices = mesh.bind.indices;
    for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
      out << "3 " << base + indices[i] << " " << base + indices[i + 1] << " "
          << base + indices[i + 2] << "\n";
    }
    base += mesh.bind.positions_A.size();
  }
  out.close();  // the last buffer's write errors show here
  if (!out) throw CommandError("cannot write " + file.string());
}

void WriteBoneFrames(const fs::path& file, const RobotState& state) {
  const RobotModel& model = state.model();
  std::ofstream out(file);
  out << "bone,name,x,y,z,qw,qx,qy,qz\n" << std::setprecision(9);
  for (std::size_t b = 0; b < model.bones.size(); ++b) {
    const Eigen::Affine3d X = state.node_pose_W(model.bones[b].node);
    Eigen::Matrix3d rotation, scaling;
    X.computeRotationScaling(&rotation, &scaling);
    const Eigen::Quaterniond q(rotation);
    out << b << "," << model.bones[b].name << "," << X.translation().x() << ","
        << X.translation().y() << "," << X.translation().z() << "," << q.w() << "," << q.x() << ","
        << q.y() << "," << q.z() << "\n";
  }
  out.close();  // the last buffer's write errors show here
  if (!out) throw CommandError("cannot write " + file.string());
}

}  // namespace

int RunPose(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed = ParseArgs(args, "pose", {"--robot", "--robot-pose", "--bones", "--out"},
                                {"--isolate"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  const std::string level_file = parsed->level.value_or(kDefaultLevel);
  const std::string robot_name = parsed->Value("--robot"),
                    pose_text = parsed->Value("--robot-pose");
  const std::string bones_text = parsed->Value("--bones"), out_file = parsed->Value("--out");
  if (out_file.empty()) {
    err << "sandbox pose: --out MESH.ply is required\n" << kUsage;
    return 2;
  }
  try {
    const LoadedLevel loaded = LoadCheckedLevel(
        level_file, {},
        parsed->flags.count("--isolate") > 0 ? Isolation::kAlways : Isolation::kSceneFiles);
    const scene::Level& level = loaded.level;
    if (level.robots.empty()) throw CommandError(level_file + ": the level declares no [[robot]]");
    const int robot = robot_name.empty() ? 0 : level.FindRobot(robot_name);
    if (robot < 0) throw UsageError("the level has no robot '" + robot_name + "'");
    const RobotModel& model = level.robots[static_cast<std::size_t>(robot)];
    RobotState state(model);
    if (!pose_text.empty() && !state.SetPose(ParsePose(pose_text, "--robot-pose"))) {
      throw UsageError("--robot-pose rejected: " + state.last_rejection());
    }
    if (!bones_text.empty()) ApplyBones(bones_text, model, &state);
    state.Update();
    fs::path bones_file = out_file;
    bones_file.replace_extension(".bones.csv");
    WritePly(out_file, state);
    WriteBoneFrames(bones_file, state);
    out << "robot " << model.name << ": " << model.num_vertices() << " vertices, "
        << model.num_triangles() << " triangles -> " << out_file << "\n"
        << model.bones.size() << " bone frames -> " << bones_file.string() << "\n";
    return 0;
  } catch (const scene::LevelError& error) {
    err << "sandbox pose: " << error.what() << "\n";
    return 1;
  } catch (const UsageError& error) {
    err << "sandbox pose: " << error.what() << "\n";
    return 2;
  } catch (const CommandError& error) {
    err << "sandbox pose: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
