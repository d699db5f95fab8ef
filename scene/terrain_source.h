#pragma once
// The rasters of a [[terrain]] table, read with GDAL: where a world point lies
// in them, which tiles are near it, and the tiles themselves, reprojected to
// the world frame (the tangent plane at the anchor, scene/geodetic.h), each
// relative to its own origin. Heights are taken as metres above the WGS84
// ellipsoid, as the bridge's geodetic poses are.
//
// Threads: a TerrainSource belongs to the thread that made it (GDAL datasets
// are not shared between threads); the streamer's worker has its own.

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scene/terrain_tile.h"

namespace sandbox::scene {

class TerrainSource {
 public:
  // Opens every raster of `spec`. One GDAL cannot read, or without
  // georeferencing, is left out and said in problems() ("FILE: why"); the
  // others still serve. Throws LevelError for settings that cannot work
  // (tile_samples not a multiple of coarse_factor, radii not positive).
  // `on_open` is called with each raster's path before GDAL opens it.
  explicit TerrainSource(const TerrainSpec& spec,
                         const std::function<void(const std::filesystem::path&)>& on_open = {});
  ~TerrainSource();
  TerrainSource(const TerrainSource&) = delete;
  TerrainSource& operator=(const TerrainSource&) = delete;

  const TerrainSpec& spec() const { return spec_; }
  const std::vector<std::string>& problems() const { return problems_; }
  int num_usable() const;  // elevation rasters that serve

  // The tiles of detail `lod` whose footprint comes within `radius_m`
  // (horizontally) of `p_W`, appended to `out`.
  void TilesNear(const Eigen::Vector3d& p_W, int lod, double radius_m,
                 std::vector<TileId>* out) const;
  // Horizontal distance from `p_W` to a tile's footprint (0 inside).
  double DistanceTo(const TileId& id, const Eigen::Vector3d& p_W) const;
  // True when `p_W` lies over some elevation raster.
  bool Covers(const Eigen::Vector3d& p_W) const;
  // The rasters' footprint in the world (x, y), without the outermost tile
  // of samples: the ground beyond it is the horizon's (renderer).
  Eigen::AlignedBox2d InnerFootprint_W() const;
  // The usable rasters' extent in the world: their whole footprint, from
  // each one's least to greatest height (GDAL's approximate statistics) with
  // the Earth's curvature; empty when no raster serves. Reads the rasters.
  Eigen::AlignedBox3d Bounds_W() const;
  // A fine tile's side in metres (about: the raster's sample spacing times tile_samples).
  double fine_tile_m() const;

  // The terrain's work against spec().limits, estimated from the rasters:
  // one tile's samples, the tiles near one robot at once (fine within
  // collision_radius_m, coarse within view_radius_m) and their memory, a
  // fine tile's imagery window. Throws LevelError naming the figure, the
  // limit and its [level] key.
  void CheckBudgets() const;

  // Builds one tile: its surface, its skirts, its imagery. Throws
  // std::runtime_error naming the file when the elevation cannot be read
  // there; imagery that cannot be read leaves the tile in its base colour
  // (TerrainTile::imagery_problem says why).
  TerrainTile Build(const TileId& id) const;

  // The world point of raster sample (col, row) of elevation raster `file`
  // at its height; tests compare it against their own reading of the file.
  Eigen::Vector3d SampleToWorld(int file, int col, int row, double height_m) const;

 private:
  struct Raster;
  std::vector<int> SampleSpan(int first, int last, int step) const;
  // Sample coordinates (col, row; NaN when it cannot be transformed) of a world point.
  Eigen::Vector2d ToSample(const Raster& raster, const Eigen::Vector3d& p_W) const;
  Eigen::Vector3d SampleToWorldOf(const Raster& raster, double col, double row,
                                  double height_m = 0.0) const;

  TerrainSpec spec_;
  LocalTangentPlane plane_;
  std::vector<std::unique_ptr<Raster>> elevation_;  // null where the file is left out
  std::vector<std::unique_ptr<Raster>> imagery_;
  std::vector<std::string> problems_;
};

}  // namespace sandbox::scene
