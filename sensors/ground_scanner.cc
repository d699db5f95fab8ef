#include "sensors/ground_scanner.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "sensors/face_scanner.h"

namespace sandbox::sensors {

void GroundScannerConfig::ValidateOrThrow() const {
  FaceScannerConfig grid;
  grid.resolution_m = resolution_m;
  grid.half_extent_m = half_extent_m;
  grid.ValidateOrThrow();
  if (!(std::isfinite(depth_m) && depth_m > 0.0)) {
    throw std::invalid_argument("depth_m must be positive, got " +
                                (std::ostringstream() << depth_m).str());
  }
}

GroundScanner::GroundScanner(const GroundScannerConfig& config) : config_(config) {
  config_.ValidateOrThrow();
  n_ = static_cast<int>(std::lround(2.0 * config_.half_extent_m / config_.resolution_m)) + 1;
}

void GroundScanner::Scan(const scene::CollisionWorld& world, RayCaster& caster,
                         const RayFilter& filter, const Eigen::Vector3d& p_WS,
                         HeightMap* map) const {
  if (!p_WS.allFinite()) throw std::invalid_argument("GroundScanner::Scan(): non-finite position");
  RayBatch rays;
  rays.origin_W = p_WS;
  rays.Resize(std::size_t(n_) * std::size_t(n_));
  const double E = config_.half_extent_m, res = config_.resolution_m;
  for (int r = 0; r < n_; ++r) {
    for (int c = 0; c < n_; ++c) {
      const std::size_t i = std::size_t(r) * std::size_t(n_) + std::size_t(c);
      rays.start[i] = Eigen::Vector3f(float(-E + c * res), float(-E + r * res), 0.f);
      rays.direction[i] = -Eigen::Vector3f::UnitZ();
      rays.length_m[i] = static_cast<float>(config_.depth_m);
    }
  }
  thread_local RayHits hits;
  hits.with_normals = config_.normals;
  caster.Cast(world, rays, filter, &hits);
  map->n = n_;
  map->resolution_m = res;
  map->corner_W = p_WS.head<2>() - Eigen::Vector2d::Constant(E);
  map->height_m.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    map->height_m[i] = hits.surface[i] == RayHits::kNoHit ? std::numeric_limits<double>::quiet_NaN()
                                                          : p_WS.z() - double(hits.distance_m[i]);
  }
  map->surface = hits.surface;
  map->surface_ids = config_.surface_ids;
  if (config_.normals) {
    map->normal_W = hits.normal_W;
  } else {
    map->normal_W.clear();
  }
}

GroundScannerConfig GroundScannerConfig::Read(scene::SettingsReader& read) {
  GroundScannerConfig ground;
  ground.resolution_m = read.Number("resolution_m", ground.resolution_m);
  ground.half_extent_m = read.Number("half_extent_m", ground.half_extent_m);
  ground.depth_m = read.Number("depth_m", ground.depth_m);
  ground.surface_ids = read.Flag("surface_ids", ground.surface_ids);
  ground.normals = read.Flag("normals", ground.normals);
  return ground;
}

std::string GroundScannerConfig::Summary() const {
  std::ostringstream out;
  out << "+-" << half_extent_m << " m at " << resolution_m << " m";
  return out.str();
}

void GroundScanner::Run(const SensorContext& at, HeightMap* map) const {
  Scan(at.world, at.caster, at.filter, at.X_WS.translation(), map);
}

}  // namespace sandbox::sensors
