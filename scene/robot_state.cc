#include "scene/robot_state.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "scene/check.h"

namespace sandbox::scene {

RobotState::RobotState(const RobotModel& model)
    : model_(&model),
      X_WB_(model.X_WB_spawn),
      rotation_(model.nodes.size(), Eigen::Quaterniond::Identity()),
      translation_(model.nodes.size(), Eigen::Vector3d::Zero()),
      X_BN_(model.nodes.size(), Eigen::Affine3d::Identity()),
      skin_(model.joints.size()),
      rigid_(model.joints.size()) {
  values_.assign(static_cast<std::size_t>(model.num_values), 0.0);
  for (const Bone& bone : model.bones) {
    if (bone.rotation == BoneRotation::kQuaternion)
      values_[static_cast<std::size_t>(bone.first_value)] = 1.0;
  }
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

std::string PoseProblem(const Eigen::Isometry3d& X_WB) {
  if (!X_WB.matrix().allFinite()) return "non-finite pose";
  const Eigen::Matrix3d R = X_WB.linear();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0) {
    return "pose rotation is not a rotation";
  }
  return "";
}

std::string BoneValuesProblem(const Bone& bone, const double* values, int num_values) {
  if (num_values != bone.num_values) return "wrong number of bone values";
  for (int i = 0; i < num_values; ++i) {
    if (!std::isfinite(values[i])) return "non-finite bone value";
  }
  if (bone.rotation == BoneRotation::kQuaternion &&
      std::abs(Eigen::Quaterniond(values[0], values[1], values[2], values[3]).norm() - 1.0) >
          1e-3) {
    return "non-unit bone quaternion";
  }
  if (bone.rotation != BoneRotation::kQuaternion) {
    for (int i = 0; i < num_values; ++i) {
      if (values[i] < bone.lower || values[i] > bone.upper) return "joint value beyond its limits";
    }
  }
  return "";
}

bool RobotState::SetPose(const Eigen::Isometry3d& X_WB) {
  if (std::string problem = PoseProblem(X_WB); !problem.empty()) return Reject(problem);
  X_WB_ = X_WB;
  return true;
}

bool RobotState::SetBone(int bone, const double* values, int num_values) {
  if (bone < 0 || bone >= static_cast<int>(model_->bones.size())) {
    return Reject("bone index out of range");
  }
  const Bone& b = model_->bones[static_cast<std::size_t>(bone)];
  if (std::string problem = BoneValuesProblem(b, values, num_values); !problem.empty()) {
    return Reject(problem);
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (b.rotation == BoneRotation::kQuaternion) {
    q = Eigen::Quaterniond(values[0], values[1], values[2], values[3]).normalized();
  } else if (b.rotation == BoneRotation::kSlide) {
    translation_[static_cast<std::size_t>(b.node)] = values[0] * b.axes[0];
  } else {
    for (std::size_t a = 0; a < b.axes.size(); ++a) {
      q = q * Eigen::Quaterniond(Eigen::AngleAxisd(values[a], b.axes[a]));
    }
  }
  rotation_[static_cast<std::size_t>(b.node)] = q;
  std::copy(values, values + num_values, values_.begin() + b.first_value);
  return true;
}

bool RobotState::SetBones(const std::vector<double>& values) {
  if (static_cast<int>(values.size()) != model_->num_values) {
    return Reject("wrong number of bone values");
  }
  // Check everything first, so that a bad bone leaves every bone as it was.
  for (const Bone& bone : model_->bones) {
    const std::string problem = BoneValuesProblem(
        bone, &values[static_cast<std::size_t>(bone.first_value)], bone.num_values);
    if (!problem.empty()) return Reject(problem);
  }
  for (std::size_t b = 0; b < model_->bones.size(); ++b) {
    const Bone& bone = model_->bones[b];
    SetBone(static_cast<int>(b), &values[static_cast<std::size_t>(bone.first_value)],
            bone.num_values);
  }
  return true;
}

void RobotState::Update() {
  UpdateKinematics();
  Skin();
}

void RobotState::Skin() {
  if (skinned_) return;
  skinned_ = true;
  // One skinning matrix per joint, in float.
  for (std::size_t j = 0; j < model_->joints.size(); ++j) {
    const SkinJoint& joint = model_->joints[j];
    skin_[j] = (X_BN_[static_cast<std::size_t>(joint.node)] * joint.offset)
                   .matrix()
                   .topRows<3>()
                   .cast<float>();
  }
  // A joint's matrix is rigid when its 3x3 part is a rotation: normals then
  // keep their length and need no normalising.
  for (std::size_t j = 0; j < skin_.size(); ++j) {
    const Eigen::Matrix3f L = skin_[j].leftCols<3>();
    rigid_[j] = (L.transpose() * L - Eigen::Matrix3f::Identity()).cwiseAbs().maxCoeff() < 1e-5f;
  }
  for (std::size_t m = 0; m < model_->meshes.size(); ++m) {
    const SkinnedMesh& mesh = model_->meshes[m];
    for (const SkinRun& run : mesh.runs) SkinRunOfVertices(mesh, run, m);
    for (const std::uint32_t v : mesh.scattered) SkinVertex(mesh, v, m);
  }
}

void RobotState::UpdateKinematics() {
  // Forward kinematics: parents come first in the node list.
  const std::size_t num_nodes = model_->nodes.size();
  for (std::size_t n = 0; n < num_nodes; ++n) {
    const RobotNode& node = model_->nodes[n];
    const Eigen::Affine3d& X_BP =
        node.parent < 0 ? model_->X_BF : X_BN_[static_cast<std::size_t>(node.parent)];
    X_BN_[n] = X_BP * node.X_PN;
    X_BN_[n].translate(translation_[n]);
    X_BN_[n].linear() *= rotation_[n].toRotationMatrix();
  }
  skinned_ = false;
}

// One vertex, any number of influences: blend the matrices, then apply.
void RobotState::SkinVertex(const SkinnedMesh& mesh, std::uint32_t v, std::size_t m) {
  const std::uint32_t begin = mesh.influence_begin[v], end = mesh.influence_begin[v + 1];
  Eigen::Matrix<float, 3, 4> M = mesh.influence_weight[begin] * skin_[mesh.influence_joint[begin]];
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    M += mesh.influence_weight[i] * skin_[mesh.influence_joint[i]];
  }
  positions_B_[m][v] = M.leftCols<3>() * mesh.bind.positions_A[v] + M.col(3);
  normals_B_[m][v] = (M.leftCols<3>() * mesh.bind.normals_A[v]).normalized();
}

#if defined(__SSE2__)
namespace {

// A 3x4 matrix with every entry broadcast (or blended) over four vertices.
struct Wide3x4 {
  __m128 m00, m01, m02, m03, m10, m11, m12, m13, m20, m21, m22, m23;
};

inline Wide3x4 Broadcast(const Eigen::Matrix<float, 3, 4>& M) {
  return {_mm_set1_ps(M(0, 0)), _mm_set1_ps(M(0, 1)), _mm_set1_ps(M(0, 2)), _mm_set1_ps(M(0, 3)),
          _mm_set1_ps(M(1, 0)), _mm_set1_ps(M(1, 1)), _mm_set1_ps(M(1, 2)), _mm_set1_ps(M(1, 3)),
          _mm_set1_ps(M(2, 0)), _mm_set1_ps(M(2, 1)), _mm_set1_ps(M(2, 2)), _mm_set1_ps(M(2, 3))};
}

// A += w * M, entry by entry.
inline void AddWeighted(__m128 w, const Eigen::Matrix<float, 3, 4>& M, Wide3x4* A) {
  const float* e = M.data();  // column-major: (0,0) (1,0) (2,0) (0,1) ...
  A->m00 = _mm_add_ps(A->m00, _mm_mul_ps(w, _mm_set1_ps(e[0])));
  A->m10 = _mm_add_ps(A->m10, _mm_mul_ps(w, _mm_set1_ps(e[1])));
  A->m20 = _mm_add_ps(A->m20, _mm_mul_ps(w, _mm_set1_ps(e[2])));
  A->m01 = _mm_add_ps(A->m01, _mm_mul_ps(w, _mm_set1_ps(e[3])));
  A->m11 = _mm_add_ps(A->m11, _mm_mul_ps(w, _mm_set1_ps(e[4])));
  A->m21 = _mm_add_ps(A->m21, _mm_mul_ps(w, _mm_set1_ps(e[5])));
  A->m02 = _mm_add_ps(A->m02, _mm_mul_ps(w, _mm_set1_ps(e[6])));
  A->m12 = _mm_add_ps(A->m12, _mm_mul_ps(w, _mm_set1_ps(e[7])));
  A->m22 = _mm_add_ps(A->m22, _mm_mul_ps(w, _mm_set1_ps(e[8])));
  A->m03 = _mm_add_ps(A->m03, _mm_mul_ps(w, _mm_set1_ps(e[9])));
  A->m13 = _mm_add_ps(A->m13, _mm_mul_ps(w, _mm_set1_ps(e[10])));
  A->m23 = _mm_add_ps(A->m23, _mm_mul_ps(w, _mm_set1_ps(e[11])));
}

// Four x, four y and four z values stored as four consecutive (x, y, z).
inline void StoreFourXyz(__m128 x, __m128 y, __m128 z, float* out) {
  const __m128 xy_low = _mm_unpacklo_ps(x, y);   // x0 y0 x1 y1
  const __m128 xy_high = _mm_unpackhi_ps(x, y);  // x2 y2 x3 y3
  const __m128 z0_x1 = _mm_unpacklo_ps(z, _mm_shuffle_ps(x, x, _MM_SHUFFLE(1, 1, 1, 1)));
  const __m128 yz = _mm_unpacklo_ps(y, z);  // y0 z0 y1 z1
  const __m128 z2z3x3y3 = _mm_shuffle_ps(z, xy_high, _MM_SHUFFLE(3, 2, 3, 2));
  _mm_storeu_ps(out, _mm_movelh_ps(xy_low, z0_x1));                              // x0 y0 z0 x1
  _mm_storeu_ps(out + 4, _mm_shuffle_ps(yz, xy_high, _MM_SHUFFLE(1, 0, 3, 2)));  // y1 z1 x2 y2
  _mm_storeu_ps(out + 8,
                _mm_shuffle_ps(z2z3x3y3, z2z3x3y3, _MM_SHUFFLE(1, 3, 2, 0)));  // z2 x3 y3 z3
}

// Positions and normals of vertices v .. v+3 under the wide matrix M.
inline void SkinFour(const Wide3x4& M, const SkinnedMesh& mesh, std::uint32_t v, bool normalize,
                     float* positions, float* normals) {
  const __m128 x = _mm_loadu_ps(&mesh.bind_x[v]), y = _mm_loadu_ps(&mesh.bind_y[v]);
  const __m128 z = _mm_loadu_ps(&mesh.bind_z[v]);
  StoreFourXyz(_mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m00, x), _mm_mul_ps(M.m01, y)),
                          _mm_add_ps(_mm_mul_ps(M.m02, z), M.m03)),
               _mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m10, x), _mm_mul_ps(M.m11, y)),
                          _mm_add_ps(_mm_mul_ps(M.m12, z), M.m13)),
               _mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m20, x), _mm_mul_ps(M.m21, y)),
                          _mm_add_ps(_mm_mul_ps(M.m22, z), M.m23)),
               positions + 3 * std::size_t{v});
  const __m128 nx = _mm_loadu_ps(&mesh.bind_nx[v]), ny = _mm_loadu_ps(&mesh.bind_ny[v]);
  const __m128 nz = _mm_loadu_ps(&mesh.bind_nz[v]);
  __m128 ox =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m00, nx), _mm_mul_ps(M.m01, ny)), _mm_mul_ps(M.m02, nz));
  __m128 oy =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m10, nx), _mm_mul_ps(M.m11, ny)), _mm_mul_ps(M.m12, nz));
  __m128 oz =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(M.m20, nx), _mm_mul_ps(M.m21, ny)), _mm_mul_ps(M.m22, nz));
  if (normalize) {
    const __m128 length = _mm_sqrt_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(ox, ox), _mm_mul_ps(oy, oy)), _mm_mul_ps(oz, oz)));
    ox = _mm_div_ps(ox, length), oy = _mm_div_ps(oy, length), oz = _mm_div_ps(oz, length);
  }
  StoreFourXyz(ox, oy, oz, normals + 3 * std::size_t{v});
}

}  // namespace
#endif

// A run of vertices on the same joints, four at a time: per vertex the
// weighted sum of the joints' matrices, applied to position and normal.
void RobotState::SkinRunOfVertices(const SkinnedMesh& mesh, const SkinRun& run, std::size_t m) {
  float* positions = positions_B_[m][0].data();
  float* normals = normals_B_[m][0].data();
  std::uint32_t v = run.first;
  const std::uint32_t end = run.first + run.count;
#if defined(__SSE2__)
  if (run.num_joints == 1) {
    const Wide3x4 M = Broadcast(skin_[run.joints[0]]);
    const bool normalize = !rigid_[run.joints[0]];
    for (; v + 4 <= end; v += 4) SkinFour(M, mesh, v, normalize, positions, normals);
  } else {
    for (; v + 4 <= end; v += 4) {
      const __m128 zero = _mm_setzero_ps();
      Wide3x4 M{zero, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero};
      for (int j = 0; j < run.num_joints; ++j) {
        AddWeighted(_mm_loadu_ps(&mesh.run_weight[j][v]), skin_[run.joints[j]], &M);
      }
      SkinFour(M, mesh, v, true, positions, normals);
    }
  }
#endif
  for (; v < end; ++v) SkinVertex(mesh, v, m);
}

Eigen::Isometry3d RobotState::MountPose(const SensorSpec& spec) const {
  const Eigen::Isometry3d X_BM = spec.mount_node < 0
                                     ? Eigen::Isometry3d::Identity()
                                     : RigidPart(X_BN_[static_cast<std::size_t>(spec.mount_node)]);
  return X_WB_ * X_BM * spec.X_MS;
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
