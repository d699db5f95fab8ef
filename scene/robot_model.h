#pragma once
// A robot's constant model: its node tree (the skeleton), the bone map that
// external publishers address by index, and its meshes with bone weights.
// Skinned meshes (glTF/FBX skins) and articulated link meshes (rigid meshes on
// nodes) are the same thing here: every vertex follows a weighted set of nodes.
// The changing part (pose, bone rotations, posed mesh) is RobotState.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "scene/mesh.h"
#include "scene/placement.h"
#include "scene/settings.h"

namespace sandbox::scene {

struct Level;

// How one bone's rotation is given from outside.
enum class BoneRotation {
  kQuaternion,  // 4 values (w, x, y, z), a unit quaternion
  kAngles,      // one angle (radians) per axis, applied in order about the bone's rest axes
  kSlide,       // one length (metres) along axes[0]: a prismatic joint (no rotation)
};

// A [[robot.sensor]] table: a sensor mounted on the robot. The scene keeps its
// settings as given; sensors/ reads and checks them (it knows each type's keys).
struct SensorSpec {
  std::string name;
  std::string type;    // as given; sensors/ (cameras: sensors/render/) parse it into a kind
  std::string mount;   // a node of the robot (a bone), empty: the robot body frame
  int mount_node{-1};  // resolved by LoadRobotModel; -1: the body frame
  Eigen::Isometry3d X_MS{Eigen::Isometry3d::Identity()};  // sensor in its mount's frame
  double rate_hz{0.0};                                    // 0: every tick
  std::string channel;     // its output channel after "<ROBOT>/"; empty: the type's own
  SettingsTable settings;  // the type's own settings, as given

  // "level.toml:12: sensor 'scanner': " for messages.
  std::string Where() const { return settings.Where(); }
};

// A [[robot]] table of the level manifest.
struct RobotSpec {
  std::string name;
  std::filesystem::path file;
  Placement placement;  // the spawn pose and the asset conversion
  bool collision{true};
  std::vector<std::string> bones;  // the bone map: index 0 = root
  BoneRotation rotation{BoneRotation::kQuaternion};
  std::vector<Eigen::Vector3d> angle_axes;                        // kAngles: the default axes
  std::map<std::string, std::vector<Eigen::Vector3d>> bone_axes;  // per-bone overrides
  std::vector<SensorSpec> sensors;
  std::vector<SensorSpec> cameras;  // [[robot.camera]]: chase, trailing, payload, fixed
  SettingsTable bridge;             // [robot.bridge]: how the bridge connects it (bridge/ reads it)
  int line{0};
};

// A node of the robot's tree. Parents come before their children.
struct RobotNode {
  std::string name;
  int parent{-1};
  Eigen::Affine3d X_PN{Eigen::Affine3d::Identity()};  // rest transform in the parent
};

// One entry of the bone map.
struct Bone {
  std::string name;
  int node{-1};
  BoneRotation rotation{BoneRotation::kQuaternion};
  std::vector<Eigen::Vector3d> axes;  // kAngles: unit axes in the bone's rest frame
  int first_value{0};                 // where this bone's values start in the flat value vector
  int num_values{4};                  // 4 for a quaternion, axes.size() for angles, 1 to slide
  // The range each value must be in (a joint's <limit>: radians or metres);
  // a value outside is rejected, never clamped.
  double lower{-std::numeric_limits<double>::infinity()};
  double upper{std::numeric_limits<double>::infinity()};
};

// A node that moves vertices: vertex v follows X_BN(node) * offset * v.
struct SkinJoint {
  int node{-1};
  Eigen::Affine3d offset{Eigen::Affine3d::Identity()};  // bind space to node space
};

// Consecutive vertices that follow the same joints (up to four), each with
// its own weights (SkinnedMesh::run_weight).
struct SkinRun {
  std::uint32_t first{0};
  std::uint32_t count{0};
  int num_joints{1};
  std::uint16_t joints[4]{0, 0, 0, 0};
};

// A mesh in bind space with its vertex weights (compressed rows: vertex v
// uses influences [influence_begin[v], influence_begin[v + 1])).
struct SkinnedMesh {
  Mesh bind;  // positions and normals in bind (file) space
  std::vector<std::uint32_t> influence_begin;
  std::vector<std::uint16_t> influence_joint;  // index into RobotModel::joints
  std::vector<float> influence_weight;         // sum to 1 per vertex
  // For fast skinning: runs of at least 4 vertices on the same joints, the
  // vertices in no run, and the bind data and run weights as separate arrays.
  std::vector<SkinRun> runs;
  std::vector<std::uint32_t> scattered;
  std::vector<float> bind_x, bind_y, bind_z, bind_nx, bind_ny, bind_nz;
  std::vector<float> run_weight[4];  // weight of the run's k-th joint, per vertex
};

// Fills the fast-skinning fields of `mesh` from its weights and bind data.
void PrepareSkinning(SkinnedMesh* mesh);

struct RobotModel {
  std::string name;
  std::filesystem::path file;
  std::vector<RobotNode> nodes;  // node 0 is the file's root
  std::vector<Bone> bones;       // the bone map
  int num_values{0};             // length of the flat bone value vector
  std::vector<SkinJoint> joints;
  std::vector<SkinnedMesh> meshes;  // Mesh::material indexes Level::materials
  // What rays see, when it differs from `meshes` (a robot description's
  // collision geometry, rigid on its links); empty: `meshes`.
  std::vector<SkinnedMesh> collision_meshes;
  // From a robot description (URDF, SDF): its links (nodes of those names;
  // an SDF joint turning about a point off its child's origin adds a node
  // named after the joint) and its movable joints as bones, in the
  // description's order.
  bool described{false};
  std::vector<std::string> links;
  // The robot body frame B from the file frame F: up axis, unit and scale.
  Eigen::Affine3d X_BF{Eigen::Affine3d::Identity()};
  Eigen::Isometry3d X_WB_spawn{Eigen::Isometry3d::Identity()};
  bool collision{true};
  std::vector<SensorSpec> sensors;  // mounts resolved
  std::vector<SensorSpec> cameras;  // mounts resolved
  SettingsTable bridge;

  int FindNode(const std::string& node_name) const;  // -1 when absent
  int FindBone(const std::string& bone_name) const;  // -1 when absent
  std::size_t num_vertices() const;
  std::size_t num_triangles() const;
};

// For each triangle of `mesh` (one of the model's), the node that carries
// most of its vertices' weight: the robot's collision body is split into
// rigid pieces by it.
std::vector<int> DominantNodePerTriangle(const RobotModel& model, const SkinnedMesh& mesh);

// The rigid part (rotation and translation) of a node pose whose 3x3 part is
// a rotation times a uniform scale (as robot node poses are).
Eigen::Isometry3d RigidPart(const Eigen::Affine3d& X);

// Loads the robot `spec` declares. Materials and textures are appended to
// `level` (the meshes index them there). Throws LevelError "manifest:line:
// robot 'name': what" for an unknown bone, a bone map longer than the
// skeleton, a bone 0 that is not the root of the others, or bones declared
// for a file without a skeleton.
// A robot description (robot_description.h) builds a node per link and a
// bone per movable joint; its mesh files are read as the level's are.
// `on_file` is called before each file is read (LoadOptions::on_file).
RobotModel LoadRobotModel(
    const RobotSpec& spec, const std::filesystem::path& manifest, Level* level,
    const std::function<void(const std::filesystem::path&, std::string_view)>& on_file = {});

}  // namespace sandbox::scene
