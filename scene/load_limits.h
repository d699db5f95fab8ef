#pragma once
// What loading one level may take. A level over a limit fails to load with an
// error naming the file, what it would take and the limit's key; a manifest's
// [level] table may set each (docs/reference/levels.md). They guard against files that
// claim sizes they do not have (a 389 KB PNG of 20000 x 20000 pixels, a GLB
// whose header lies) as much as against files too big for the machine.

#include <cstdint>
#include <filesystem>
#include <string>

namespace sandbox::scene {

struct LoadLimits {
  std::uint64_t max_file_mb{2048};                // any one file the level reads
  std::uint64_t max_heightmap_samples{1u << 24};  // one heightmap's points (4096 x 4096)
  std::uint64_t max_texture_pixels{1u << 26};     // one texture, decoded (8192 x 8192)
  std::uint64_t max_triangles{50'000'000};        // the whole level, robots included
  // An isolated import (sandbox --isolate): its address space and CPU time.
  std::uint64_t max_import_mb{8192};
  std::uint64_t max_import_s{600};
  // A [[terrain]]'s work, checked when the level loads (estimated from the
  // rasters and the tile settings) and again for each tile as it is built.
  std::uint64_t max_terrain_tiles{2000};          // tiles near one robot at once, fine and coarse
  std::uint64_t max_terrain_mb{1280};             // their memory, with their collision shapes
  std::uint64_t max_tile_samples{1025 * 1025};    // one tile's raster samples (tile_samples 1024)
  std::uint64_t max_imagery_window_px{1u << 26};  // imagery pixels read for one tile's texture

  // Throws LevelError "FILE: WHAT, over the limit of LIMIT ([level] KEY)"
  // when `amount` is above `limit`.
  static void Check(const std::filesystem::path& file, const std::string& what,
                    std::uint64_t amount, std::uint64_t limit, const char* key);
  // The file's size against max_file_mb.
  void CheckFileSize(const std::filesystem::path& file) const;
};

}  // namespace sandbox::scene
