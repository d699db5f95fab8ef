#pragma once
// The level's actors as the renderer draws them: what stays merged into
// chunks (one per material, surface, 128 m ground cell and kind of hidden
// back faces, with its bounds for culling), the movable actors' meshes each
// on its own, and the rules of which meshes are drawn whole or see-through.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "scene/level.h"
#include "scene/surface_ids.h"
#include "sensors/render/gpu_mesh.h"
#include "sensors/render/hidden_faces.h"

namespace sandbox::render {

// Whether meshes of this material and surface (none: the material's) are
// drawn opaque and whole (not water, not cut out, not see-through): their
// back faces hide behind their front faces.
bool DrawnWhole(const scene::Level& level, int material, std::optional<scene::Surface> surface);
// Whether they are drawn after the opaque ones, blended (water, alpha below 1).
bool IsTranslucent(const scene::Level& level, int material, std::optional<scene::Surface> surface);

// Static geometry, merged. Positions are relative to the level's centre
// (double) so that floats keep their precision in large levels.
struct StaticChunk {
  int material{-1};
  std::optional<scene::Surface> surface;
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs, lightmap_uvs;  // empty when no mesh in it had them
  std::vector<Eigen::Vector4f> colors;             // empty when no mesh in it had them
  std::vector<std::uint32_t> segments, indices;
  Eigen::AlignedBox3f bounds;
  HiddenBackFaces hidden;  // of the meshes it holds pieces of (one kind)
};
constexpr double kChunkCell_m = 128.0;

// The origin of the chunks' frame: the level's centre.
Eigen::Vector3d ChunkOrigin(const scene::Level& level);

// The static actors' meshes in the frame at `origin`, grouped by material,
// surface, ground cell and which back faces may go; no GL.
std::vector<StaticChunk> MergeStaticActors(const scene::Level& level, const Eigen::Vector3d& origin,
                                           const scene::SurfaceIds& legend);

// Chunks with their levels of detail, uploaded, with their bounds.
std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> UploadChunks(
    const std::vector<StaticChunk>& chunks);

// The movable actors' meshes with their levels of detail (by actor index),
// and each actor's bounds in its own frame.
struct MovableMeshes {
  std::vector<std::pair<int, GpuMesh>> meshes;
  std::map<int, Eigen::AlignedBox3d> bounds_A;
};
MovableMeshes UploadMovableActors(const scene::Level& level, const scene::SurfaceIds& legend);

}  // namespace sandbox::render
