// Robots from descriptions: links as nodes, movable joints as bones, shapes
// as meshes rigid on their links (robot_model.h's LoadRobotModel calls it).

#include "scene/described_robot.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <sstream>

#include "scene/asset_import.h"
#include "scene/level.h"
#include "scene/robot_description.h"
#include "scene/shape_meshes.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// Every vertex of `mesh` rigidly on node `node` (its bind space is the node's frame).
SkinnedMesh RigidOnNode(Mesh mesh, int node, RobotModel* model) {
  SkinnedMesh out;
  out.bind = std::move(mesh);
  // One skin joint per node for rigid meshes: (node, identity).
  std::uint16_t joint = 0;
  while (joint < model->joints.size() &&
         !(model->joints[joint].node == node &&
           model->joints[joint].offset.isApprox(Eigen::Affine3d::Identity(), 0.0))) {
    ++joint;
  }
  if (joint == model->joints.size()) model->joints.push_back({node, Eigen::Affine3d::Identity()});
  const std::size_t n = out.bind.positions_A.size();
  out.influence_begin.resize(n + 1);
  std::iota(out.influence_begin.begin(), out.influence_begin.end(), 0u);
  out.influence_joint.assign(n, joint);
  out.influence_weight.assign(n, 1.0f);
  PrepareSkinning(&out);
  return out;
}

// A robot description's links as nodes, movable joints as bones, geometry as
// meshes rigid on their links (drawn: the visuals; rays: the collisions).
class DescribedRobotBuilder {
 public:
  DescribedRobotBuilder(const RobotSpec& spec, const std::string& where, Level* level,
                        const std::function<void(const fs::path&, std::string_view)>& on_file)
      : spec_(spec), where_(where), level_(level), on_file_(on_file) {}

  void Build(RobotModel* model) {
    if (!spec_.bones.empty() || !spec_.angle_axes.empty() || !spec_.bone_axes.empty()) {
      throw LevelError(where_ + "'bones', 'angle_axes' and 'bone_axes' are for skeleton files; " +
                       spec_.file.filename().string() +
                       " is a robot description, whose bones are its movable joints");
    }
    RobotDescription description;
    try {
      description = ReadRobotDescription(spec_.file);
    } catch (const LevelError& error) {
      throw LevelError(where_ + error.what());
    }
    for (std::string& warning : description.warnings) level_->warnings.push_back(warning);
    model->described = true;
    model->X_BF = Eigen::Affine3d(Eigen::Scaling(spec_.placement.scale));  // Z up, metres
    // A node per link; a revolute joint whose axis misses its child's origin
    // (SDF) adds a node at the pivot that turns, the link hanging from it.
    std::vector<int> node_of_link(description.links.size(), -1);
    auto add_node = [&](const std::string& name, int parent, const Eigen::Isometry3d& X_PN) {
      RobotNode node;
      node.name = name;
      node.parent = parent;
      node.X_PN = Eigen::Affine3d(X_PN.matrix());
      model->nodes.push_back(node);
      return int(model->nodes.size()) - 1;
    };
    node_of_link[0] = add_node(description.links[0].name, -1, Eigen::Isometry3d::Identity());
    for (const DescribedJoint& joint : description.joints) {
      const int parent = node_of_link[std::size_t(joint.parent)];
      const std::string& link = description.links[std::size_t(joint.child)].name;
      const bool pivots = joint.moves() && joint.type != DescribedJoint::Type::kPrismatic &&
                          joint.pivot.norm() > 1e-12;
      int moving = -1;
      if (pivots) {
        const std::string name =
            description.links.end() !=
                    std::find_if(description.links.begin(), description.links.end(),
                                 [&](const DescribedLink& l) { return l.name == joint.name; })
                ? joint.name + " joint"
                : joint.name;
        moving = add_node(name, parent, joint.X_PC * Eigen::Translation3d(joint.pivot));
        node_of_link[std::size_t(joint.child)] =
            add_node(link, moving, Eigen::Isometry3d(Eigen::Translation3d(-joint.pivot)));
      } else {
        moving = node_of_link[std::size_t(joint.child)] = add_node(link, parent, joint.X_PC);
      }
      if (!joint.moves()) continue;
      Bone bone;
      bone.name = joint.name;
      bone.node = moving;
      bone.rotation = joint.type == DescribedJoint::Type::kPrismatic ? BoneRotation::kSlide
                                                                     : BoneRotation::kAngles;
      bone.axes = {joint.axis};
      bone.first_value = model->num_values;
      bone.num_values = 1;
      bone.lower = joint.lower, bone.upper = joint.upper;
      model->num_values += 1;
      model->bones.push_back(std::move(bone));
    }
    for (const DescribedLink& link : description.links) model->links.push_back(link.name);
    for (std::size_t l = 0; l < description.links.size(); ++l) {
      const DescribedLink& link = description.links[l];
      for (const LinkGeometry& geometry : link.visuals) {
        for (Mesh& mesh : Meshes(geometry, link.name, true)) {
          model->meshes.push_back(RigidOnNode(std::move(mesh), node_of_link[l], model));
        }
      }
      for (const LinkGeometry& geometry : link.collisions) {
        for (Mesh& mesh : Meshes(geometry, link.name, false)) {
          model->collision_meshes.push_back(RigidOnNode(std::move(mesh), node_of_link[l], model));
        }
      }
    }
  }

 private:
  // The geometry as meshes in its link's frame; drawn ones get materials.
  std::vector<Mesh> Meshes(const LinkGeometry& geometry, const std::string& link, bool drawn) {
    std::vector<Mesh> out;
    const Eigen::Affine3d X_LG(geometry.X_LG.matrix());
    switch (geometry.kind) {
      case LinkGeometry::Kind::kBox:
        out.push_back(BoxMesh(geometry.size));
        break;
      case LinkGeometry::Kind::kCylinder:
        out.push_back(CylinderMesh(geometry.radius, geometry.length));
        break;
      case LinkGeometry::Kind::kSphere:
        out.push_back(SphereMesh(geometry.radius));
        break;
      case LinkGeometry::Kind::kMesh: {
        const Asset& asset = Read(geometry.mesh, drawn);
        const Eigen::Affine3d X_LF = X_LG * Eigen::Scaling(geometry.scale);
        for (const ImportedNode& node : asset.imported.nodes) {
          for (Mesh mesh : node.meshes) {
            TransformMesh(X_LF * node.X_RN, &mesh);
            mesh.material = mesh.material >= 0 && asset.material_base >= 0
                                ? mesh.material + asset.material_base
                                : -1;
            if (!drawn) mesh.uvs.clear(), mesh.lightmap_uvs.clear(), mesh.colors.clear();
            out.push_back(std::move(mesh));
          }
        }
        for (Mesh& mesh : out) mesh.material = drawn ? mesh.material : -1;
        break;
      }
    }
    if (geometry.kind != LinkGeometry::Kind::kMesh) {
      for (Mesh& mesh : out) TransformMesh(X_LG, &mesh);
    }
    if (drawn) {
      // A colour the description gives: for shapes, and meshes without their own.
      for (Mesh& mesh : out) {
        if (mesh.material >= 0) continue;
        Material material;
        material.name = geometry.material.empty() ? link : geometry.material;
        material.base_color = geometry.rgba.value_or(Eigen::Vector4f(0.7f, 0.7f, 0.7f, 1.0f));
        std::ostringstream key;
        key << material.name << ' ' << material.base_color.transpose();
        auto [at, is_new] = materials_.try_emplace(key.str(), -1);
        if (is_new) at->second = AppendMaterials({material}, {}, level_);
        mesh.material = at->second;
      }
    }
    return out;
  }

  struct Asset {
    ImportedAsset imported;
    int material_base{-1};  // -1: its materials are not in the level yet
  };

  // A mesh file, read once (its materials added to the level once drawn).
  const Asset& Read(const fs::path& file, bool drawn) {
    auto [at, is_new] = assets_.try_emplace(file.string());
    Asset& asset = at->second;
    if (is_new) {
      if (on_file_) on_file_(file, AssetReader(file));
      try {
        asset.imported = ImportAsset(file, {}, level_->limits);
      } catch (const LevelError& error) {
        throw LevelError(where_ + error.what());
      }
      for (std::string& warning : asset.imported.warnings) level_->warnings.push_back(warning);
    }
    if (drawn && asset.material_base < 0 && !asset.imported.materials.empty()) {
      asset.material_base =
          AppendMaterials(asset.imported.materials, asset.imported.textures, level_);
    }
    return asset;
  }

  const RobotSpec& spec_;
  const std::string& where_;
  Level* level_;
  const std::function<void(const fs::path&, std::string_view)>& on_file_;
  std::map<std::string, Asset> assets_;
  std::map<std::string, int> materials_;  // the description's colours, by name and value
};

}  // namespace

void BuildDescribedRobot(const RobotSpec& spec, const std::string& where, Level* level,
                         const std::function<void(const fs::path&, std::string_view)>& on_file,
                         RobotModel* model) {
  DescribedRobotBuilder(spec, where, level, on_file).Build(model);
}

}  // namespace sandbox::scene
