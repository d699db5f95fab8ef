#include "sensors/render/terrain_meshes.h"

#include <algorithm>

#include "sensors/render/projection.h"
#include "sensors/render/renderer.h"

namespace sandbox::render {

PlainMesh HorizonGrid(const scene::Horizon& h, const Eigen::Vector3d& origin) {
  constexpr double kExtent_m = 1.0e6;
  auto axis = [&](double lo, double hi) {
    std::vector<double> out;
    for (double d = 500.0 * (1.5 - 1.0), k = 1.5; lo - d > -kExtent_m;
         k *= 1.5, d = 500.0 * (k - 1.0)) {
      out.insert(out.begin(), lo - d);
    }
    out.insert(out.begin(), -kExtent_m);
    for (int i = 0; i <= 8; ++i) out.push_back(lo + (hi - lo) * i / 8.0);
    for (double d = 500.0 * (1.5 - 1.0), k = 1.5; hi + d < kExtent_m;
         k *= 1.5, d = 500.0 * (k - 1.0)) {
      out.push_back(hi + d);
    }
    out.push_back(kExtent_m);
    return out;
  };
  const std::vector<double> xs = axis(h.hole_W.min().x(), h.hole_W.max().x());
  const std::vector<double> ys = axis(h.hole_W.min().y(), h.hole_W.max().y());
  PlainMesh grid;
  for (const double y : ys) {
    for (const double x : xs) {
      const double drop = (x * x + y * y) / (2.0 * scene::kEarthRadius_m);
      grid.positions.push_back((Eigen::Vector3d(x, y, h.height_m - drop) - origin).cast<float>());
      grid.normals.push_back(
          Eigen::Vector3d(-x / scene::kEarthRadius_m, -y / scene::kEarthRadius_m, 1.0)
              .normalized()
              .cast<float>());
    }
  }
  const std::uint32_t nx = std::uint32_t(xs.size());
  for (std::uint32_t j = 0; j + 1 < ys.size(); ++j) {
    for (std::uint32_t i = 0; i + 1 < nx; ++i) {
      const Eigen::Vector2d centre(0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]));
      if (h.hole_W.contains(centre)) continue;
      const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      for (const std::uint32_t v : {a, b, d, a, d, c}) grid.indices.push_back(v);
    }
  }
  return grid;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> TileRanges(const scene::TerrainTile& tile,
                                                                const std::set<std::uint64_t>& fine,
                                                                int coarse_factor) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
  if (tile.id.lod == 0) {
    ranges.push_back({0, std::uint32_t(tile.indices.size())});
  } else {
    for (int k = 0; k + 1 < int(tile.block_first.size()); ++k) {
      const scene::TileId under{0, tile.id.file, tile.id.tx * coarse_factor + k % coarse_factor,
                                tile.id.ty * coarse_factor + k / coarse_factor};
      if (fine.count(under.key())) continue;
      const std::uint32_t a = tile.block_first[std::size_t(k)],
                          b = tile.block_first[std::size_t(k) + 1];
      if (!ranges.empty() && ranges.back().second == a) {
        ranges.back().second = b;
      } else if (b > a) {
        ranges.push_back({a, b});
      }
    }
  }
  ranges.push_back({std::uint32_t(tile.indices.size()),
                    std::uint32_t(tile.indices.size() + tile.skirt_indices.size())});
  return ranges;
}

std::vector<TileDraw> TileDraws(const scene::TileList& tiles, int coarse_factor,
                                const Eigen::Vector3d& camera_W, const Eigen::Matrix4f& view_proj,
                                bool casting_shadows) {
  std::set<std::uint64_t> fine;
  for (const auto& tile : tiles) {
    if (tile->id.lod == 0) fine.insert(tile->id.key());
  }
  std::vector<std::pair<float, const scene::TerrainTile*>> order;
  for (const auto& tile : tiles) {
    if (tile->indices.empty() || tile->bounds_W.isEmpty()) continue;
    if (casting_shadows && tile->id.lod != 0) continue;
    const Eigen::AlignedBox3f box((tile->bounds_W.min() - camera_W).cast<float>(),
                                  (tile->bounds_W.max() - camera_W).cast<float>());
    if (!InFrustum(view_proj, box)) continue;
    order.push_back({box.exteriorDistance(Eigen::Vector3f::Zero()), tile.get()});
  }
  std::sort(order.begin(), order.end());
  std::vector<TileDraw> draws;
  for (const auto& [distance, tile] : order) {
    draws.push_back({tile, TileRanges(*tile, fine, coarse_factor)});
  }
  return draws;
}

void TerrainTiles::Update(const scene::TileList& tiles, std::uint32_t segment) {
  std::map<const scene::TerrainTile*, Gpu> kept;
  for (const auto& tile : tiles) {
    auto found = gpu_.find(tile.get());
    if (found != gpu_.end()) {
      kept[tile.get()] = found->second;
      gpu_.erase(found);
      continue;
    }
    std::vector<std::uint32_t> indices = tile->indices;
    indices.insert(indices.end(), tile->skirt_indices.begin(), tile->skirt_indices.end());
    Gpu& gpu = kept[tile.get()];
    gpu.mesh =
        Upload({&tile->positions, &tile->normals, &tile->uvs, nullptr, nullptr, nullptr, &indices},
               -1, GL_STATIC_DRAW);
    gpu.mesh.surface = scene::Surface::kTerrain;
    gpu.mesh.segment_base = segment;
    if (!tile->texture_rgba.empty()) {
      gpu.texture = UploadTexture({tile->texture_width, tile->texture_height, tile->texture_rgba},
                                  GL_CLAMP_TO_EDGE, true);
    }
  }
  for (auto& [tile, gpu] : gpu_) {
    Free(gpu.mesh);
    if (gpu.texture != 0) glDeleteTextures(1, &gpu.texture);
  }
  gpu_.swap(kept);
}

}  // namespace sandbox::render
