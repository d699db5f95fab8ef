#pragma once
// Meshes and textures on the GPU: vertex buffers with the scene programs'
// attribute locations (0 position, 1 normal, 2 uv, 3 lightmap uv, 4 colour,
// 5 segment id), index buffers with their levels of detail, a per-triangle
// segment table, RGBA8 textures with mipmaps. In the current context; freed
// by Free or with the context.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "scene/mesh.h"
#include "sensors/render/gl.h"
#include "sensors/render/hidden_faces.h"
#include "sensors/render/mesh_lods.h"
#include "sensors/render/view.h"

namespace sandbox::render {

struct RgbaImage;

// A mesh on the GPU, with what it is drawn as.
struct GpuMesh {
  GLuint vao{0}, positions{0}, normals{0}, uvs{0}, lightmap_uvs{0}, colors{0}, segments{0},
      indices{0};
  GLsizei index_count{0};             // of the mesh as given (level 0)
  std::vector<MeshLods::Level> lods;  // its levels of detail in `indices`; empty: level 0 only
  // What moves (robots, movable actors) takes one level a frame for every
  // pass, shadows too (its own shadow then falls on the surface drawn);
  // what stays, its last level in colour.
  bool moving{false};
  mutable std::size_t level{0};
  HiddenBackFaces hidden;  // where its back faces cannot be seen, in its own frame
  int material{-1};
  std::optional<scene::Surface> surface;  // over the material's; none: the material's
  std::uint32_t segment_base{0};
  GLuint triangle_segments{0}, triangle_segment_buffer{0};  // a buffer texture, 0: none
};

// What a mesh is made of, for Upload. An attribute with another count than
// `positions` is left out (a constant: uv 0, colour white, segment 0).
struct MeshData {
  const std::vector<Eigen::Vector3f>* positions{nullptr};
  const std::vector<Eigen::Vector3f>* normals{nullptr};
  const std::vector<Eigen::Vector2f>* uvs{nullptr};
  const std::vector<Eigen::Vector2f>* lightmap_uvs{nullptr};
  const std::vector<Eigen::Vector4f>* colors{nullptr};
  const std::vector<std::uint32_t>* vertex_segments{nullptr};
  const std::vector<std::uint32_t>* indices{nullptr};
  const MeshLods* lods{nullptr};  // instead of `indices`: the levels of detail
};

// `usage`: GL_STATIC_DRAW, or GL_DYNAMIC_DRAW for positions and normals
// rewritten each frame (robots).
GpuMesh Upload(const MeshData& data, int material, GLenum usage);
void Free(const GpuMesh& mesh);

// A per-triangle id table for gl_PrimitiveID lookups (none when `ids` is empty).
void SetTriangleSegments(GpuMesh* mesh, const std::vector<std::uint32_t>& ids);

// `indices` with vertices equal in every attribute (and `ids`) joined, for
// the simplifier (an attribute not given per vertex does not count).
std::vector<std::uint32_t> WeldedIndices(const std::vector<Eigen::Vector3f>& positions,
                                         const std::vector<Eigen::Vector3f>& normals,
                                         const std::vector<Eigen::Vector2f>& uvs,
                                         const std::vector<Eigen::Vector2f>& lightmap_uvs,
                                         const std::vector<Eigen::Vector4f>& colors,
                                         const std::vector<std::uint32_t>* ids,
                                         const std::vector<std::uint32_t>& indices);

// An RGBA8 texture (sRGB: colours; else data) with mipmaps, rows as given.
GLuint UploadTexture(const RgbaImage& image, GLint wrap, bool srgb);

}  // namespace sandbox::render
