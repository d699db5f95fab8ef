#include "scene/robot_state.h"

#include <cmath>

#include "scene/check.h"

namespace sandbox::scene {

RobotState::RobotState(const RobotModel& model)
    : model_(&model),
      X_WB_(model.X_WB_spawn),
      rotation_(model.nodes.size(), Eigen::Quaterniond::Identity()),
      X_BN_(model.nodes.size(), Eigen::Affine3d::Identity()),
      skin_(model.joints.size()) {
  for (const SkinnedMesh& mesh : model.meshes) {
    positions_B_.emplace_back(mesh.bind.positions_A.size());
    normals_B_.emplace_back(mesh.bind.normals_A.size());
  }
  Update();
}

bool RobotState::Reject(const std::string& reason) {
  ++rejected_[reason];
  last_rejection_ = reason;
  return false;
}

bool RobotState::SetPose(const Eigen::Isometry3d& X_WB) {
  if (!X_WB.matrix().allFinite()) return Reject("non-finite pose");
  const Eigen::Matrix3d R = X_WB.linear();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0) {
    return Reject("pose rotation is not a rotation");
  }
  X_WB_ = X_WB;
  return true;
}

bool RobotState::SetBone(int bone, const double* values, int num_values) {
  if (bone < 0 || bone >= static_cast<int>(model_->bones.size())) {
    return Reject("bone index out of range");
  }
  const Bone& b = model_->bones[static_cast<std::size_t>(bone)];
  if (num_values != b.num_values) return Reject("wrong number of bone values");
  for (int i = 0; i < num_values; ++i) {
    if (!std::isfinite(values[i])) return Reject("non-finite bone value");
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (b.rotation == BoneRotation::kQuaternion) {
    q = Eigen::Quaterniond(values[0], values[1], values[2], values[3]);
    if (std::abs(q.norm() - 1.0) > 1e-3) return Reject("non-unit bone quaternion");
    q.normalize();
  } else {
    for (std::size_t a = 0; a < b.axes.size(); ++a) {
      q = q * Eigen::Quaterniond(Eigen::AngleAxisd(values[a], b.axes[a]));
    }
  }
  rotation_[static_cast<std::size_t>(b.node)] = q;
  return true;
}

bool RobotState::SetBones(const std::vector<double>& values) {
  if (static_cast<int>(values.size()) != model_->num_values) {
    return Reject("wrong number of bone values");
  }
  // Check everything first, so that a bad bone leaves every bone as it was.
  const std::vector<Eigen::Quaterniond> before = rotation_;
  for (std::size_t b = 0; b < model_->bones.size(); ++b) {
    const Bone& bone = model_->bones[b];
    if (!SetBone(static_cast<int>(b), &values[static_cast<std::size_t>(bone.first_value)],
                 bone.num_values)) {
      rotation_ = before;
      return false;
    }
  }
  return true;
}

void RobotState::Update() {
  // Forward kinematics: parents come first in the node list.
  const std::size_t num_nodes = model_->nodes.size();
  for (std::size_t n = 0; n < num_nodes; ++n) {
    const RobotNode& node = model_->nodes[n];
    const Eigen::Affine3d& X_BP =
        node.parent < 0 ? model_->X_BF : X_BN_[static_cast<std::size_t>(node.parent)];
    X_BN_[n] = X_BP * node.X_PN;
    X_BN_[n].linear() *= rotation_[n].toRotationMatrix();
  }
  // One skinning matrix per joint, in float.
  for (std::size_t j = 0; j < model_->joints.size(); ++j) {
    const SkinJoint& joint = model_->joints[j];
    skin_[j] = (X_BN_[static_cast<std::size_t>(joint.node)] * joint.offset)
                   .matrix()
                   .topRows<3>()
                   .cast<float>();
  }
  // Linear-blend skinning; a vertex with one influence takes its matrix as is.
  for (std::size_t m = 0; m < model_->meshes.size(); ++m) {
    const SkinnedMesh& mesh = model_->meshes[m];
    const std::size_t n = mesh.bind.positions_A.size();
    Eigen::Vector3f* positions = positions_B_[m].data();
    Eigen::Vector3f* normals = normals_B_[m].data();
    const Eigen::Vector3f* bind_positions = mesh.bind.positions_A.data();
    const Eigen::Vector3f* bind_normals = mesh.bind.normals_A.data();
    for (std::size_t v = 0; v < n; ++v) {
      const std::uint32_t begin = mesh.influence_begin[v], end = mesh.influence_begin[v + 1];
      Eigen::Matrix<float, 3, 4> M = skin_[mesh.influence_joint[begin]];
      if (end - begin > 1) {
        M *= mesh.influence_weight[begin];
        for (std::uint32_t i = begin + 1; i < end; ++i) {
          M += mesh.influence_weight[i] * skin_[mesh.influence_joint[i]];
        }
      }
      positions[v] = M.leftCols<3>() * bind_positions[v] + M.col(3);
      normals[v] = (M.leftCols<3>() * bind_normals[v]).normalized();
    }
  }
}

Eigen::Affine3d RobotState::node_pose_W(int node) const {
  SANDBOX_CHECK(node >= 0 && node < static_cast<int>(X_BN_.size()));
  return X_WB_ * X_BN_[static_cast<std::size_t>(node)];
}

const std::vector<Eigen::Vector3f>& RobotState::positions_B(int mesh) const {
  SANDBOX_CHECK(mesh >= 0 && mesh < static_cast<int>(positions_B_.size()));
  return positions_B_[static_cast<std::size_t>(mesh)];
}

const std::vector<Eigen::Vector3f>& RobotState::normals_B(int mesh) const {
  SANDBOX_CHECK(mesh >= 0 && mesh < static_cast<int>(normals_B_.size()));
  return normals_B_[static_cast<std::size_t>(mesh)];
}

}  // namespace sandbox::scene
