#pragma once
// One asset file as read: its nodes with meshes, materials and textures, in
// the world's axes and units. What the importers give (asset_import.h,
// heightmap.h) and the level loader takes.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "scene/frames.h"
#include "scene/mesh.h"

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

}  // namespace sandbox::scene
