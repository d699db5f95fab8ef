#include "sensors/lidar.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace sandbox::sensors {

LidarConfig LidarConfig::Uniform(int channels, double min_deg, double max_deg, int azimuth_steps,
                                 double range_m, double rotation_hz) {
  LidarConfig config;
  for (int c = 0; c < channels; ++c) {
    const double deg = channels == 1 ? min_deg : min_deg + (max_deg - min_deg) * c / (channels - 1);
    config.elevations_rad.push_back(deg * M_PI / 180.0);
  }
  config.azimuth_steps = azimuth_steps;
  config.range_m = range_m;
  config.rotation_hz = rotation_hz;
  return config;
}

void LidarConfig::ValidateOrThrow() const {
  auto fail = [](const std::string& field, double value, const std::string& what) {
    std::ostringstream out;
    out << field << " " << what << ", got " << value;
    throw std::invalid_argument(out.str());
  };
  if (elevations_rad.empty()) throw std::invalid_argument("channels must be at least 1, got 0");
  for (const double e : elevations_rad) {
    if (!std::isfinite(e)) fail("elevations", e, "must be finite");
  }
  if (azimuth_steps <= 0) fail("azimuth_steps", azimuth_steps, "must be positive");
  if (!(std::isfinite(range_m) && range_m > 0.0)) fail("range_m", range_m, "must be positive");
  if (!(std::isfinite(rotation_hz) && rotation_hz > 0.0)) {
    fail("rotation_hz", rotation_hz, "must be positive");
  }
  if (double(azimuth_steps) * double(elevations_rad.size()) > 1e7) {
    throw std::invalid_argument("channels x azimuth_steps makes more than 10 million rays");
  }
}

Lidar::Lidar(const LidarConfig& config) : config_(config) { config_.ValidateOrThrow(); }

RayBatch Lidar::Rays(const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end) const {
  const int channels = config_.channels(), steps = config_.azimuth_steps;
  RayBatch rays;
  rays.origin_W = X_WS_start.translation();
  rays.Resize(std::size_t(channels) * std::size_t(steps));
  const Eigen::Quaterniond q0(X_WS_start.linear()), q1(X_WS_end.linear());
  const Eigen::Vector3d travel = X_WS_end.translation() - X_WS_start.translation();
  for (int k = 0; k < steps; ++k) {
    // The pose at this step's time: position linear, rotation spherical.
    const double s = double(k) / steps;
    const Eigen::Matrix3d R = q0.slerp(s, q1).toRotationMatrix();
    const Eigen::Vector3f start = (s * travel).cast<float>();
    const double azimuth = 2.0 * M_PI * k / steps;
    for (int c = 0; c < channels; ++c) {
      const double e = config_.elevations_rad[std::size_t(c)];
      const Eigen::Vector3d d(std::cos(e) * std::cos(azimuth), std::cos(e) * std::sin(azimuth),
                              std::sin(e));
      const std::size_t i = std::size_t(c) * std::size_t(steps) + std::size_t(k);
      rays.start[i] = start;
      rays.direction[i] = (R * d).cast<float>();
      rays.length_m[i] = static_cast<float>(config_.range_m);
    }
  }
  return rays;
}

void Lidar::Sweep(const scene::CollisionWorld& world, RayCaster& caster, const RayFilter& filter,
                  const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                  LidarScan* scan) const {
  if (!X_WS_start.matrix().allFinite() || !X_WS_end.matrix().allFinite()) {
    throw std::invalid_argument("Lidar::Sweep(): non-finite pose");
  }
  const RayBatch rays = Rays(X_WS_start, X_WS_end);
  thread_local RayHits hits;
  hits.with_normals = config_.normals;
  caster.Cast(world, rays, filter, &hits);
  const std::size_t n = rays.size();
  scan->channels = config_.channels();
  scan->origin_W = rays.origin_W;
  scan->azimuth_steps = config_.azimuth_steps;
  scan->range_m = hits.distance_m;
  scan->hit.resize(n);
  scan->points_W.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scan->hit[i] = hits.surface[i] != RayHits::kNoHit;
    scan->points_W[i] =
        rays.origin_W + (rays.start[i] + hits.distance_m[i] * rays.direction[i]).cast<double>();
  }
  scan->surface = hits.surface;
  scan->surface_ids = config_.surface_ids;
  if (config_.normals) {
    scan->normal_W = hits.normal_W;
  } else {
    scan->normal_W.clear();
  }
  scan->sweep_s = 1.0 / config_.rotation_hz;
  scan->X_WS_start = X_WS_start;
  scan->X_WS_end = X_WS_end;
  scan->time_s.resize(std::size_t(config_.azimuth_steps));
  for (int k = 0; k < config_.azimuth_steps; ++k) {
    scan->time_s[std::size_t(k)] = k / (config_.azimuth_steps * config_.rotation_hz);
  }
}

LidarConfig LidarConfig::Read(scene::SettingsReader& read) {
  LidarConfig lidar;
  if (read.Has("elevations_deg")) {
    for (const double deg : read.Numbers("elevations_deg")) {
      lidar.elevations_rad.push_back(deg * M_PI / 180.0);
    }
  } else {
    const int channels = read.Whole("channels", 16);
    if (channels < 1) read.Fail("channels", "'channels' must be at least 1");
    lidar = Uniform(channels, read.Number("min_elevation_deg", -15.0),
                    read.Number("max_elevation_deg", 15.0), 1024);
  }
  lidar.azimuth_steps = read.Whole("azimuth_steps", 1024);
  lidar.range_m = read.Number("range_m", 100.0);
  lidar.rotation_hz = read.Number("rotation_hz", 10.0);
  lidar.surface_ids = read.Flag("surface_ids", lidar.surface_ids);
  lidar.normals = read.Flag("normals", lidar.normals);
  read.Removed("kernel",
               "every lidar is cast by the general caster, faster than the structured sweep "
               "kernel on every level measured (docs/decisions/001-no-structured-lidar-kernel.md); "
               "delete the key");
  return lidar;
}

std::string LidarConfig::Summary() const {
  std::ostringstream out;
  out << channels() << "x" << azimuth_steps << ", " << range_m << " m";
  return out.str();
}

void Lidar::Run(const SensorContext& at, LidarScan* scan) const {
  const double sweep_s = 1.0 / config_.rotation_hz;
  const Eigen::Isometry3d X_RS = at.X_WR.inverse() * at.X_WS;
  const Eigen::Isometry3d X_WS_start =
      at.history != nullptr ? at.history->At(at.t_s - sweep_s) * X_RS : at.X_WS;
  Sweep(at.world, at.caster, at.filter, X_WS_start, at.X_WS, scan);
}

}  // namespace sandbox::sensors
