#pragma once
// A GNSS receiver: latitude, longitude and ellipsoidal height (WGS84) of the
// sensor frame's origin through the world's geodetic anchor
// (scene/geodetic.h), and its velocity north, east and down, from the motion
// of the sensor frame (sensors/pose_track.h). Fixes at rate_hz on the poses'
// clock, each published `latency_s` after its time (with the first pose at or
// after it), with seeded Gaussian noise: horizontal and vertical in metres,
// velocity in m/s. A level without a geodetic anchor cannot carry one
// (refused at load).

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/pose_track.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

struct GnssConfig {
  double rate_hz{0.0};  // the table's rate_hz: fixes a second; 0: one a pose
  double latency_s{0.0};
  double horizontal_sigma_m{0.0};
  double vertical_sigma_m{0.0};
  double velocity_sigma_m_s{0.0};
  std::uint64_t seed{0};
  double max_gap_s{1.0};         // a pose further than this after the one before starts afresh
  void ValidateOrThrow() const;  // throws std::invalid_argument naming the field

  static GnssConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "latency 0.1 s, noise off"
};

struct GnssFix {
  std::int64_t utime{0};  // when it was taken, on the poses' clock
  double latitude_deg{0.0};
  double longitude_deg{0.0};
  double height_m{0.0};                                   // above the WGS84 ellipsoid
  Eigen::Vector3d velocity_ned{Eigen::Vector3d::Zero()};  // m/s: north, east, down
};

// The fixes released since the last output, oldest first (empty: none this tick).
struct GnssFixes {
  std::vector<GnssFix> fixes;
};

// The true fix of world point p_W moving at v_W, through `frame`.
GnssFix TrueFix(const scene::LocalTangentPlane& frame, const Eigen::Vector3d& p_W,
                const Eigen::Vector3d& v_W);

class Gnss {
 public:
  using Config = GnssConfig;
  using Output = GnssFixes;
  static constexpr std::string_view kType = "gnss";  // [[robot.sensor]] type

  explicit Gnss(const GnssConfig& config);  // throws std::invalid_argument
  const GnssConfig& config() const { return config_; }
  // The loop's call, every tick: fixes when a new pose has come, nothing
  // otherwise or without a geodetic frame.
  void Run(const SensorContext& at, GnssFixes* out);

 private:
  GnssConfig config_;
  PoseSampler clock_;
  std::deque<GnssFix> pending_;  // taken, not yet released (latency)
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

}  // namespace sandbox::sensors
