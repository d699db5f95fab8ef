#include "sensors/lidar.h"

#include <algorithm>
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
  if (!(std::isfinite(intensity_reference_m) && intensity_reference_m > 0.0)) {
    fail("intensity_reference_m", intensity_reference_m, "must be positive");
  }
  const std::pair<const char*, double> non_negative[] = {
      {"range_noise_sigma_m", noise.range_sigma_m},
      {"range_noise_sigma_per_m", noise.range_sigma_per_m},
      {"range_step_m", noise.range_step_m},
      {"min_range_m", noise.min_range_m}};
  for (const auto& [field, value] : non_negative) {
    if (!(std::isfinite(value) && value >= 0.0)) fail(field, value, "must be 0 or more");
  }
  const std::pair<const char*, double> unit[] = {
      {"dropout_probability", noise.dropout_probability},
      {"dropout_below_intensity", noise.dropout_below_intensity}};
  for (const auto& [field, value] : unit) {
    if (!(value >= 0.0 && value <= 1.0)) fail(field, value, "must be 0 to 1");
  }
}

bool LidarConfig::Noise::any() const {
  return range_sigma_m > 0.0 || range_sigma_per_m > 0.0 || dropout_probability > 0.0 ||
         dropout_below_intensity > 0.0 || range_step_m > 0.0 || min_range_m > 0.0;
}

namespace {

// SplitMix64's finaliser: a well-mixed 64-bit value of its argument.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Draw k (0 or 1) of beam `beam`, given the sweep's key (Mix of the seed and
// the sweep): uniform in (0, 1), a function of its arguments alone (no
// generator state: threads and order do not matter).
double Uniform(std::uint64_t sweep_key, std::uint64_t beam, std::uint64_t k) {
  return (double(Mix(sweep_key ^ (beam << 1 | k)) >> 11) + 0.5) * 0x1.0p-53;
}

// The standard normal quantile at p in (0, 1) (inverse transform sampling):
// Acklam's rational approximation, relative error under 1.2e-9; the tails
// (p < 0.02425 or > 0.97575, 5% of draws) take a logarithm and a square root.
double NormalQuantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                 -2.759285104469687e+02, 1.383577518672690e+02,
                                 -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                 -1.556989798598866e+02, 6.680131188771972e+01,
                                 -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  if (p < kLow || p > 1.0 - kLow) {
    const double q = std::sqrt(-2.0 * std::log(p < kLow ? p : 1.0 - p));
    const double z = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                     ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    return p < kLow ? z : -z;
  }
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

}  // namespace

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
                  LidarScan* scan, std::uint64_t sweep) const {
  if (!X_WS_start.matrix().allFinite() || !X_WS_end.matrix().allFinite()) {
    throw std::invalid_argument("Lidar::Sweep(): non-finite pose");
  }
  const RayBatch rays = Rays(X_WS_start, X_WS_end);
  thread_local RayHits hits;
  const LidarConfig::Noise& noise = config_.noise;
  const bool intensity = config_.intensity || noise.dropout_below_intensity > 0.0;
  hits.with_normals = config_.normals || intensity;
  caster.Cast(world, rays, filter, &hits);
  const std::size_t n = rays.size();
  scan->channels = config_.channels();
  scan->origin_W = rays.origin_W;
  scan->azimuth_steps = config_.azimuth_steps;
  scan->hit.resize(n);
  scan->points_W.resize(n);
  scan->intensity.assign(intensity ? n : 0, 0.f);
  const bool noisy = noise.any();
  const std::uint64_t sweep_key = Mix(Mix(noise.seed) ^ sweep);
  const float range = static_cast<float>(config_.range_m);
  const double reference2 = config_.intensity_reference_m * config_.intensity_reference_m;
  for (std::size_t i = 0; i < n; ++i) {
    if (hits.surface[i] == RayHits::kNoHit) continue;
    float r = hits.distance_m[i];
    float brightness = 0.f;
    if (intensity) {
      const double cosine = -double(hits.normal_W[i].dot(rays.direction[i]));
      const double falloff = r > 0.f ? std::min(1.0, reference2 / (double(r) * r)) : 1.0;
      brightness = float(world.surface_ids().reflectivity(hits.surface[i]) * std::max(0.0, cosine) *
                         falloff);
    }
    if (noisy) {
      const bool lost = r < noise.min_range_m || brightness < noise.dropout_below_intensity ||
                        Uniform(sweep_key, i, 0) < noise.dropout_probability;
      if (lost) {
        hits.surface[i] = RayHits::kNoHit;
        hits.distance_m[i] = range;
        if (hits.with_normals) hits.normal_W[i].setZero();
        continue;
      }
      const double sigma = noise.range_sigma_m + noise.range_sigma_per_m * r;
      if (sigma > 0.0) r += float(sigma * NormalQuantile(Uniform(sweep_key, i, 1)));
      if (noise.range_step_m > 0.0) {
        r = float(std::round(r / noise.range_step_m) * noise.range_step_m);
      }
      r = std::clamp(r, 0.f, range);
      hits.distance_m[i] = r;
    }
    if (intensity) scan->intensity[i] = brightness;
  }
  scan->range_m = hits.distance_m;
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
  lidar.intensity = read.Flag("intensity", lidar.intensity);
  lidar.intensity_reference_m = read.Number("intensity_reference_m", lidar.intensity_reference_m);
  LidarConfig::Noise& noise = lidar.noise;
  noise.range_sigma_m = read.Number("range_noise_sigma_m", 0.0);
  noise.range_sigma_per_m = read.Number("range_noise_sigma_per_m", 0.0);
  noise.dropout_probability = read.Number("dropout_probability", 0.0);
  noise.dropout_below_intensity = read.Number("dropout_below_intensity", 0.0);
  noise.range_step_m = read.Number("range_step_m", 0.0);
  noise.min_range_m = read.Number("min_range_m", 0.0);
  const int seed = read.Whole("seed", 0);
  if (seed < 0) read.Fail("seed", "'seed' must be 0 or more");
  noise.seed = std::uint64_t(seed);
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
  Sweep(at.world, at.caster, at.filter, X_WS_start, at.X_WS, scan,
        static_cast<std::uint64_t>(at.tick));
}

}  // namespace sandbox::sensors
