#pragma once
// Built terrain tiles kept on disk ([[terrain]] cache = "DIR"), so that a run
// over the same rasters reads each tile back instead of reading, reprojecting
// and meshing it again. A tile file is named after everything it was built
// from (the rasters' paths, sizes and times, the anchor, the tile settings,
// the tile): a changed raster or setting misses the cache, never reads a
// stale tile. Files are written whole (to a temporary name, then renamed).
// A file is an input like any other: its size is checked against what a tile
// of the spec can hold before it is read, and everything in it (counts,
// indices, finite values, the texture's size against its pixels) before it
// is used; a file that fails is reported and built again.
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

  struct Loaded {
    std::optional<TerrainTile> tile;  // the tile when the cache holds it whole and sound
    std::string damage;               // "FILE: why" when a file is there but cannot be used
  };
  Loaded Load(const TileId& id) const;
  // Why `tile` cannot be a tile of `spec` (a count, an index, a value that
  // is not finite, a texture whose size does not match its pixels), or "".
  static std::string Problem(const TerrainTile& tile, const TerrainSpec& spec);
  // A tile file's bytes, and back: the tile when `bytes` hold tile `id` of
  // `spec` whole and sound, else why not (Loaded::damage, without the file).
  static std::string Encode(const TerrainTile& tile);
  static Loaded Decode(const std::string& bytes, const TileId& id, const TerrainSpec& spec);
  // The most bytes a tile file of `spec` can take.
  static std::uint64_t MaxFileBytes(const TerrainSpec& spec);
  // Keeps `tile`; on failure the cache is switched off and problem() says why.
  void Store(const TerrainTile& tile);

 private:
  std::filesystem::path FileOf(const TileId& id) const;

  TerrainSpec spec_;
  std::filesystem::path dir_;
  std::string fingerprint_;  // what every tile of this spec was built from
  std::string problem_;
};

}  // namespace sandbox::scene
