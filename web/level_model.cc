#include "web/level_model.h"

#include <assimp/material.h>
#include <assimp/scene.h>
#include <meshoptimizer.h>

#include <nlohmann/json.hpp>

#include "scene/robot_state.h"
#include "scene/surface_ids.h"

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

namespace sandbox::web {
namespace {

// The mesh's triangles, simplified to about `ratio` of them (1: as they
// are): by edge collapse keeping the borders, and where that stops short of
// the count (a mesh of many small parts), by clustering.
std::vector<std::uint32_t> Simplified(const scene::Mesh& mesh, double ratio) {
  if (ratio >= 1.0 || mesh.indices.empty()) return mesh.indices;
  const std::size_t target =
      std::max<std::size_t>(3, std::size_t(double(mesh.indices.size()) * ratio) / 3 * 3);
  std::vector<std::uint32_t> out(mesh.indices.size());
  const float* positions = mesh.positions_A[0].data();
  out.resize(meshopt_simplify(out.data(), mesh.indices.data(), mesh.indices.size(), positions,
                              mesh.positions_A.size(), sizeof(Eigen::Vector3f), target, 1e-2f,
                              meshopt_SimplifyLockBorder, nullptr));
  if (out.size() > target + target / 4) {
    out.resize(mesh.indices.size());
    out.resize(meshopt_simplifySloppy(out.data(), mesh.indices.data(), mesh.indices.size(),
                                      positions, mesh.positions_A.size(), sizeof(Eigen::Vector3f),
                                      target, 1.0f, nullptr));
  }
  return out;
}

aiMatrix4x4 ToAssimp(const Eigen::Affine3d& X_affine) {
  const Eigen::Matrix4f X = X_affine.matrix().cast<float>();
  return aiMatrix4x4(X(0, 0), X(0, 1), X(0, 2), X(0, 3), X(1, 0), X(1, 1), X(1, 2), X(1, 3),
                     X(2, 0), X(2, 1), X(2, 2), X(2, 3), X(3, 0), X(3, 1), X(3, 2), X(3, 3));
}

aiNode* MakeParentOf(const std::string& name, const std::vector<aiNode*>& children) {
  auto* node = new aiNode(name);
  node->mNumChildren = unsigned(children.size());
  node->mChildren = new aiNode*[std::max<std::size_t>(1, children.size())];
  for (std::size_t i = 0; i < children.size(); ++i) {
    children[i]->mParent = node;
    node->mChildren[i] = children[i];
  }
  return node;
}

// One of a robot's meshes in bind space with its joints as assimp bones
// (named as the joint nodes), at most four influences a vertex (glTF's
// JOINTS_0), the strongest, their weights scaled to sum to 1.
aiMesh* MakeRobotMesh(const scene::SkinnedMesh& source, const std::string& joint_prefix,
                      const scene::RobotModel& model, unsigned material) {
  auto* mesh = new aiMesh;
  const scene::Mesh& bind = source.bind;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = material;
  mesh->mNumVertices = unsigned(bind.positions_A.size());
  mesh->mVertices = new aiVector3D[mesh->mNumVertices];
  const bool normals = bind.normals_A.size() == bind.positions_A.size();
  if (normals) mesh->mNormals = new aiVector3D[mesh->mNumVertices];
  const bool uvs = bind.uvs.size() == bind.positions_A.size();
  if (uvs) {
    mesh->mTextureCoords[0] = new aiVector3D[mesh->mNumVertices];
    mesh->mNumUVComponents[0] = 2;
  }
  for (std::size_t v = 0; v < bind.positions_A.size(); ++v) {
    if (uvs) mesh->mTextureCoords[0][v] = aiVector3D(bind.uvs[v].x(), bind.uvs[v].y(), 0.0f);
    const Eigen::Vector3f& p = bind.positions_A[v];
    mesh->mVertices[v] = aiVector3D(p.x(), p.y(), p.z());
    if (normals) {
      const Eigen::Vector3f& n = bind.normals_A[v];
      mesh->mNormals[v] = aiVector3D(n.x(), n.y(), n.z());
    }
  }
  mesh->mNumFaces = unsigned(bind.indices.size() / 3);
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices =
        new unsigned[3]{bind.indices[3 * f], bind.indices[3 * f + 1], bind.indices[3 * f + 2]};
  }
  std::map<std::uint16_t, std::vector<aiVertexWeight>> weights;  // by joint
  std::vector<std::pair<float, std::uint16_t>> strongest;
  for (std::uint32_t v = 0; v + 1 < source.influence_begin.size(); ++v) {
    strongest.clear();
    for (std::uint32_t i = source.influence_begin[v]; i < source.influence_begin[v + 1]; ++i)
      strongest.emplace_back(source.influence_weight[i], source.influence_joint[i]);
    std::sort(strongest.begin(), strongest.end(), std::greater<>());
    if (strongest.size() > 4) strongest.resize(4);
    float sum = 0.0f;
    for (const auto& [weight, joint] : strongest) sum += weight;
    for (const auto& [weight, joint] : strongest)
      if (weight > 0.0f) weights[joint].emplace_back(v, weight / sum);
  }
  mesh->mNumBones = unsigned(weights.size());
  mesh->mBones = new aiBone*[std::max<std::size_t>(1, weights.size())];
  unsigned b = 0;
  for (auto& [joint, list] : weights) {
    auto* bone = new aiBone;
    bone->mName = aiString(joint_prefix + std::to_string(joint));
    bone->mOffsetMatrix = ToAssimp(model.joints[joint].offset);
    bone->mNumWeights = unsigned(list.size());
    bone->mWeights = new aiVertexWeight[list.size()];
    std::copy(list.begin(), list.end(), bone->mWeights);
    mesh->mBones[b++] = bone;
  }
  return mesh;
}

// A material's base colour texture as a browser decodes it (a PNG or JPEG
// file's bytes), or empty: none, another format, raw texels, unreadable.
std::pair<std::string, std::string> TextureFile(const scene::Material& material,
                                                const scene::Level& level) {
  auto format_of = [](std::string hint) {
    for (char& c : hint) c = char(std::tolower(static_cast<unsigned char>(c)));
    return hint == "png" ? "png" : hint == "jpg" || hint == "jpeg" ? "jpg" : "";
  };
  if (!material.base_color_texture_path.empty()) {
    const std::filesystem::path path = material.base_color_texture_path;
    const std::string format = format_of(path.extension().string().substr(
        std::min<std::size_t>(1, path.extension().string().size())));
    std::ifstream in(path, std::ios::binary);
    if (format.empty() || !in) return {};
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return {bytes.str(), format};
  }
  const int i = material.base_color_texture_embedded;
  if (i < 0 || std::size_t(i) >= level.textures.size()) return {};
  const scene::EmbeddedTexture& texture = level.textures[std::size_t(i)];
  const std::string format = format_of(texture.format_hint);
  if (texture.height != 0 || format.empty()) return {};
  return {std::string(texture.bytes.begin(), texture.bytes.end()), format};
}

aiMaterial* MakeMaterial(const scene::Material& source, int texture = -1) {
  auto* material = new aiMaterial;
  const aiString name(source.name);
  material->AddProperty(&name, AI_MATKEY_NAME);
  if (texture >= 0) {  // an embedded texture of the scene: "*N"
    const aiString file("*" + std::to_string(texture));
    material->AddProperty(&file, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
    material->AddProperty(&file, AI_MATKEY_TEXTURE(aiTextureType_BASE_COLOR, 0));
  }
  const aiColor4D color(source.base_color.x(), source.base_color.y(), source.base_color.z(),
                        source.base_color.w());
  material->AddProperty(&color, 1, AI_MATKEY_COLOR_DIFFUSE);
  material->AddProperty(&color, 1, AI_MATKEY_BASE_COLOR);
  return material;
}

}  // namespace

std::string LevelInfoJson(const scene::Level& level, const RecordedRun* recorded,
                          bool camera_control) {
  nlohmann::json surfaces = nlohmann::json::array(), robots = nlohmann::json::array();
  const scene::SurfaceIds ids(level);
  for (const scene::SurfaceEntry& entry : ids.entries())
    surfaces.push_back({{"id", entry.id}, {"kind", entry.kind}, {"name", entry.name}});
  for (const scene::RobotModel& robot : level.robots) {
    nlohmann::json bones = nlohmann::json::array(), sensors = nlohmann::json::array();
    for (const scene::Bone& bone : robot.bones)
      bones.push_back({{"name", bone.name}, {"values", bone.num_values}});
    for (const scene::SensorSpec& sensor : robot.sensors)
      sensors.push_back({{"name", sensor.name}, {"type", sensor.type}});
    robots.push_back({{"name", robot.name}, {"bones", std::move(bones)},
                      {"sensors", std::move(sensors)}});
  }
  nlohmann::json info = {{"type", "level"},
                         {"name", level.name},
                         {"surfaces", std::move(surfaces)},
                         {"robots", std::move(robots)},
                         {"camera_control", camera_control}};
  if (recorded != nullptr) {
    info["recorded"] = {{"log", recorded->log},
                        {"ticks", recorded->ticks},
                        {"duration_s", recorded->duration_s}};
  }
  return info.dump();
}

std::string RobotNodeName(int robot) { return "sandbox_robot" + std::to_string(robot); }

LevelModel MakeLevelModel(const scene::Level& level, std::size_t max_triangles,
                          std::size_t max_texture_bytes) {
  LevelModel model;
  for (const scene::Actor& actor : level.actors) model.source_triangles += actor.num_triangles();
  const double ratio = model.source_triangles > max_triangles
                           ? double(max_triangles) / double(model.source_triangles)
                           : 1.0;

  // aiScene owns what it points to (and deletes it with new's partners).
  auto scene = std::make_unique<aiScene>();
  // Base colour textures (PNG, JPEG) embedded, each file once, within a budget.
  std::vector<aiMaterial*> materials;
  std::vector<aiTexture*> textures;
  std::map<std::string, int> texture_of_file;
  std::size_t texture_bytes = 0;
  for (const scene::Material& material : level.materials) {
    int texture = -1;
    const std::string key = material.base_color_texture_path.empty()
                                ? "#" + std::to_string(material.base_color_texture_embedded)
                                : material.base_color_texture_path;
    if (const auto found = texture_of_file.find(key); found != texture_of_file.end()) {
      texture = found->second;
    } else if (auto [bytes, format] = TextureFile(material, level);
               !bytes.empty() && texture_bytes + bytes.size() <= max_texture_bytes) {
      auto* t = new aiTexture;
      t->mWidth = unsigned(bytes.size());
      t->mHeight = 0;  // compressed: a whole file
      std::snprintf(t->achFormatHint, sizeof(t->achFormatHint), "%s", format.c_str());
      t->pcData = new aiTexel[(bytes.size() + sizeof(aiTexel) - 1) / sizeof(aiTexel)];
      std::memcpy(t->pcData, bytes.data(), bytes.size());
      texture_bytes += bytes.size();
      texture = int(textures.size());
      textures.push_back(t);
      texture_of_file[key] = texture;
    } else if (!bytes.empty()) {  // over the budget
      ++model.textures_left_out;
      texture_of_file[key] = -1;
    }
    materials.push_back(MakeMaterial(material, texture));
  }
  model.textures = textures.size();
  scene->mNumTextures = unsigned(textures.size());
  if (!textures.empty()) {
    scene->mTextures = new aiTexture*[textures.size()];
    std::copy(textures.begin(), textures.end(), scene->mTextures);
  }
  const int default_material = int(materials.size());
  scene::Material fallback;
  fallback.name = "default";
  materials.push_back(MakeMaterial(fallback));
  scene->mNumMaterials = unsigned(materials.size());
  scene->mMaterials = new aiMaterial*[materials.size()];
  std::copy(materials.begin(), materials.end(), scene->mMaterials);

  std::vector<aiMesh*> meshes;
  std::vector<aiNode*> nodes;
  for (const scene::Actor& actor : level.actors) {
    std::vector<unsigned> node_meshes;
    // A static actor's vertices in the world frame; a movable one's in its
    // own, under a node at its pose (which the stream's placements replace).
    const Eigen::Affine3f X_WA =
        actor.movable ? Eigen::Affine3f::Identity() : Eigen::Affine3f(actor.X_WA.cast<float>());
    const Eigen::Matrix3f R_WA = X_WA.linear();
    for (const scene::Mesh& source : actor.meshes) {
      const std::vector<std::uint32_t> indices = Simplified(source, ratio);
      if (indices.empty()) continue;
      auto* mesh = new aiMesh;
      meshes.push_back(mesh);  // owned by the scene from here
      mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
      mesh->mMaterialIndex =
          unsigned(source.material >= 0 && source.material < default_material ? source.material
                                                                              : default_material);
      mesh->mNumVertices = unsigned(source.positions_A.size());
      mesh->mVertices = new aiVector3D[mesh->mNumVertices];
      const bool normals = source.normals_A.size() == source.positions_A.size();
      if (normals) mesh->mNormals = new aiVector3D[mesh->mNumVertices];
      const bool uvs = source.uvs.size() == source.positions_A.size();
      if (uvs) {
        mesh->mTextureCoords[0] = new aiVector3D[mesh->mNumVertices];
        mesh->mNumUVComponents[0] = 2;
      }
      for (std::size_t v = 0; v < source.positions_A.size(); ++v) {
        if (uvs) mesh->mTextureCoords[0][v] = aiVector3D(source.uvs[v].x(), source.uvs[v].y(), 0.0f);
        const Eigen::Vector3f p = X_WA * source.positions_A[v];
        mesh->mVertices[v] = aiVector3D(p.x(), p.y(), p.z());
        if (normals) {
          const Eigen::Vector3f n = R_WA * source.normals_A[v];
          mesh->mNormals[v] = aiVector3D(n.x(), n.y(), n.z());
        }
      }
      mesh->mNumFaces = unsigned(indices.size() / 3);
      mesh->mFaces = new aiFace[mesh->mNumFaces];
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        aiFace& face = mesh->mFaces[f];
        face.mNumIndices = 3;
        face.mIndices = new unsigned[3]{indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]};
      }
      model.triangles += mesh->mNumFaces;
      node_meshes.push_back(unsigned(meshes.size() - 1));
    }
    if (node_meshes.empty()) continue;
    auto* node = new aiNode(actor.name);
    if (actor.movable) node->mTransformation = ToAssimp(Eigen::Affine3d(actor.X_WA.matrix()));
    node->mNumMeshes = unsigned(node_meshes.size());
    node->mMeshes = new unsigned[node_meshes.size()];
    std::copy(node_meshes.begin(), node_meshes.end(), node->mMeshes);
    nodes.push_back(node);
  }
  // Each robot: a node (the page places it at the robot's pose) with its
  // joints' nodes under it, flat, at rest (the page sets them from each
  // state), and its meshes skinned to them.
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    const scene::RobotModel& robot = level.robots[r];
    const std::string name = RobotNodeName(int(r));
    const scene::RobotState rest(robot);
    std::vector<aiNode*> children;
    for (std::size_t k = 0; k < robot.joints.size(); ++k) {
      auto* joint = new aiNode(name + "_joint" + std::to_string(k));
      joint->mTransformation =
          ToAssimp(rest.node_poses_B()[std::size_t(robot.joints[k].node)]);
      children.push_back(joint);
    }
    for (std::size_t m = 0; m < robot.meshes.size(); ++m) {
      const scene::SkinnedMesh& source = robot.meshes[m];
      if (source.bind.indices.empty()) continue;
      const int material = source.bind.material;
      meshes.push_back(MakeRobotMesh(
          source, name + "_joint", robot,
          unsigned(material >= 0 && material < default_material ? material : default_material)));
      model.robot_triangles += meshes.back()->mNumFaces;
      model.triangles += meshes.back()->mNumFaces;
      auto* node = new aiNode(name + "_mesh" + std::to_string(m));
      node->mNumMeshes = 1;
      node->mMeshes = new unsigned[1]{unsigned(meshes.size() - 1)};
      children.push_back(node);
    }
    nodes.push_back(MakeParentOf(name, children));
  }
  scene->mNumMeshes = unsigned(meshes.size());
  scene->mMeshes = new aiMesh*[std::max<std::size_t>(1, meshes.size())];
  std::copy(meshes.begin(), meshes.end(), scene->mMeshes);
  scene->mRootNode = MakeParentOf("level", nodes);

  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), "glb2");
  if (blob == nullptr) {
    throw std::runtime_error("the browser's level model: assimp's glTF exporter failed: " +
                             std::string(exporter.GetErrorString()));
  }
  model.glb.assign(static_cast<const char*>(blob->data), blob->size);
  return model;
}

}  // namespace sandbox::web
