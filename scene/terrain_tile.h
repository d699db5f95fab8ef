#pragma once
// Terrain from elevation rasters, cut into tiles: what a [[terrain]] table of
// a level manifest asks for (TerrainSpec) and one built tile (TerrainTile).
// Tiles are built off the loop thread (terrain_streamer.h) from the rasters
// (terrain_source.h); a tile is constant once built and shared by the
// collision world and the renderer.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/geodetic.h"
#include "scene/load_limits.h"

namespace sandbox::scene {

// Heights farther than this from the WGS84 ellipsoid (above or below) are
// not the Earth's surface: a raster's undeclared no-data value (-3.4e38, -9999
// is within reach of neither) or a damaged sample. They are taken as no data.
inline constexpr double kMaxHeightAboveEllipsoid_m = 12000.0;

// A terrain's radii reach at most half the way round the Earth; its anchor
// lies at most at the edge of space (the Karman line).
inline constexpr double kMaxTerrainRadius_m = 2.0e7;
inline constexpr double kMaxAnchorHeight_m = 100000.0;

// One [[terrain]] table (docs/how-to/large-worlds.md).
struct TerrainSpec {
  std::string name{"terrain"};                   // the actor rays report as hit
  std::vector<std::filesystem::path> elevation;  // rasters GDAL reads: heights in metres
  std::vector<std::filesystem::path> imagery;    // rasters draped as the texture (RGB)
  GeodeticPoint anchor;                          // the world origin
  int tile_samples{128};                         // raster samples along a fine tile's side
  int coarse_factor{8};                          // a coarse tile spans this many fine tiles a side
  double collision_radius_m{3000.0};             // fine tiles (collision and cameras) within this
  double view_radius_m{60000.0};                 // coarse tiles (cameras only) within this
  double prefetch_s{10.0};                       // also around where each robot will be this soon
  int texture_px{256};                           // a tile's imagery texture, a side
  std::filesystem::path cache;  // built tiles kept here (terrain_cache.h); empty: none
  LoadLimits limits;            // the level's ([level] table): the terrain's budgets
  int line{0};
};

// Where a tile sits in its raster's tile grid.
struct TileId {
  int lod{0};   // 0: fine (collision and cameras), 1: coarse (cameras)
  int file{0};  // index into TerrainSpec::elevation
  int tx{0}, ty{0};
  std::uint64_t key() const {
    return (std::uint64_t(lod) << 62) | (std::uint64_t(file & 0x3fff) << 48) |
           (std::uint64_t(tx & 0xffffff) << 24) | std::uint64_t(ty & 0xffffff);
  }
  bool operator<(const TileId& o) const { return key() < o.key(); }
  bool operator==(const TileId& o) const { return key() == o.key(); }
};

struct TerrainTile {
  TileId id;
  // The tile's own origin in the world: positions are relative to it, so the
  // floats stay small however far the tile is from the world origin.
  Eigen::Vector3d origin_W{Eigen::Vector3d::Zero()};
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs;          // into `texture`; empty without imagery
  std::vector<std::uint32_t> indices;        // the surface (what rays hit)
  std::vector<std::uint32_t> skirt_indices;  // walls down from the edges, for cameras only:
                                             // they hide cracks between details
  // Coarse tiles: their triangles grouped by the fine tile under them;
  // fine tile (tx * f + i, ty * f + j) has indices [block_first[k], block_first[k + 1])
  // with k = j * f + i. The renderer leaves out blocks whose fine tile it draws.
  std::vector<std::uint32_t> block_first;
  int texture_width{0}, texture_height{0};
  std::vector<std::uint8_t> texture_rgba;  // row 0 at v = 0
  Eigen::AlignedBox3d bounds_W;
  double build_ms{0.0};  // reading, reprojecting and meshing (as when it was built)
  // What building it left out (not kept in the tile cache): heights beyond
  // kMaxHeightAboveEllipsoid_m taken as no data, and why the imagery was not
  // draped ("FILE: why"; the tile keeps its ground and base colour).
  std::int64_t heights_out_of_bound{0};
  std::string imagery_problem;

  std::size_t bytes() const;
};

}  // namespace sandbox::scene
