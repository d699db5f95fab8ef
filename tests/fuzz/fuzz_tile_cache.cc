// Fuzz target: bytes as a tile-cache file (scene/terrain_cache.h), decoded for
// a fine and a coarse tile; a tile that is accepted is made into the collision
// shape the streamer would insert.

#include <cstdint>
#include <memory>
#include <string>

#include "scene/collision_world.h"
#include "scene/terrain_cache.h"

using namespace sandbox::scene;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  TerrainSpec spec;  // the seeds' settings (make_fuzz_seeds)
  spec.tile_samples = 16, spec.coarse_factor = 4, spec.texture_px = 8;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const int lod : {0, 1}) {
    TerrainCache::Loaded loaded = TerrainCache::Decode(bytes, TileId{lod, 0, 0, 0}, spec);
    if (!loaded.tile) continue;
    if (lod == 0 && !loaded.tile->indices.empty()) {
      const auto tile = std::make_shared<TerrainTile>(std::move(*loaded.tile));
      CollisionWorld::PrepareTile(tile);
    }
  }
  return 0;
}
