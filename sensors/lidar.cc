#include "sensors/lidar.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "scene/manifest.h"
#include "sensors/lidar_returns.h"

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
  if (divergence.rays != 0 || divergence.angle_rad != 0.0) {
    if (divergence.rays < 2) fail("divergence_rays", divergence.rays, "must be at least 2");
    const double deg = divergence.angle_rad * 180.0 / M_PI;
    if (!(deg > 0.0 && deg < 90.0)) fail("divergence_deg", deg, "must be more than 0 and under 90");
  }
  if (!(divergence.return_separation_m >= 0.0 && std::isfinite(divergence.return_separation_m))) {
    fail("return_separation_m", divergence.return_separation_m, "must be 0 or more");
  }
  const double per_beam = std::max(divergence.rays, 1);
  if (double(azimuth_steps) * double(elevations_rad.size()) * per_beam > 1e7) {
    throw std::invalid_argument(divergence.on()
                                    ? "channels x azimuth_steps x divergence_rays makes "
                                      "more than 10 million rays"
                                    : "channels x azimuth_steps makes more than 10 "
                                      "million rays");
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

// The per-beam lambdas below, inlined into their loops (GCC keeps them
// out of line, each capture then read through the closure at every call).
#define SANDBOX_INLINE __attribute__((always_inline))

Lidar::Lidar(const LidarConfig& config) : config_(config) { config_.ValidateOrThrow(); }

RayBatch Lidar::Rays(const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                     RayBatch* sub_rays) const {
  RayBatch rays;
  FillRays(X_WS_start, X_WS_end, &rays, sub_rays, nullptr);
  return rays;
}

void Lidar::FillRays(const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                     RayBatch* beams, RayBatch* sub_rays, RayCaster* workers) const {
  const int channels = config_.channels(), steps = config_.azimuth_steps;
  const int per_beam = sub_rays != nullptr ? config_.divergence.rays : 0;
  RayBatch& rays = *beams;
  rays.origin_W = X_WS_start.translation();
  rays.Resize(std::size_t(channels) * std::size_t(steps));
  if (per_beam > 0) {
    sub_rays->origin_W = rays.origin_W;
    sub_rays->Resize(rays.size() * std::size_t(per_beam));
  }
  // Sub-ray j: cos(h) d + sin(h) (cos(phi_j) up + sin(phi_j) side).
  const double h = config_.divergence.angle_rad / 2.0;
  std::vector<Eigen::Vector2d> around(std::size_t(std::max(per_beam, 0)));
  for (int j = 0; j < per_beam; ++j) {
    const double phi = 2.0 * M_PI * j / per_beam;
    around[std::size_t(j)] = std::sin(h) * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  // Each channel's elevation's cosine and sine, once a sweep.
  std::vector<Eigen::Vector2d> elevation(static_cast<std::size_t>(channels));
  for (int c = 0; c < channels; ++c) {
    const double e = config_.elevations_rad[std::size_t(c)];
    elevation[std::size_t(c)] = {std::cos(e), std::sin(e)};
  }
  // Each step's rotation, offset and azimuth, once a sweep; then the beams
  // channel by channel, in the order they are stored.
  const Eigen::Quaterniond q0(X_WS_start.linear()), q1(X_WS_end.linear());
  const Eigen::Vector3d travel = X_WS_end.translation() - X_WS_start.translation();
  // A beam at elevation e points along cos(e) level + sin(e) up, level and up
  // being its step's rotated (cos a, sin a, 0) and (0, 0, 1).
  struct Step {
    Eigen::Matrix3d R;
    Eigen::Vector3d level, up;
    Eigen::Vector3f start;
    double ca, sa;
  };
  thread_local std::vector<Step> kept_steps;  // kept between sweeps (a large block's pages)
  std::vector<Step>& at = kept_steps;
  at.resize(static_cast<std::size_t>(steps));
  for (int k = 0; k < steps; ++k) {
    // The pose at this step's time: position linear, rotation spherical.
    const double s = double(k) / steps;
    const double azimuth = 2.0 * M_PI * k / steps;
    Step& step = at[std::size_t(k)];
    step.R = q0.slerp(s, q1).toRotationMatrix();
    step.ca = std::cos(azimuth), step.sa = std::sin(azimuth);
    step.level = step.R * Eigen::Vector3d(step.ca, step.sa, 0.0);
    step.up = step.R.col(2);
    step.start = (s * travel).cast<float>();
  }
  const float length = static_cast<float>(config_.range_m);
  auto channel = [&](int c) {
    const double cos_e = elevation[std::size_t(c)].x(), sin_e = elevation[std::size_t(c)].y();
    for (int k = 0; k < steps; ++k) {
      const Step& step = at[std::size_t(k)];
      const std::size_t i = std::size_t(c) * std::size_t(steps) + std::size_t(k);
      rays.start[i] = step.start;
      rays.direction[i] = (cos_e * step.level + sin_e * step.up).cast<float>();
      rays.length_m[i] = length;
      if (per_beam == 0) continue;
      const double ca = step.ca, sa = step.sa;
      const Eigen::Vector3d d(cos_e * ca, cos_e * sa, sin_e);
      const Eigen::Vector3d up(-sin_e * ca, -sin_e * sa, cos_e), side(-sa, ca, 0);
      for (int j = 0; j < per_beam; ++j) {
        const Eigen::Vector2d& o = around[std::size_t(j)];
        const std::size_t q = i * std::size_t(per_beam) + std::size_t(j);
        sub_rays->start[q] = step.start;
        sub_rays->direction[q] =
            (step.R * (std::cos(h) * d + o.x() * up + o.y() * side)).normalized().cast<float>();
        sub_rays->length_m[q] = length;
      }
    }
  };
  if (workers != nullptr) {
    workers->RunParallel(channels, channel);
  } else {
    for (int c = 0; c < channels; ++c) channel(c);
  }
}

namespace {

// One return of a beam: its range, what it hit and how bright it came back.
struct Return {
  float range_m{0.f};
  std::int32_t surface{RayHits::kNoHit};
  Eigen::Vector3f normal{Eigen::Vector3f::Zero()};
  float brightness{0.f};
  bool there() const { return surface != RayHits::kNoHit; }
};

// A chunk's noise (Sweep): each beam's Gaussian draw and chance and, for single
// rays, its noisy range and whether it is kept.
struct Noisy {
  float z[kReturnChunk];
  std::uint64_t chance[kReturnChunk];
  float range[kReturnChunk];
  bool kept[kReturnChunk];
};

}  // namespace

void Lidar::Sweep(const scene::CollisionWorld& world, RayCaster& caster, const RayFilter& filter,
                  const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                  LidarScan* scan, std::uint64_t sweep) const {
  if (!X_WS_start.matrix().allFinite() || !X_WS_end.matrix().allFinite()) {
    throw std::invalid_argument("Lidar::Sweep(): non-finite pose");
  }
  const LidarConfig::Divergence& divergence = config_.divergence;
  const int per_beam = std::max(divergence.rays, 1);
  // Kept between sweeps (this thread's); the workers below read them through
  // these references (a thread_local named in a lambda is the worker's own).
  thread_local RayBatch kept_beams, kept_sub_rays;
  thread_local RayHits kept_hits;
  RayBatch& beams = kept_beams;
  RayBatch& sub_rays = kept_sub_rays;
  RayHits& hits = kept_hits;
  FillRays(X_WS_start, X_WS_end, &beams, divergence.on() ? &sub_rays : nullptr, &caster);
  const RayBatch& rays = divergence.on() ? sub_rays : beams;
  const LidarConfig::Noise& noise = config_.noise;
  const bool intensity = config_.intensity || noise.dropout_below_intensity > 0.0;
  hits.with_normals = config_.normals || intensity;
  hits.with_reflectivity = intensity;
  caster.Cast(world, rays, filter, &hits);
  const std::size_t n = beams.size(), lasts = divergence.on() ? n : 0;
  scan->channels = config_.channels();
  scan->origin_W = beams.origin_W;
  scan->azimuth_steps = config_.azimuth_steps;
  scan->hit.resize(n);
  scan->points_W.resize(n);
  scan->range_m.resize(n);
  scan->surface.resize(n);
  scan->normal_W.resize(config_.normals ? n : 0);
  scan->intensity.resize(config_.intensity ? n : 0);
  scan->last_range_m.resize(lasts);
  scan->last_points_W.resize(lasts);
  scan->last_surface.resize(lasts);
  scan->last_intensity.resize(config_.intensity ? lasts : 0);
  const bool noisy = noise.any();
  const std::uint64_t sweep_key = SweepKey(noise.seed, sweep);
  const float range = static_cast<float>(config_.range_m);
  const double reference2 = config_.intensity_reference_m * config_.intensity_reference_m;

  // Ray q's hit as a return (its brightness: "Intensity").
  auto hit_of = [&](std::size_t q, bool bright = true) SANDBOX_INLINE {
    Return hit;
    hit.surface = hits.surface[q];
    hit.range_m = hits.distance_m[q];
    if (!hits.with_normals || !hit.there()) return hit;
    hit.normal = hits.normal_W[q];
    if (intensity && bright) {
      hit.brightness = Brightness(hits.reflectivity[q], hit.normal, rays.direction[q],
                                  hit.range_m, reference2);
    }
    return hit;
  };
  // A cone's sub-ray hits grouped into the first and the last return.
  auto cone = [&](std::size_t i, Return* first, Return* last) SANDBOX_INLINE {
    const std::size_t q0 = i * std::size_t(per_beam);
    float nearest = range, farthest = -1.f;
    for (std::size_t q = q0; q < q0 + std::size_t(per_beam); ++q) {
      if (hits.surface[q] == RayHits::kNoHit) continue;
      nearest = std::min(nearest, hits.distance_m[q]);
      farthest = std::max(farthest, hits.distance_m[q]);
    }
    *first = *last = Return{};
    if (farthest < 0.f) return;
    const float near_end = nearest + float(divergence.return_separation_m);
    const float far_start = farthest - float(divergence.return_separation_m);
    double sum[2] = {0.0, 0.0};
    int count[2] = {0, 0};
    for (std::size_t q = q0; q < q0 + std::size_t(per_beam); ++q) {
      if (hits.surface[q] == RayHits::kNoHit) continue;
      const float d = hits.distance_m[q];
      const int group = d <= near_end ? 0 : d >= far_start ? 1 : -1;
      if (group < 0) continue;
      Return& to = group == 0 ? *first : *last;
      const Return hit = hit_of(q);
      // Its identity: the group's nearest sub-ray (the first), farthest (the
      // last); a tie goes to the lower id.
      const bool take = !to.there() || (group == 0 ? d < to.range_m : d > to.range_m) ||
                        (d == to.range_m && hit.surface < to.surface);
      const float brightness = to.brightness + hit.brightness / float(per_beam);
      if (take) to = hit;
      to.brightness = brightness;
      sum[group] += d;
      ++count[group];
    }
    first->range_m = float(sum[0] / count[0]);
    if (count[1] == 0) {
      *last = *first;
    } else {
      last->range_m = float(sum[1] / count[1]);
    }
  };
  const RangeNoise range_noise(config_);
  const NormalDraw& normal = NormalDraw::Standard();
  // The noise on a divergent beam's return, given its Gaussian draw z: false
  // when it is lost to the minimum range or to dimness.
  auto perturb = [&](float z, Return* ret) SANDBOX_INLINE {
    const bool kept = (ret->range_m >= range_noise.min_range) &
                      (ret->brightness >= range_noise.dimmest);
    ret->range_m = range_noise.Range(ret->range_m, z);
    return kept;
  };
  // Beam i; with noise (with_noise true), given the chunk's draws at k (its
  // place in the chunk) and, for a single ray, its noisy range and whether it
  // escapes the minimum range and chance.
  auto beam = [&](auto with_noise, std::size_t i, std::size_t k, const Noisy* noisy_chunk,
                  const float* brightness) SANDBOX_INLINE {
    Return first, last;
    if (divergence.on()) {
      cone(i, &first, &last);
    } else if (hits.surface[i] != RayHits::kNoHit) {
      first = hit_of(i, false);
      if (intensity) first.brightness = brightness[k];
    }
    if constexpr (decltype(with_noise)::value) {
      if (!first.there()) {
      } else if (!divergence.on()) {
        first.range_m = noisy_chunk->range[k];
        if (!(noisy_chunk->kept[k] & (first.brightness >= range_noise.dimmest))) first = Return{};
      } else if (range_noise.Dropped(noisy_chunk->chance[k])) {
        first = last = Return{};
      } else {
        const bool separate = last.range_m != first.range_m;
        const bool keep_first = perturb(noisy_chunk->z[k], &first);
        const bool keep_last =
            separate ? perturb(normal(std::uint32_t(Draw(sweep_key, i, 1) >> 32)), &last)
                     : keep_first;
        if (!separate) last = first;
        if (!keep_first) first = keep_last ? last : Return{};
        if (!keep_last) last = first;
      }
    }
    const Eigen::Vector3d start = beams.origin_W + beams.start[i].cast<double>();
    const Eigen::Vector3d direction = beams.direction[i].cast<double>();
    const float r = first.there() ? first.range_m : range;
    scan->hit[i] = first.there();
    scan->range_m[i] = r;
    scan->points_W[i] = start + double(r) * direction;
    scan->surface[i] = first.surface;
    if (config_.normals) scan->normal_W[i] = first.normal;
    if (config_.intensity) scan->intensity[i] = first.brightness;
    if (!divergence.on()) return;
    const float r_last = last.there() ? last.range_m : range;
    scan->last_range_m[i] = r_last;
    scan->last_points_W[i] = start + double(r_last) * direction;
    scan->last_surface[i] = last.surface;
    if (config_.intensity) scan->last_intensity[i] = last.brightness;
  };
  caster.RunParallel(int((n + kReturnChunk - 1) / kReturnChunk), [&](int chunk) {
    const std::size_t begin = std::size_t(chunk) * kReturnChunk;
    const std::size_t end = std::min(n, begin + kReturnChunk);
    // The chunk's brightness and noise first, in loops of their own (they
    // vectorise there; inside the beam's long body they would not).
    float brightness[kReturnChunk];
    if (intensity && !divergence.on()) {
      BrightnessOf(hits, rays, begin, end, reference2, brightness);
    }
    if (!noisy) {
      for (std::size_t i = begin; i < end; ++i) {
        beam(std::false_type{}, i, i - begin, nullptr, brightness);
      }
      return;
    }
    Noisy draws;
    DrawBeams(sweep_key, begin, draws.z, draws.chance);
    if (!divergence.on()) {
      std::copy(hits.distance_m.begin() + std::ptrdiff_t(begin),
                hits.distance_m.begin() + std::ptrdiff_t(end), draws.range);
      std::fill(draws.range + (end - begin), draws.range + kReturnChunk, 0.f);
      PerturbBeams(range_noise, draws.z, draws.chance, draws.range, draws.kept);
    }
    for (std::size_t i = begin; i < end; ++i) {
      beam(std::true_type{}, i, i - begin, &draws, brightness);
    }
  });
  scan->surface_ids = config_.surface_ids;
  scan->sweep_s = 1.0 / config_.rotation_hz;
  scan->X_WS_start = X_WS_start;
  scan->X_WS_end = X_WS_end;
  scan->time_s.resize(std::size_t(config_.azimuth_steps));
  for (int k = 0; k < config_.azimuth_steps; ++k) {
    scan->time_s[std::size_t(k)] = k / (config_.azimuth_steps * config_.rotation_hz);
  }
}

LidarConfig LidarConfig::FromText(const std::string& text, const std::string& origin) {
  try {
    const scene::SettingsTable table = scene::ParseSettingsText(text, origin, "lidar");
    scene::SettingsReader read(table);
    LidarConfig config = Read(read);
    read.RejectUnknownKeys("lidar");
    config.ValidateOrThrow();
    return config;
  } catch (const scene::LevelError& error) {
    throw std::invalid_argument(error.what());
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(origin + ": " + error.what());
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
  const bool divergent = read.Has("divergence_rays") || read.Has("divergence_deg");
  lidar.divergence.rays = read.Whole("divergence_rays", divergent ? 4 : 0);
  lidar.divergence.angle_rad = read.Number("divergence_deg", 0.0) * M_PI / 180.0;
  lidar.divergence.return_separation_m =
      read.Number("return_separation_m", lidar.divergence.return_separation_m);
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
