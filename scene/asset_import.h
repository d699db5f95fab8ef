#pragma once
// Reading one asset file into meshes in the world's axes and units. Used by the
// level loader; scene-internal.

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/level.h"

namespace sandbox::scene {

// A node of an asset that carries meshes. Its meshes are in the node's own
// frame N, in file units; X_RN takes them to the asset root frame R, which has
// world axes (Z up) and metres (the up-axis and unit conversion are in X_RN).
struct ImportedNode {
  std::string path;  // unique within the asset: "body/wing", unnamed nodes "node3"
  Eigen::Affine3d X_RN{Eigen::Affine3d::Identity()};
  std::vector<Mesh> meshes;  // Mesh::material indexes ImportedAsset::materials
};

struct ImportedAsset {
  std::vector<ImportedNode> nodes;
  std::vector<Material> materials;
  std::vector<EmbeddedTexture> textures;
  std::vector<std::string> warnings;
  UpAxis up{UpAxis::kPosZ};
  double unit_scale_m{1.0};
};

// Reads a scene file with assimp (or a Terragen .ter terrain natively).
// Throws LevelError naming the file when it is missing, not a regular file,
// unreadable, over a limit, of an unsupported format or has no triangles.
// assimp's own checks (ai_assert) fail the import rather than the process;
// crashes inside assimp need an isolated import (app/isolated_load.h).
ImportedAsset ImportAsset(const std::filesystem::path& file, const AssetConversion& conversion,
                          const LoadLimits& limits = {});

// Appends materials and textures to the level, renumbering the materials'
// texture references; returns the index the first material got.
int AppendMaterials(std::vector<Material> materials, std::vector<EmbeddedTexture> textures,
                    Level* level);

// The file's extension in lower case, with its dot: ".glb".
std::string LowerExtension(const std::filesystem::path& file);

// Applies an affine map to a mesh: positions, normals (inverse transpose), and
// the triangle winding when the map mirrors.
void TransformMesh(const Eigen::Affine3d& T, Mesh* mesh);

}  // namespace sandbox::scene
