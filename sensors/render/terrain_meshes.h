#pragma once
// The ground beyond the level's own meshes: streamed terrain tiles (on the
// GPU while the streamer lists them; which of their index ranges a frame
// draws) and the horizon (a grid around the level out to 1000 km, falling
// away with the Earth's curvature).

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "scene/level.h"
#include "scene/terrain_streamer.h"
#include "sensors/render/gpu_mesh.h"

namespace sandbox::render {

// A mesh without GL.
struct PlainMesh {
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<std::uint32_t> indices;
};

// The horizon's grid in the frame at `origin` (double): cells growing by half
// again each step away from the hole, out to 1000 km; none over the hole.
PlainMesh HorizonGrid(const scene::Horizon& horizon, const Eigen::Vector3d& origin);

// Index ranges [first, end) of `tile` to draw: the surface (a coarse tile
// without the blocks that the fine tiles in `fine` cover; `coarse_factor`
// fine tiles a coarse tile's side), then the skirts.
std::vector<std::pair<std::uint32_t, std::uint32_t>> TileRanges(const scene::TerrainTile& tile,
                                                                const std::set<std::uint64_t>& fine,
                                                                int coarse_factor);

// A tile to draw: its index ranges (TileRanges).
struct TileDraw {
  const scene::TerrainTile* tile;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
};
// The tiles with triangles in the view of clip matrix `view_proj` (camera-
// centred world at `camera_W`), nearest first; `casting_shadows`: the fine
// ones alone (far tiles cast no shadow).
std::vector<TileDraw> TileDraws(const scene::TileList& tiles, int coarse_factor,
                                const Eigen::Vector3d& camera_W, const Eigen::Matrix4f& view_proj,
                                bool casting_shadows);

// Terrain tiles on the GPU: uploaded when first seen, freed when gone.
class TerrainTiles {
 public:
  struct Gpu {
    GpuMesh mesh;
    GLuint texture{0};  // the imagery, 0: none
  };
  // The tiles drawn from now on; `segment`: their segmentation id.
  void Update(const scene::TileList& tiles, std::uint32_t segment);
  const Gpu& at(const scene::TerrainTile* tile) const { return gpu_.at(tile); }

 private:
  std::map<const scene::TerrainTile*, Gpu> gpu_;
};

}  // namespace sandbox::render
