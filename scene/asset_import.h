#pragma once
// Reading one asset file into meshes in the world's axes and units. Used by the
// level loader; scene-internal.

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "scene/imported_asset.h"
#include "scene/load_limits.h"
#include "scene/mesh.h"
#include "scene/placement.h"

namespace sandbox::scene {

// Which library ImportAsset reads `file` with: "assimp", or "the Terragen
// reader" (for the messages of an isolated load, app/isolated_load.h).
std::string_view AssetReader(const std::filesystem::path& file);

// Reads a scene file with assimp (or a Terragen .ter terrain natively).
// Throws LevelError naming the file when it is missing, not a regular file,
// unreadable, over a limit, of an unsupported format or has no triangles.
// assimp's own checks (ai_assert) fail the import rather than the process;
// crashes inside assimp need an isolated import (app/isolated_load.h).
ImportedAsset ImportAsset(const std::filesystem::path& file, const AssetConversion& conversion,
                          const LoadLimits& limits = {});

// Applies an affine map to a mesh: positions, normals (inverse transpose), and
// the triangle winding when the map mirrors.
void TransformMesh(const Eigen::Affine3d& T, Mesh* mesh);

}  // namespace sandbox::scene
