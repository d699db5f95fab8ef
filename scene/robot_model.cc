#include "scene/robot_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include "scene/asset_import.h"
#include "scene/assimp_read.h"
#include "scene/described_robot.h"
#include "scene/level.h"
#include "scene/robot_description.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// The node tree in depth-first order (parents first).
void CollectNodes(const aiNode& node, int parent, std::vector<RobotNode>* nodes,
                  std::vector<const aiNode*>* sources) {
  RobotNode out;
  out.name = node.mName.C_Str();
  if (out.name.empty()) out.name = "node" + std::to_string(nodes->size());
  out.parent = parent;
  out.X_PN = Eigen::Affine3d(ToEigen(node.mTransformation));
  const int index = static_cast<int>(nodes->size());
  nodes->push_back(out);
  sources->push_back(&node);
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    CollectNodes(*node.mChildren[c], index, nodes, sources);
  }
}

// Finds or adds the joint (node, offset); rigid meshes share one joint per node.
std::uint16_t JointIndex(RobotModel* model, int node, const Eigen::Affine3d& offset) {
  for (std::size_t j = 0; j < model->joints.size(); ++j) {
    if (model->joints[j].node == node && model->joints[j].offset.isApprox(offset, 0.0)) {
      return static_cast<std::uint16_t>(j);
    }
  }
  model->joints.push_back({node, offset});
  return static_cast<std::uint16_t>(model->joints.size() - 1);
}

// Builds the weights of one aiMesh on node `node`: its bones when it has
// some, else every vertex rigidly on the node.
SkinnedMesh ConvertSkinnedMesh(const aiMesh& in, int node, int material_base, RobotModel* model,
                               std::size_t* non_triangles) {
  SkinnedMesh out;
  out.bind = ConvertMesh(in, non_triangles);
  if (out.bind.material >= 0) out.bind.material += material_base;
  const std::size_t n = out.bind.positions_A.size();
  std::vector<std::vector<std::pair<std::uint16_t, float>>> influences(n);
  for (unsigned b = 0; b < in.mNumBones; ++b) {
    const aiBone& bone = *in.mBones[b];
    const int bone_node = model->FindNode(bone.mName.C_Str());
    if (bone_node < 0) continue;  // assimp always names an existing node
    const std::uint16_t joint =
        JointIndex(model, bone_node, Eigen::Affine3d(ToEigen(bone.mOffsetMatrix)));
    for (unsigned w = 0; w < bone.mNumWeights; ++w) {
      const aiVertexWeight& weight = bone.mWeights[w];
      if (weight.mVertexId < n && weight.mWeight > 0.0f) {
        influences[weight.mVertexId].emplace_back(joint, weight.mWeight);
      }
    }
  }
  // Vertices without weights (and every vertex of a rigid mesh) follow the node.
  const std::uint16_t rigid = JointIndex(model, node, Eigen::Affine3d::Identity());
  out.influence_begin.reserve(n + 1);
  out.influence_begin.push_back(0);
  for (std::size_t v = 0; v < n; ++v) {
    auto& list = influences[v];
    float sum = 0.0f;
    for (const auto& [joint, weight] : list) sum += weight;
    if (list.empty() || sum <= 0.0f) list = {{rigid, 1.0f}}, sum = 1.0f;
    for (const auto& [joint, weight] : list) {
      out.influence_joint.push_back(joint);
      out.influence_weight.push_back(weight / sum);
    }
    out.influence_begin.push_back(static_cast<std::uint32_t>(out.influence_joint.size()));
  }
  return out;
}

std::string NodeList(const RobotModel& model) {
  std::ostringstream out;
  for (std::size_t i = 0; i < model.nodes.size() && i < 12; ++i) {
    out << (i > 0 ? ", " : "") << model.nodes[i].name;
  }
  if (model.nodes.size() > 12) out << ", ... (" << model.nodes.size() << " in all)";
  return out.str();
}

bool IsBelow(const RobotModel& model, int node, int ancestor) {
  for (int n = node; n >= 0; n = model.nodes[static_cast<std::size_t>(n)].parent) {
    if (n == ancestor) return true;
  }
  return false;
}

// The bone map: names to nodes, and where each bone's values sit.
void MapBones(const RobotSpec& spec, bool has_skeleton, RobotModel* model,
              const std::string& where) {
  auto fail = [&](const std::string& what) { throw LevelError(where + what); };
  if (spec.bones.empty()) return;
  if (!has_skeleton) {
    fail(spec.file.string() +
         " has no skeleton (no bones and a single node), but 'bones' "
         "declares " +
         std::to_string(spec.bones.size()));
  }
  if (spec.bones.size() > model->nodes.size()) {
    fail("the bone map lists " + std::to_string(spec.bones.size()) + " bones, the skeleton of " +
         spec.file.filename().string() + " has " + std::to_string(model->nodes.size()) + " nodes");
  }
  for (const std::string& name : spec.bones) {
    Bone bone;
    bone.name = name;
    bone.node = model->FindNode(name);
    if (bone.node < 0) {
      fail("bone '" + name + "' is not a node of " + spec.file.filename().string() +
           " (nodes: " + NodeList(*model) + ")");
    }
    if (!model->bones.empty() && !IsBelow(*model, bone.node, model->bones[0].node)) {
      fail("bone 0 '" + model->bones[0].name + "' must be the root of the bone map, but '" + name +
           "' is not below it");
    }
    bone.rotation = spec.rotation;
    if (bone.rotation == BoneRotation::kAngles) {
      const auto override_axes = spec.bone_axes.find(name);
      bone.axes = override_axes != spec.bone_axes.end() ? override_axes->second : spec.angle_axes;
    }
    bone.first_value = model->num_values;
    bone.num_values = bone.rotation == BoneRotation::kQuaternion ? 4 : int(bone.axes.size());
    model->num_values += bone.num_values;
    model->bones.push_back(std::move(bone));
  }
}

// Sensor and camera mounts: a node of the robot, or its body frame.
void ResolveMounts(const RobotSpec& spec, RobotModel* model_out) {
  RobotModel& model = *model_out;
  for (const auto* list : {&spec.sensors, &spec.cameras}) {
    for (SensorSpec sensor : *list) {
      if (!sensor.mount.empty() && sensor.mount != "body") {
        sensor.mount_node = model.FindNode(sensor.mount);
        if (sensor.mount_node < 0) {
          throw LevelError(sensor.Where() + "mount '" + sensor.mount + "' is not a node of " +
                           spec.file.filename().string() + " (nodes: " + NodeList(model) + ")");
        }
      }
      (list == &spec.sensors ? model.sensors : model.cameras).push_back(std::move(sensor));
    }
  }
}

}  // namespace

void PrepareSkinning(SkinnedMesh* mesh) {
  const std::size_t n = mesh->bind.positions_A.size();
  mesh->runs.clear();
  mesh->scattered.clear();
  for (std::vector<float>& weights : mesh->run_weight) weights.assign(n, 0.0f);
  // A vertex's joints in order; empty when it has more than four.
  auto joints_of = [&](std::size_t v) {
    std::vector<std::uint16_t> joints(mesh->influence_joint.begin() + mesh->influence_begin[v],
                                      mesh->influence_joint.begin() + mesh->influence_begin[v + 1]);
    std::sort(joints.begin(), joints.end());
    if (joints.size() > 4 || std::adjacent_find(joints.begin(), joints.end()) != joints.end()) {
      joints.clear();
    }
    return joints;
  };
  for (std::size_t v = 0; v < n;) {
    const std::vector<std::uint16_t> joints = joints_of(v);
    std::size_t end = v + 1;
    while (!joints.empty() && end < n && joints_of(end) == joints) ++end;
    if (joints.empty() || end - v < 4) {
      for (std::size_t u = v; u < end; ++u)
        mesh->scattered.push_back(static_cast<std::uint32_t>(u));
      v = end;
      continue;
    }
    SkinRun run;
    run.first = static_cast<std::uint32_t>(v);
    run.count = static_cast<std::uint32_t>(end - v);
    run.num_joints = static_cast<int>(joints.size());
    std::copy(joints.begin(), joints.end(), run.joints);
    for (std::size_t u = v; u < end; ++u) {
      for (std::uint32_t i = mesh->influence_begin[u]; i < mesh->influence_begin[u + 1]; ++i) {
        const auto k =
            std::find(joints.begin(), joints.end(), mesh->influence_joint[i]) - joints.begin();
        mesh->run_weight[k][u] = mesh->influence_weight[i];
      }
    }
    mesh->runs.push_back(run);
    v = end;
  }
  std::vector<float>* soa[6] = {&mesh->bind_x,  &mesh->bind_y,  &mesh->bind_z,
                                &mesh->bind_nx, &mesh->bind_ny, &mesh->bind_nz};
  for (int k = 0; k < 3; ++k) {
    soa[k]->resize(n);
    soa[k + 3]->resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      (*soa[k])[v] = mesh->bind.positions_A[v][k];
      (*soa[k + 3])[v] = mesh->bind.normals_A[v][k];
    }
  }
}

std::vector<int> DominantNodePerTriangle(const RobotModel& model, const SkinnedMesh& mesh) {
  const std::vector<std::uint32_t>& indices = mesh.bind.indices;
  std::vector<int> nodes(indices.size() / 3);
  std::map<int, float> weight_of_node;
  for (std::size_t t = 0; t < nodes.size(); ++t) {
    weight_of_node.clear();
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = indices[3 * t + std::size_t(k)];
      for (std::uint32_t i = mesh.influence_begin[v]; i < mesh.influence_begin[v + 1]; ++i) {
        weight_of_node[model.joints[mesh.influence_joint[i]].node] += mesh.influence_weight[i];
      }
    }
    nodes[t] = std::max_element(weight_of_node.begin(), weight_of_node.end(),
                                [](const auto& a, const auto& b) { return a.second < b.second; })
                   ->first;
  }
  return nodes;
}

Eigen::Isometry3d RigidPart(const Eigen::Affine3d& X) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() = X.translation();
  const Eigen::Matrix3d L = X.linear();
  const double scale = std::cbrt(L.determinant());
  Eigen::Matrix3d R = L / scale;
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6)) {
    Eigen::Matrix3d scaling;
    X.computeRotationScaling(&R, &scaling);  // shear or non-uniform scale: the nearest rotation
  }
  out.linear() = R;
  return out;
}

int RobotModel::FindNode(const std::string& node_name) const {
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].name == node_name) return static_cast<int>(i);
  }
  return -1;
}

int RobotModel::FindBone(const std::string& bone_name) const {
  for (std::size_t i = 0; i < bones.size(); ++i) {
    if (bones[i].name == bone_name) return static_cast<int>(i);
  }
  return -1;
}

std::size_t RobotModel::num_vertices() const {
  return std::accumulate(
      meshes.begin(), meshes.end(), std::size_t{0},
      [](std::size_t sum, const SkinnedMesh& m) { return sum + m.bind.positions_A.size(); });
}

std::size_t RobotModel::num_triangles() const {
  return std::accumulate(
      meshes.begin(), meshes.end(), std::size_t{0},
      [](std::size_t sum, const SkinnedMesh& m) { return sum + m.bind.num_triangles(); });
}

RobotModel LoadRobotModel(const RobotSpec& spec, const fs::path& manifest, Level* level,
                          const std::function<void(const fs::path&, std::string_view)>& on_file) {
  // Messages start "manifest:line: robot 'name': " (a description given as
  // the level itself: its own messages name it).
  const std::string where = spec.line > 0 ? manifest.string() + ":" + std::to_string(spec.line) +
                                                ": robot '" + spec.name + "': "
                                          : "";
  RobotModel model;
  model.name = spec.name;
  model.file = spec.file;
  model.collision = spec.collision;
  model.bridge = spec.bridge;
  model.X_WB_spawn = spec.placement.pose();
  if (IsRobotDescription(spec.file)) {
    if (on_file) on_file(spec.file, "urdfdom");
    BuildDescribedRobot(spec, where, level, on_file, &model);
    if (model.meshes.empty() && model.collision_meshes.empty()) {
      throw LevelError(where + spec.file.string() + ": no link has geometry");
    }
    ResolveMounts(spec, &model);
    return model;
  }
  if (on_file) on_file(spec.file, AssetReader(spec.file));

  Assimp::Importer importer;
  AssimpScene read;
  try {
    read = ReadAssimpScene(importer, spec.file, spec.placement.conversion, level->limits);
  } catch (const LevelError& error) {
    throw LevelError(where + error.what());
  }
  model.X_BF = Eigen::Scaling(spec.placement.scale) * read.X_RF;
  const aiScene& scene = *read.scene;
  const int material_base =
      AppendMaterials(std::move(read.materials), std::move(read.textures), level);
  for (std::string& warning : read.warnings) level->warnings.push_back(std::move(warning));

  // The skeleton: every node of the file.
  std::vector<const aiNode*> sources;
  CollectNodes(*scene.mRootNode, -1, &model.nodes, &sources);
  bool has_bones = false;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) has_bones |= scene.mMeshes[m]->HasBones();
  MapBones(spec, has_bones || model.nodes.size() > 1, &model, where);

  // Meshes with their weights.
  std::size_t non_triangles = 0;
  for (std::size_t n = 0; n < sources.size(); ++n) {
    for (unsigned i = 0; i < sources[n]->mNumMeshes; ++i) {
      SkinnedMesh mesh = ConvertSkinnedMesh(*scene.mMeshes[sources[n]->mMeshes[i]], int(n),
                                            material_base, &model, &non_triangles);
      if (mesh.bind.indices.empty()) continue;
      PrepareSkinning(&mesh);
      model.meshes.push_back(std::move(mesh));
    }
  }
  if (non_triangles > 0) {
    level->warnings.push_back(spec.file.string() + ": skipped " + std::to_string(non_triangles) +
                              " point and line primitives");
  }
  if (model.meshes.empty()) {
    throw LevelError(where + spec.file.string() + ": has no triangle meshes");
  }

  ResolveMounts(spec, &model);
  return model;
}

}  // namespace sandbox::scene
