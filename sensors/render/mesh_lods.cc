#include "sensors/render/mesh_lods.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <map>

namespace sandbox::render {

const MeshLods::Level& LevelFor(const std::vector<MeshLods::Level>& levels, float error_m) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < levels.size() && levels[k].error_m <= error_m; ++k) best = k;
  return levels[best];
}

std::size_t NextLevel(const std::vector<MeshLods::Level>& levels, std::size_t current,
                      float error_m) {
  auto index = [&](float e) { return std::size_t(&LevelFor(levels, e) - levels.data()); };
  const std::size_t k = index(error_m);
  return k > current ? std::max(index(error_m / 1.5f), current) : k;
}

float PixelError(float lod_px, float pixel_angle_rad, const Eigen::AlignedBox3f& box_C) {
  if (lod_px <= 0.f || box_C.isEmpty()) return 0.f;
  return lod_px * pixel_angle_rad * box_C.exteriorDistance(Eigen::Vector3f::Zero());
}

float UnderShadowTexel(float error_m, const std::vector<ShadowCascade>& cascades,
                       const Eigen::Vector3f& view_axis, const Eigen::AlignedBox3f& box_C) {
  if (cascades.empty()) return error_m;
  const float depth =
      view_axis.dot(box_C.center()) - 0.5f * box_C.sizes().dot(view_axis.cwiseAbs());
  std::size_t c = 0;
  while (c + 1 < cascades.size() && depth > cascades[c].far_m) ++c;
  if (depth <= cascades.back().far_m) return std::min(error_m, float(cascades[c].texel_m) / 5.f);
  return error_m;
}

std::vector<std::uint32_t> WeldIdentical(const std::vector<std::uint32_t>& indices,
                                         std::size_t vertex_count,
                                         const std::vector<VertexStream>& streams) {
  std::vector<meshopt_Stream> meshopt_streams;
  for (const VertexStream& stream : streams) {
    if (stream.data != nullptr)
      meshopt_streams.push_back({stream.data, stream.bytes, stream.bytes});
  }
  std::vector<std::uint32_t> welded(indices.size());
  if (indices.empty() || meshopt_streams.empty()) return indices;
  meshopt_generateShadowIndexBufferMulti(welded.data(), indices.data(), indices.size(),
                                         vertex_count, meshopt_streams.data(),
                                         meshopt_streams.size());
  return welded;
}

MeshLods MakeMeshLods(const std::vector<Eigen::Vector3f>& positions,
                      const std::vector<std::uint32_t>& indices,
                      const std::vector<std::uint32_t>* vertex_group) {
  MeshLods lods;
  lods.indices = indices;
  lods.levels.push_back({0, std::uint32_t(indices.size()), 0.f});
  if (positions.empty() || indices.size() < 3 * 64) return lods;
  const float scale =
      meshopt_simplifyScale(positions[0].data(), positions.size(), sizeof(Eigen::Vector3f));
  if (!(scale > 0.f)) return lods;
  // The triangles by group (one group without `vertex_group`), each over the
  // vertices it uses alone (the simplifier takes vertices it is given at one
  // place but not used together as a seam); the triangles across groups apart.
  struct Group {
    std::vector<std::uint32_t> vertices;  // local to the mesh's
    std::vector<Eigen::Vector3f> positions;
    std::vector<std::uint32_t> triangles;  // local
    std::map<std::uint32_t, std::uint32_t> local;
  };
  std::map<std::uint32_t, Group> groups;
  std::vector<std::uint32_t> across;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const std::uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    const std::uint32_t g = vertex_group != nullptr ? (*vertex_group)[a] : 0;
    if (vertex_group != nullptr && ((*vertex_group)[b] != g || (*vertex_group)[c] != g)) {
      across.insert(across.end(), {a, b, c});
      continue;
    }
    Group& group = groups[g];
    for (const std::uint32_t v : {a, b, c}) {
      const auto [at, added] = group.local.emplace(v, std::uint32_t(group.vertices.size()));
      if (added) {
        group.vertices.push_back(v);
        group.positions.push_back(positions[v]);
      }
      group.triangles.push_back(at->second);
    }
  }
  // Each level simplifies the one before (fast: each is smaller); its error is
  // the sum of the steps' (the distance to the mesh's own surface is no more),
  // each twice what the simplifier estimates (its quadric measure came to 0.5-1
  // of the true distance on a wavy surface: MeshLodsTest).
  std::vector<std::uint32_t> level, part;
  float error_before_m = 0.f;
  for (float step_m = 0.01f; step_m < std::min(10.f, 0.1f * scale); step_m *= 3.f) {
    level = across;
    float reached_m = 0.f;
    for (auto& [id, group] : groups) {
      part.resize(group.triangles.size());
      float relative = 0.f;
      part.resize(meshopt_simplify(part.data(), group.triangles.data(), group.triangles.size(),
                                   group.positions[0].data(), group.positions.size(),
                                   sizeof(Eigen::Vector3f), 0, step_m / scale,
                                   meshopt_SimplifyLockBorder, &relative));
      group.triangles.swap(part);
      for (const std::uint32_t v : group.triangles) level.push_back(group.vertices[v]);
      reached_m = std::max(reached_m, 2.f * relative * scale);
    }
    error_before_m += reached_m;
    if (4 * level.size() > 3 * std::size_t(lods.levels.back().count)) continue;
    lods.levels.push_back({std::uint32_t(lods.indices.size()), std::uint32_t(level.size()),
                           std::max(error_before_m, 1e-6f)});
    lods.indices.insert(lods.indices.end(), level.begin(), level.end());
  }
  return lods;
}

}  // namespace sandbox::render
