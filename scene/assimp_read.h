#pragma once
// Scene-internal: reading files with assimp, shared by the level and robot
// loaders. Includes assimp; no header outside scene/*.cc includes this one.

#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/load_limits.h"
#include "scene/mesh.h"
#include "scene/placement.h"

namespace sandbox::scene {

// A scene read by ReadAssimpScene and how to convert it to the world's axes.
struct AssimpScene {
  const aiScene* scene{nullptr};                      // owned by the importer
  Eigen::Affine3d X_RF{Eigen::Affine3d::Identity()};  // root R (Z up, metres) from file F
  UpAxis up{UpAxis::kPosZ};
  double unit_scale_m{1.0};
  std::vector<Material> materials;  // the scene's, in its order
  std::vector<EmbeddedTexture> textures;
  std::vector<std::string> warnings;
};

// Reads `file` without validation, rebuilds Quake 3 faces (assimp 5.2.5
// leaves their indices wrong), drops faces with out-of-range indices or none
// (one warning each), triangulates and adds smooth normals where missing.
// Throws LevelError for an unsupported or unreadable file, a GLB whose
// header does not match the file, or an embedded texture over the limits.
AssimpScene ReadAssimpScene(Assimp::Importer& importer, const std::filesystem::path& file,
                            const AssetConversion& conversion, const LoadLimits& limits);

// The triangles of `mesh`; counts skipped points and lines in `non_triangles`.
Mesh ConvertMesh(const aiMesh& mesh, std::size_t* non_triangles);

Eigen::Matrix4d ToEigen(const aiMatrix4x4& m);

}  // namespace sandbox::scene
