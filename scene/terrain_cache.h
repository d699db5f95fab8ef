#pragma once
// Built terrain tiles kept on disk ([[terrain]] cache = "DIR"), so that a run
// over the same rasters reads each tile back instead of reading, reprojecting
// and meshing it again. A tile file is named after everything it was built
// from (the rasters' paths, sizes and times, the anchor, the tile settings,
// the tile): a changed raster or setting misses the cache, never reads a
// stale tile. Files are written whole (to a temporary name, then renamed).
//
// Threads: one (the streamer's worker).

#include <filesystem>
#include <optional>
#include <string>

#include "scene/terrain_tile.h"

namespace sandbox::scene {

class TerrainCache {
 public:
  // `spec.cache` empty: no cache. A folder that cannot be made or written is
  // said once by problem() and not used.
  explicit TerrainCache(const TerrainSpec& spec);

  bool enabled() const { return !dir_.empty() && problem_.empty(); }
  const std::string& problem() const { return problem_; }

  // The tile when the cache holds it whole, else nullopt.
  std::optional<TerrainTile> Load(const TileId& id) const;
  // Keeps `tile`; on failure the cache is switched off and problem() says why.
  void Store(const TerrainTile& tile);

 private:
  std::filesystem::path FileOf(const TileId& id) const;

  std::filesystem::path dir_;
  std::string fingerprint_;  // what every tile of this spec was built from
  std::string problem_;
};

}  // namespace sandbox::scene
