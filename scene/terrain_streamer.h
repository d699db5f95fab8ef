#pragma once
// Terrain tiles streamed by position (docs/how-to/large-worlds.md). A worker thread
// keeps the tiles near the robots built: fine tiles (collision and cameras)
// within TerrainSpec::collision_radius_m of each robot and of where it will
// be prefetch_s from now, coarse tiles (cameras only) within view_radius_m,
// none beyond; it reads and reprojects the rasters and builds each fine
// tile's Bullet shape. Between ticks the loop swaps in what is finished and
// swaps out what is no longer wanted: a few Bullet insertions, no BVH work.
// Memory stays bounded by the radii, however far the flight goes.
//
// Threads: Update, drawn() and TakeMessages() belong to the loop thread; the
// worker is private.

#include <Eigen/Geometry>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/terrain_tile.h"

namespace sandbox::scene {

using TileList = std::vector<std::shared_ptr<const TerrainTile>>;

class TerrainStreamer {
 public:
  struct Figures {
    std::int64_t built{0}, fine_built{0}, dropped{0}, failed{0};
    std::int64_t from_cache{0};                         // of `built`: read back from the tile cache
    double longest_build_ms{0.0}, total_build_ms{0.0};  // reading or building, and the shape
    double longest_swap_ms{0.0};  // tiles in and out of the collision world, on the loop
    std::int64_t waits{0};        // updates that waited for fine tiles (lock-step)
    double longest_wait_ms{0.0};
    std::int64_t late{0};  // updates whose robots were nearer than the radius
                           // to a fine tile not yet built (real time)
    int resident_tiles{0}, peak_resident_tiles{0};
    std::size_t resident_bytes{0}, peak_resident_bytes{0};
  };

  // Starts the worker on `level`'s terrain (level.terrain must be set).
  // `level` must outlive the streamer.
  explicit TerrainStreamer(const Level& level);
  ~TerrainStreamer();
  TerrainStreamer(const TerrainStreamer&) = delete;
  TerrainStreamer& operator=(const TerrainStreamer&) = delete;

  enum class Wait {
    kNone,  // real time: what is finished goes in, the rest later
    kFine,  // until every fine tile within the collision radius of each robot is in
    kAll,   // until every tile wanted is in: lock-step runs and one-shot commands, whose
            // outputs (scans and frames) then do not depend on the worker's speed
  };
  // Between ticks: tells the worker where the robots are (at time t_s) and
  // swaps finished and unwanted tiles in and out of `world` (null: none).
  // Returns the milliseconds it took.
  double Update(const std::vector<Eigen::Vector3d>& robots_W, double t_s, CollisionWorld* world,
                Wait wait);
  // The tiles cameras draw now (constant; a new list after each change).
  std::shared_ptr<const TileList> drawn() const { return drawn_; }
  // What went wrong since the last call: a raster left out, a tile that
  // could not be read, a robot beyond every raster (each said once).
  std::vector<std::string> TakeMessages();
  Figures figures() const;
  int collision_tiles() const { return collision_tiles_; }

 private:
  struct Shared;
  void Work();

  const Level& level_;
  std::unique_ptr<Shared> shared_;
  std::thread worker_;
  std::vector<Eigen::Vector3d> last_sent_;
  double last_sent_t_{-1e300};
  std::vector<Eigen::Vector3d> velocity_W_;
  std::vector<Eigen::Vector3d> previous_W_;
  double previous_t_{0.0};
  std::uint64_t sent_{0};
  std::map<std::uint64_t, std::shared_ptr<const TerrainTile>> tiles_;  // drawn, by key
  std::shared_ptr<const TileList> drawn_{std::make_shared<TileList>()};
  int collision_tiles_{0};
  double longest_swap_ms_{0.0};
  std::int64_t waits_{0};
  double longest_wait_ms_{0.0};
};

}  // namespace sandbox::scene
