#pragma once
// Terrains given as height grids: Terragen .ter files and heightmap images
// (8- or 16-bit PNG, binary PGM) placed by a level manifest.

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "scene/imported_asset.h"
#include "scene/load_limits.h"
#include "scene/mesh.h"
#include "scene/placement.h"

namespace sandbox::scene {

// A regular grid of heights: height_m[row * cols + col] at
// x = origin.x + col * spacing.x, y = origin.y - row * spacing.y (row 0 is the
// north edge, as in an image).
struct HeightGrid {
  int cols{0};
  int rows{0};
  Eigen::Vector2d spacing_m{1.0, 1.0};
  Eigen::Vector2d origin_m{0.0, 0.0};
  std::vector<float> height_m;
};

// Two triangles per cell, counter-clockwise seen from above, normals from
// central differences. Throws LevelError when the grid has fewer than 2 x 2 points.
Mesh MeshFromHeightGrid(const HeightGrid& grid);

// A Terragen terrain: its own SCAL spacing and ALTW heights, corner at the
// origin. `conversion.unit_scale_m` scales the whole terrain. Grids over
// limits.max_heightmap_samples are refused before anything is allocated.
ImportedAsset ImportTerragen(const std::filesystem::path& file, const AssetConversion& conversion,
                             const LoadLimits& limits = {});

// A heightmap image centred on the origin: `size_m` = (x extent, y extent,
// height of the brightest value). The first channel is the height. The size
// the image header states is checked against limits.max_heightmap_samples
// before the image is decoded.
ImportedAsset ImportHeightmapImage(const std::filesystem::path& file, const Eigen::Vector3d& size_m,
                                   const LoadLimits& limits = {});

}  // namespace sandbox::scene
