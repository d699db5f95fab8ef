#include "sensors/render/level_meshes.h"

#include <array>
#include <cmath>
#include <tuple>

#include "sensors/render/mesh_lods.h"

namespace sandbox::render {

bool DrawnWhole(const scene::Level& level, int material, std::optional<scene::Surface> surface) {
  if (surface == scene::Surface::kWater) return false;
  if (material < 0 || material >= int(level.materials.size())) return true;
  const scene::Material& m = level.materials[std::size_t(material)];
  return m.surface != scene::Surface::kWater && m.alpha_mode != scene::AlphaMode::kMask &&
         m.base_color.w() >= 0.999f;
}

bool IsTranslucent(const scene::Level& level, int material, std::optional<scene::Surface> surface) {
  if (surface == scene::Surface::kWater) return true;
  if (material < 0 || material >= int(level.materials.size())) return false;
  const scene::Material& m = level.materials[std::size_t(material)];
  return m.surface == scene::Surface::kWater ||
         (m.alpha_mode != scene::AlphaMode::kMask && m.base_color.w() < 0.999f);
}

Eigen::Vector3d ChunkOrigin(const scene::Level& level) {
  return level.bounds_W().isEmpty() ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                    : Eigen::Vector3d(level.bounds_W().center());
}

std::vector<StaticChunk> MergeStaticActors(const scene::Level& level, const Eigen::Vector3d& origin,
                                           const scene::SurfaceIds& legend) {
  // By material, surface, ground cell and which back faces may go
  // (-1: none, 0: those of solids, k + 1: those of height field k).
  using Key = std::tuple<int, std::optional<scene::Surface>, long, long, int>;
  std::map<Key, StaticChunk> chunks;
  // Whether any mesh in a chunk had uvs, lightmap uvs, colours.
  std::map<Key, std::array<bool, 3>> any;
  int height_fields = 0;
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    const scene::Actor& actor = level.actors[a];
    if (actor.movable) continue;
    const std::optional<scene::Surface> surface = actor.surface;
    const Eigen::Matrix3d R = actor.X_WA.linear();
    for (const scene::Mesh& mesh : actor.meshes) {
      // This mesh's vertices already copied into each chunk.
      std::map<Key, std::vector<std::int64_t>> copied;
      // Its vertices in the chunks' frame, once each.
      std::vector<Eigen::Vector3d> p_S(mesh.positions_A.size());
      std::vector<Eigen::Vector3f> positions_S(p_S.size());
      for (std::size_t v = 0; v < p_S.size(); ++v) {
        p_S[v] = actor.X_WA * mesh.positions_A[v].cast<double>() - origin;
        positions_S[v] = p_S[v].cast<float>();
      }
      const HiddenBackFaces hidden = DrawnWhole(level, mesh.material, surface)
                                         ? HiddenBackFaces::Of(positions_S, mesh.indices)
                                         : HiddenBackFaces();
      const int kind = hidden.shape() == HiddenBackFaces::Shape::kSolid         ? 0
                       : hidden.shape() == HiddenBackFaces::Shape::kHeightField ? ++height_fields
                                                                                : -1;
      const bool has_uvs = mesh.uvs.size() == mesh.positions_A.size();
      const bool has_lightmap_uvs = mesh.lightmap_uvs.size() == mesh.positions_A.size();
      const bool has_colors = mesh.colors.size() == mesh.positions_A.size();
      for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Eigen::Vector3d c =
            (p_S[mesh.indices[t]] + p_S[mesh.indices[t + 1]] + p_S[mesh.indices[t + 2]]) / 3.0;
        const Key key{mesh.material, surface, std::lround(std::floor(c.x() / kChunkCell_m)),
                      std::lround(std::floor(c.y() / kChunkCell_m)), kind};
        StaticChunk& chunk = chunks[key];
        std::vector<std::int64_t>& map = copied[key];
        if (map.empty()) {
          map.assign(mesh.positions_A.size(), -1);
          // (A chunk of solids culls while the eye is outside all of their boxes.)
          chunk.hidden =
              chunk.indices.empty() ? hidden : HiddenBackFaces::Union(chunk.hidden, hidden);
        }
        std::array<bool, 3>& has = any[key];
        has[0] = has[0] || has_uvs;
        has[1] = has[1] || has_lightmap_uvs;
        has[2] = has[2] || has_colors;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t v = mesh.indices[t + std::size_t(k)];
          if (map[v] < 0) {
            map[v] = std::int64_t(chunk.positions.size());
            chunk.positions.push_back(positions_S[v]);
            chunk.normals.push_back((R * mesh.normals_A[v].cast<double>()).cast<float>());
            chunk.uvs.push_back(has_uvs ? mesh.uvs[v] : Eigen::Vector2f::Zero());
            chunk.lightmap_uvs.push_back(has_lightmap_uvs ? mesh.lightmap_uvs[v]
                                                          : Eigen::Vector2f::Zero());
            chunk.colors.push_back(has_colors ? mesh.colors[v] : Eigen::Vector4f::Ones());
            chunk.segments.push_back(legend.actor(int(a)));
            chunk.bounds.extend(chunk.positions.back());
          }
          chunk.indices.push_back(std::uint32_t(map[v]));
        }
      }
    }
  }
  std::vector<StaticChunk> merged;
  for (auto& [key, chunk] : chunks) {
    const std::array<bool, 3>& has = any[key];
    if (!has[0]) chunk.uvs.clear();
    if (!has[1]) chunk.lightmap_uvs.clear();
    if (!has[2]) chunk.colors.clear();
    chunk.material = std::get<0>(key);
    chunk.surface = std::get<1>(key);
    merged.push_back(std::move(chunk));
  }
  return merged;
}

std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> UploadChunks(
    const std::vector<StaticChunk>& chunks) {
  std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> uploaded;
  for (const StaticChunk& chunk : chunks) {
    const MeshLods lods =
        MakeMeshLods(chunk.positions,
                     WeldedIndices(chunk.positions, chunk.normals, chunk.uvs, chunk.lightmap_uvs,
                                   chunk.colors, &chunk.segments, chunk.indices));
    GpuMesh gpu = Upload({&chunk.positions, &chunk.normals, &chunk.uvs, &chunk.lightmap_uvs,
                          &chunk.colors, &chunk.segments, nullptr, &lods},
                         chunk.material, GL_STATIC_DRAW);
    gpu.surface = chunk.surface;
    gpu.hidden = chunk.hidden;
    uploaded.push_back({chunk.bounds, gpu});
  }
  return uploaded;
}

MovableMeshes UploadMovableActors(const scene::Level& level, const scene::SurfaceIds& legend) {
  MovableMeshes out;
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    if (!level.actors[a].movable) continue;  // merged into chunks
    Eigen::AlignedBox3d& bounds_A = out.bounds_A[int(a)];
    for (const scene::Mesh& mesh : level.actors[a].meshes) {
      for (const Eigen::Vector3f& p : mesh.positions_A) bounds_A.extend(p.cast<double>());
      const MeshLods lods = MakeMeshLods(
          mesh.positions_A, WeldedIndices(mesh.positions_A, mesh.normals_A, mesh.uvs,
                                          mesh.lightmap_uvs, mesh.colors, nullptr, mesh.indices));
      GpuMesh gpu = Upload({&mesh.positions_A, &mesh.normals_A, &mesh.uvs, &mesh.lightmap_uvs,
                            &mesh.colors, nullptr, nullptr, &lods},
                           mesh.material, GL_STATIC_DRAW);
      gpu.surface = level.actors[a].surface;
      gpu.segment_base = legend.actor(int(a));
      gpu.moving = true;
      if (DrawnWhole(level, mesh.material, gpu.surface)) {
        gpu.hidden = HiddenBackFaces::Of(mesh.positions_A, mesh.indices);
      }
      out.meshes.push_back({int(a), gpu});
    }
  }
  return out;
}

}  // namespace sandbox::render
