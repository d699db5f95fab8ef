#pragma once
// The changing part of a robot: its world pose, its bone rotations, and the
// posed (skinned) mesh from forward kinematics. Owned by the loop thread.

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "scene/robot_model.h"

namespace sandbox::scene {

// Why a pose or one bone's values would be rejected ("" when they would not):
// the checks of RobotState::SetPose and SetBone, for callers that check
// before they hold a state.
std::string PoseProblem(const Eigen::Isometry3d& X_WB);
std::string BoneValuesProblem(const Bone& bone, const double* values, int num_values);

class RobotState {
 public:
  // At the model's spawn pose with every bone at rest, already updated.
  // Keeps a reference to `model`, which must outlive the state.
  explicit RobotState(const RobotModel& model);

  // Updates from outside. A rejected update changes nothing, returns false and
  // is counted under its reason in rejected(); the last good value stays.
  bool SetPose(const Eigen::Isometry3d& X_WB);
  // One bone of the bone map: Bone::num_values values (radians for angles,
  // metres for a slide, (w, x, y, z) for a quaternion, relative to the bone's
  // rest rotation); angles and slides within the bone's limits.
  bool SetBone(int bone, const double* values, int num_values);
  // Every bone at once, flat in bone-map order (RobotModel::num_values values).
  bool SetBones(const std::vector<double>& values);

  // Forward kinematics, root to tip, then linear-blend skinning of every mesh.
  void Update();
  // Forward kinematics alone: node poses (all CollisionWorld::UpdateRobot and
  // the sensors read), the posed meshes left as they were until Skin().
  void UpdateKinematics();
  // Linear-blend skinning of every mesh for the node poses, unless they are
  // skinned already (only a camera draws the posed meshes: the loop skins
  // when a frame is due, not every tick).
  void Skin();
  bool skinned() const { return skinned_; }

  const RobotModel& model() const { return *model_; }
  const Eigen::Isometry3d& pose() const { return X_WB_; }
  // The bone values in use, flat in bone-map order (at rest: 0 for angles,
  // (1, 0, 0, 0) for quaternions).
  const std::vector<double>& bone_values() const { return values_; }
  // Node poses in the robot body frame B (after Update()).
  const std::vector<Eigen::Affine3d>& node_poses_B() const { return X_BN_; }
  Eigen::Affine3d node_pose_W(int node) const;
  // Where a sensor or camera mounted as `spec` says is: the robot pose, its
  // mount node's rigid part (none: the body frame) and the offset X_MS.
  Eigen::Isometry3d MountPose(const SensorSpec& spec) const;
  // The posed mesh in frame B, one array per RobotModel::meshes entry (as of
  // the last Skin()).
  const std::vector<Eigen::Vector3f>& positions_B(int mesh) const;
  const std::vector<Eigen::Vector3f>& normals_B(int mesh) const;
  // Rejected updates by reason, and the reason of the latest one.
  const std::map<std::string, int>& rejected() const { return rejected_; }
  const std::string& last_rejection() const { return last_rejection_; }

 private:
  bool Reject(const std::string& reason);
  void SkinVertex(const SkinnedMesh& mesh, std::uint32_t v, std::size_t m);
  void SkinRunOfVertices(const SkinnedMesh& mesh, const SkinRun& run, std::size_t m);

  const RobotModel* model_;
  Eigen::Isometry3d X_WB_;
  std::vector<Eigen::Quaterniond> rotation_;  // per node, relative to its rest transform
  std::vector<Eigen::Vector3d> translation_;  // per node (a slide), before its rotation
  std::vector<double> values_;                // the bone values that set rotation_
  std::vector<Eigen::Affine3d> X_BN_;
  std::vector<Eigen::Matrix<float, 3, 4>> skin_;  // per joint: X_BN * offset
  std::vector<bool> rigid_;                       // per joint: skin_ keeps lengths
  std::vector<std::vector<Eigen::Vector3f>> positions_B_;
  std::vector<std::vector<Eigen::Vector3f>> normals_B_;
  bool skinned_{false};  // positions_B_ and normals_B_ are of X_BN_
  std::map<std::string, int> rejected_;
  std::string last_rejection_;
};

}  // namespace sandbox::scene
