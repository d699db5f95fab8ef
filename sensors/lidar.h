#pragma once
// A spinning lidar: `channels` beams at fixed elevations, swept through
// `azimuth_steps` azimuths per revolution. Each azimuth step is stamped with
// its time within the sweep and cast from the sensor pose interpolated at that
// time, so the scan shows no motion distortion.
//
// Beam (channel c, step k) points along (cos e cos a, cos e sin a, sin e) in
// the sensor frame, e = elevation of channel c, a = 2 pi k / azimuth_steps
// (counter-clockwise from +X); index = c * azimuth_steps + k.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

struct LidarConfig {
  std::vector<double> elevations_rad;  // one per channel
  int azimuth_steps{1024};
  double range_m{100.0};
  double rotation_hz{10.0};  // one sweep lasts 1 / rotation_hz
  bool surface_ids{true};    // publish each beam's surface id (LidarScan::surface)
  bool normals{false};       // publish each beam's normal (LidarScan::normal_W)
  // Each return's intensity (LidarScan::intensity; docs/reference/sensors.md,
  // "Intensity"): reflectivity x cos(incidence) x min(1, (reference / range)^2).
  bool intensity{true};
  double intensity_reference_m{10.0};
  // Seeded imperfections (docs/reference/sensors.md, "Lidar noise"); all off
  // by default: the returns are then the exact geometry.
  struct Noise {
    double range_sigma_m{0.0};            // Gaussian range noise, standard deviation
    double range_sigma_per_m{0.0};        // and its growth per metre of range
    double dropout_probability{0.0};      // that a return is lost
    double dropout_below_intensity{0.0};  // returns dimmer than this are lost
    double range_step_m{0.0};             // ranges rounded to multiples of it (0: none)
    double min_range_m{0.0};              // nearer hits give no return
    std::uint64_t seed{0};                // the same seed and inputs: the same noise
    bool any() const;
  } noise;
  // Beam divergence (docs/reference/sensors.md, "Beam divergence"): each beam
  // a cone of `rays` sub-rays on its rim, `angle_rad` across; the sub-rays'
  // hits make a first and a last return. rays = 0: one ray a beam.
  struct Divergence {
    int rays{0};
    double angle_rad{0.0};
    double return_separation_m{0.5};  // hits this far apart are two returns
    bool on() const { return rays > 0; }
  } divergence;

  // `channels` elevations evenly from min to max (degrees).
  static LidarConfig Uniform(int channels, double min_deg, double max_deg, int azimuth_steps,
                             double range_m = 100.0, double rotation_hz = 10.0);
  // Throws std::invalid_argument naming the field: no channels, a non-positive
  // step count, range or rate, a non-finite elevation, over 10 million rays,
  // a negative sigma, step or minimum range, a probability or intensity
  // threshold outside [0, 1], a non-positive intensity reference, or a
  // divergence cone of fewer than 2 rays or an angle outside (0, 90) degrees.
  void ValidateOrThrow() const;
  int channels() const { return static_cast<int>(elevations_rad.size()); }

  // The [[robot.sensor]] table's own keys (docs/reference/levels.md); throws scene::LevelError
  // naming the key.
  static LidarConfig Read(scene::SettingsReader& read);
  // The same keys as TOML on one line ("channels = 32, seed = 7": sandbox
  // scan --lidar, Python), validated; `origin` names the source in messages.
  // Throws std::invalid_argument: "--lidar: ..." naming the key.
  static LidarConfig FromText(const std::string& text, const std::string& origin);
  std::string Summary() const;  // "16x1024, 100 m"
};

struct LidarScan {
  int channels{0};
  int azimuth_steps{0};
  std::vector<float> range_m;             // the hit distance, or range_m when nothing
  std::vector<std::uint8_t> hit;          // 1 when the beam hit something
  std::vector<Eigen::Vector3d> points_W;  // the hit, or the beam's end
  std::vector<std::int32_t> surface;      // surface id of the hit; 0 without
  std::vector<Eigen::Vector3f> normal_W;  // unit, world, facing the beam (LidarConfig::normals)
  std::vector<float> intensity;           // 0 to 1; 0 without a return (LidarConfig::intensity)
  // With beam divergence, the fields above hold each beam's first return and
  // these its last (the same as the first when the beam has one return);
  // empty without divergence.
  std::vector<float> last_range_m;
  std::vector<Eigen::Vector3d> last_points_W;
  std::vector<std::int32_t> last_surface;
  std::vector<float> last_intensity;                  // with LidarConfig::intensity
  bool surface_ids{true};                             // published (LidarConfig::surface_ids)
  std::vector<double> time_s;                         // per azimuth step, from the sweep's start
  Eigen::Vector3d origin_W{Eigen::Vector3d::Zero()};  // the sensor at the sweep's start
  double sweep_s{0.0};                                // 1 / rotation_hz
  Eigen::Isometry3d X_WS_start{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WS_end{Eigen::Isometry3d::Identity()};
};

class Lidar {
 public:
  using Config = LidarConfig;
  using Output = LidarScan;
  static constexpr std::string_view kType = "lidar";  // [[robot.sensor]] type

  explicit Lidar(const LidarConfig& config);  // throws std::invalid_argument
  const LidarConfig& config() const { return config_; }

  // The loop's call (sensors/sensor.h): the sweep that ends now began
  // 1 / rotation_hz ago, from the mount as it is now on the robot as it was
  // then (the context's history; none: the sensor as it is now).
  void Run(const SensorContext& at, LidarScan* scan) const;
  // How long the robot's poses must be kept for Run.
  double history_s() const { return 2.0 / config_.rotation_hz; }

  // One sweep from pose X_WS_start (at its start) to X_WS_end (at its end);
  // `sweep` numbers it for the noise (Run: the tick), which beam by beam
  // depends on the seed, the sweep and the beam alone.
  void Sweep(const scene::CollisionWorld& world, RayCaster& caster, const RayFilter& filter,
             const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
             LidarScan* scan, std::uint64_t sweep = 0) const;

  // The beams of that sweep (origin_W is the start pose's position), one ray
  // each; with divergence and `sub_rays`, their sub-rays too: beam i's at
  // i * rays .. i * rays + rays - 1, sub-ray j turned by half the angle from
  // the beam towards 2 pi j / rays about it, counted from the beam's rising
  // elevation towards its rising azimuth.
  RayBatch Rays(const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                RayBatch* sub_rays = nullptr) const;

 private:
  // Rays into *beams (and *sub_rays), channel by channel on the workers when given.
  void FillRays(const Eigen::Isometry3d& X_WS_start, const Eigen::Isometry3d& X_WS_end,
                RayBatch* beams, RayBatch* sub_rays, RayCaster* workers) const;

  LidarConfig config_;
};

}  // namespace sandbox::sensors
