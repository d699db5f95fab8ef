#include "scene/terrain_streamer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#include "scene/terrain_cache.h"
#include "scene/terrain_source.h"

namespace sandbox::scene {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A tile finished (tile set) or dropped (tile null), in the worker's order.
struct Event {
  std::uint64_t key{0};
  std::shared_ptr<const TerrainTile> tile;
  std::shared_ptr<CollisionWorld::PreparedTile> collision;  // fine tiles
};

}  // namespace

struct TerrainStreamer::Shared {
  std::mutex mutex;
  std::condition_variable wake, covered;
  bool stop{false};
  std::uint64_t want{0}, covered_want{0}, covered_all_want{0};
  std::vector<Eigen::Vector3d> now_W, ahead_W;
  std::vector<Event> events;
  std::vector<std::string> messages;
  Figures figures;
};

TerrainStreamer::TerrainStreamer(const Level& level)
    : level_(level), shared_(std::make_unique<Shared>()) {
  if (!level.terrain)
    throw std::invalid_argument("TerrainStreamer::TerrainStreamer(): the level has no terrain");
  worker_ = std::thread([this] { Work(); });
}

TerrainStreamer::~TerrainStreamer() {
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->stop = true;
  }
  shared_->wake.notify_all();
  worker_.join();
}

void TerrainStreamer::Work() {
  Shared& s = *shared_;
  const TerrainSpec& spec = *level_.terrain;
  auto say = [&s](const std::string& message) {
    const std::lock_guard<std::mutex> lock(s.mutex);
    s.messages.push_back(message);
  };
  std::unique_ptr<TerrainSource> source;
  try {
    source = std::make_unique<TerrainSource>(spec);
  } catch (const std::exception& error) {
    say(error.what());
  }
  if (source) {
    for (const std::string& problem : source->problems()) say(problem);
  }
  TerrainCache cache(spec);
  if (!cache.problem().empty()) say(cache.problem());
  const double fine_m = source ? source->fine_tile_m() : 0.0;
  const double coarse_m = fine_m * spec.coarse_factor;
  struct Resident {
    TileId id;
    std::size_t bytes;
  };
  std::map<std::uint64_t, Resident> resident;
  std::set<std::uint64_t> failed;
  std::set<int> heights_said;
  std::set<std::string> imagery_said;
  std::vector<char> off_raster;
  std::uint64_t handled = 0;
  while (true) {
    std::vector<Eigen::Vector3d> now, ahead;
    {
      std::unique_lock<std::mutex> lock(s.mutex);
      s.wake.wait(lock, [&] { return s.stop || s.want != handled; });
      if (s.stop) return;
      handled = s.want;
      now = s.now_W, ahead = s.ahead_W;
    }
    if (!source || source->num_usable() == 0) {
      const std::lock_guard<std::mutex> lock(s.mutex);
      s.covered_want = s.covered_all_want = handled;
      s.covered.notify_all();
      continue;
    }
    // A robot beyond every raster: said once each time it leaves.
    off_raster.resize(now.size(), 0);
    for (std::size_t r = 0; r < now.size(); ++r) {
      const bool off = !source->Covers(now[r]);
      if (off && !off_raster[r]) {
        std::ostringstream message;
        message << "terrain '" << spec.name << "': robot "
                << (r < level_.robots.size() ? level_.robots[r].name : std::to_string(r)) << " at ("
                << std::lround(now[r].x()) << ", " << std::lround(now[r].y())
                << ") m is beyond every elevation raster: no terrain there";
        say(message.str());
      }
      off_raster[r] = off;
    }
    // What is wanted, nearest first.
    auto nearest = [&](const TileId& id) {
      double d = std::numeric_limits<double>::infinity();
      for (const auto& p : now) d = std::min(d, source->DistanceTo(id, p));
      for (const auto& p : ahead) d = std::min(d, source->DistanceTo(id, p));
      return d;
    };
    std::vector<TileId> fine, coarse, near_now;
    for (std::size_t r = 0; r < now.size(); ++r) {
      source->TilesNear(now[r], 0, spec.collision_radius_m, &near_now);
      source->TilesNear(ahead[r], 0, spec.collision_radius_m, &fine);
      source->TilesNear(now[r], 1, spec.view_radius_m, &coarse);
    }
    fine.insert(fine.end(), near_now.begin(), near_now.end());
    for (std::vector<TileId>* list : {&fine, &coarse}) {
      std::sort(list->begin(), list->end());
      list->erase(std::unique(list->begin(), list->end()), list->end());
      std::vector<std::pair<double, TileId>> by_distance;
      for (const TileId& id : *list) by_distance.push_back({nearest(id), id});
      std::sort(by_distance.begin(), by_distance.end(),
                [](const auto& a, const auto& b) { return a.first < b.first; });
      for (std::size_t i = 0; i < by_distance.size(); ++i) (*list)[i] = by_distance[i].second;
    }
    const bool late =
        handled > 1 && std::any_of(near_now.begin(), near_now.end(), [&](const TileId& id) {
          return resident.count(id.key()) == 0 && failed.count(id.key()) == 0;
        });
    // Dropped: beyond the radius by more than a tile (no flicker at the edge).
    std::vector<Event> dropped;
    for (auto it = resident.begin(); it != resident.end();) {
      const double keep =
          it->second.id.lod == 0 ? spec.collision_radius_m + fine_m : spec.view_radius_m + coarse_m;
      if (nearest(it->second.id) > keep) {
        dropped.push_back({it->first, nullptr, nullptr});
        it = resident.erase(it);
      } else {
        ++it;
      }
    }
    {
      const std::lock_guard<std::mutex> lock(s.mutex);
      if (late) ++s.figures.late;
      s.figures.dropped += std::int64_t(dropped.size());
      s.events.insert(s.events.end(), dropped.begin(), dropped.end());
    }
    // Built: fine tiles first (the collision world waits for them), then coarse;
    // a newer want interrupts (it is handled from the top).
    bool interrupted = false;
    for (std::vector<TileId>* list : {&fine, &coarse}) {
      for (const TileId& id : *list) {
        if (resident.count(id.key()) || failed.count(id.key())) continue;
        {
          const std::lock_guard<std::mutex> lock(s.mutex);
          if (s.stop || s.want != handled) {
            interrupted = true;
            break;
          }
        }
        Event event;
        event.key = id.key();
        bool cached = false;
        double ms = 0.0;
        try {
          const auto start = Clock::now();
          TerrainCache::Loaded kept = cache.Load(id);
          if (!kept.damage.empty()) {
            say("terrain '" + spec.name + "': cache file " + kept.damage +
                "; built again from the rasters");
          }
          cached = kept.tile.has_value();
          auto tile =
              std::make_shared<TerrainTile>(cached ? std::move(*kept.tile) : source->Build(id));
          if (!cached && cache.enabled()) {
            cache.Store(*tile);
            if (!cache.enabled()) say(cache.problem());
          }
          // What the build left out: said once per raster.
          if (tile->heights_out_of_bound > 0 && heights_said.insert(id.file).second) {
            say("terrain '" + spec.name + "': " + spec.elevation[std::size_t(id.file)].string() +
                ": " + std::to_string(tile->heights_out_of_bound) +
                " heights in a tile lie beyond " +
                std::to_string(int(kMaxHeightAboveEllipsoid_m / 1000)) +
                " km of the ellipsoid: taken as no data (said once for this raster)");
          }
          if (!tile->imagery_problem.empty() &&
              imagery_said.insert(tile->imagery_problem.substr(0, tile->imagery_problem.find(": ")))
                  .second) {
            say("terrain '" + spec.name + "': " + tile->imagery_problem +
                "; tiles without it keep their ground and base colour (said once for this raster)");
          }
          if (id.lod == 0 && !tile->indices.empty())
            event.collision = CollisionWorld::PrepareTile(tile);
          ms = MsSince(start);
          event.tile = std::move(tile);
        } catch (const std::exception& error) {
          failed.insert(id.key());
          say(std::string("terrain '") + spec.name + "': " + error.what());
          const std::lock_guard<std::mutex> lock(s.mutex);
          ++s.figures.failed;
          continue;
        }
        const std::size_t bytes =
            event.tile->bytes() + (event.collision ? event.tile->indices.size() / 3 * 32 : 0);
        resident[id.key()] = {id, bytes};
        const std::lock_guard<std::mutex> lock(s.mutex);
        Figures& f = s.figures;
        ++f.built;
        if (id.lod == 0) ++f.fine_built;
        if (cached) ++f.from_cache;
        f.total_build_ms += ms;
        f.longest_build_ms = std::max(f.longest_build_ms, ms);
        s.events.push_back(std::move(event));
      }
      if (interrupted) break;
      if (list == &fine) {
        const std::lock_guard<std::mutex> lock(s.mutex);
        s.covered_want = handled;
        s.covered.notify_all();
      }
    }
    const std::lock_guard<std::mutex> lock(s.mutex);
    if (!interrupted) s.covered_all_want = handled;
    s.covered.notify_all();
    Figures& f = s.figures;
    f.resident_tiles = int(resident.size());
    f.resident_bytes = 0;
    for (const auto& [key, tile] : resident) f.resident_bytes += tile.bytes;
    f.peak_resident_tiles = std::max(f.peak_resident_tiles, f.resident_tiles);
    f.peak_resident_bytes = std::max(f.peak_resident_bytes, f.resident_bytes);
  }
}

double TerrainStreamer::Update(const std::vector<Eigen::Vector3d>& robots_W, double t_s,
                               CollisionWorld* world, Wait wait) {
  const auto start = Clock::now();
  Shared& s = *shared_;
  const TerrainSpec& spec = *level_.terrain;
  // Velocities from the last two updates, for the prefetch.
  velocity_W_.resize(robots_W.size(), Eigen::Vector3d::Zero());
  if (previous_W_.size() == robots_W.size() && t_s > previous_t_) {
    for (std::size_t r = 0; r < robots_W.size(); ++r) {
      velocity_W_[r] = (robots_W[r] - previous_W_[r]) / (t_s - previous_t_);
    }
  }
  previous_W_ = robots_W, previous_t_ = t_s;
  // A new want when a robot moved a fraction of the radius, or once a second.
  bool send = last_sent_.size() != robots_W.size() || t_s - last_sent_t_ >= 1.0;
  for (std::size_t r = 0; !send && r < robots_W.size(); ++r) {
    send = (robots_W[r] - last_sent_[r]).head<2>().norm() > 0.05 * spec.collision_radius_m;
  }
  if (send) {
    last_sent_ = robots_W, last_sent_t_ = t_s;
    std::vector<Eigen::Vector3d> ahead(robots_W.size());
    for (std::size_t r = 0; r < robots_W.size(); ++r) {
      ahead[r] = robots_W[r] + spec.prefetch_s * velocity_W_[r];
    }
    {
      const std::lock_guard<std::mutex> lock(s.mutex);
      s.want = ++sent_;
      s.now_W = robots_W, s.ahead_W = std::move(ahead);
    }
    s.wake.notify_all();
  }
  std::vector<Event> events;
  {
    std::unique_lock<std::mutex> lock(s.mutex);
    const std::uint64_t& covered = wait == Wait::kAll ? s.covered_all_want : s.covered_want;
    if (wait != Wait::kNone && covered < sent_) {
      const auto wait_start = Clock::now();
      s.covered.wait(lock, [&] { return covered >= sent_; });
      ++waits_;
      longest_wait_ms_ = std::max(longest_wait_ms_, MsSince(wait_start));
    }
    events.swap(s.events);
  }
  if (!events.empty()) {
    const auto swap_start = Clock::now();
    for (Event& event : events) {
      if (!event.tile) {
        if (tiles_.erase(event.key) && world && world->RemoveTile(event.key)) --collision_tiles_;
        continue;
      }
      if (event.collision && world) {
        world->AddTile(std::move(event.collision));
        ++collision_tiles_;
      }
      tiles_[event.key] = std::move(event.tile);
    }
    auto drawn = std::make_shared<TileList>();
    for (const auto& [key, tile] : tiles_) drawn->push_back(tile);
    drawn_ = std::move(drawn);
    longest_swap_ms_ = std::max(longest_swap_ms_, MsSince(swap_start));
  }
  return MsSince(start);
}

std::vector<std::string> TerrainStreamer::TakeMessages() {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  std::vector<std::string> messages;
  messages.swap(shared_->messages);
  return messages;
}

TerrainStreamer::Figures TerrainStreamer::figures() const {
  Figures f;
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    f = shared_->figures;
  }
  f.longest_swap_ms = longest_swap_ms_;
  f.waits = waits_;
  f.longest_wait_ms = longest_wait_ms_;
  return f;
}

}  // namespace sandbox::scene
