#pragma once
// Levels of detail of a triangle mesh: coarser triangle lists over the same
// vertices (meshoptimizer's simplifier), each with the largest distance its
// surface keeps from the mesh's own, so that a draw takes the coarsest level
// whose error stays under what a pixel (or a shadow-map texel) resolves there.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sensors/render/shadow_cascades.h"

namespace sandbox::render {

struct MeshLods {
  struct Level {
    std::uint32_t first{0};  // into `indices`
    std::uint32_t count{0};  // indices
    float error_m{0.f};      // in the mesh's units
  };
  std::vector<std::uint32_t> indices;  // the levels' triangles, one after the other
  std::vector<Level> levels;           // level 0: the mesh as given (error 0)
};

// The coarsest of `levels` whose error is at most `error_m` (0: the first).
const MeshLods::Level& LevelFor(const std::vector<MeshLods::Level>& levels, float error_m);

// The level to draw after `current`: the coarsest within `error_m`, but a
// coarser one than `current` only once well within it (the error over 1.5):
// a camera that keeps its distance does not see a mesh flicker between two levels.
std::size_t NextLevel(const std::vector<MeshLods::Level>& levels, std::size_t current,
                      float error_m);

// What `lod_px` pixels of `pixel_angle_rad` span at the nearest point of
// `box_C` (camera-centred); 0 when lod_px is 0 or the box empty.
float PixelError(float lod_px, float pixel_angle_rad, const Eigen::AlignedBox3f& box_C);

// `error_m` capped, within the shadows' reach, at a fifth of the shadow-map
// texel of the cascade the box's nearest depth along `view_axis` falls in:
// the shadow maps hold another level, and the two stay under the shadows'
// bias of 0.4 texel (no acne).
float UnderShadowTexel(float error_m, const std::vector<ShadowCascade>& cascades,
                       const Eigen::Vector3f& view_axis, const Eigen::AlignedBox3f& box_C);

// Levels at errors growing about threefold from 1 cm (to 10 m at most), each
// kept only if it has at most three quarters of the triangles of the level before. The mesh's open
// edges stay where they are (meshes cut into pieces meet without cracks), and so do the edges
// between `groups`: with `vertex_group` (one id per vertex), a triangle is simplified only with
// triangles whose vertices are all in its group, and triangles across groups are kept as they are
// (a skinned mesh: vertices that follow the same bones by the same weights move rigidly together,
// so an error in the bind pose is the error in every pose).
// `indices` with each vertex replaced by the first one equal to it in every
// stream (one element of `bytes` bytes per vertex): files that repeat a vertex
// for each face (OBJ through assimp) become connected meshes the simplifier
// can work on; vertices that differ (a hard edge's normals, a texture seam)
// stay apart.
struct VertexStream {
  const void* data;
  std::size_t bytes;
};
std::vector<std::uint32_t> WeldIdentical(const std::vector<std::uint32_t>& indices,
                                         std::size_t vertex_count,
                                         const std::vector<VertexStream>& streams);

MeshLods MakeMeshLods(const std::vector<Eigen::Vector3f>& positions,
                      const std::vector<std::uint32_t>& indices,
                      const std::vector<std::uint32_t>* vertex_group = nullptr);

}  // namespace sandbox::render
