#pragma once
// An inertial measurement unit: specific force and angular rate in the sensor
// frame, from the motion of the sensor's frame (sensors/pose_track.h: the
// cubic through its four newest poses, so a mount on a bone moves with the
// bone), with gravity from WGS84 normal gravity at the sensor's geodetic
// position when the level has an anchor, else standard gravity, straight down.
// The world frame is taken as inertial (the Earth's rotation is not sensed).
//
// It samples on the poses' clock (their time stamps): at k / rate_hz for
// every k in (previous pose, newest pose], so several samples a pose when its
// rate is above the poses' (none at the first pose; one at each pose without
// a rate). Each axis adds white noise of the configured density, a bias that
// walks at the configured rate, and clips at its saturation; the noise is
// drawn from a generator seeded by `seed`, so a run repeats exactly.

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/pose_track.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

// One measured quantity's errors, per axis.
struct ImuAxisErrors {
  double noise_density{0.0};     // white noise, unit / sqrt(Hz)
  double bias_random_walk{0.0};  // bias drift, unit / s / sqrt(Hz)
  double saturation{0.0};        // |reading| at most this; 0: none
};

struct ImuConfig {
  double rate_hz{0.0};  // the table's rate_hz: samples a second; 0: one a pose
  ImuAxisErrors accel;  // m/s^2
  ImuAxisErrors gyro;   // rad/s
  std::uint64_t seed{0};
  // A pose further than this after the one before starts the track afresh.
  double max_gap_s{1.0};
  void ValidateOrThrow() const;  // throws std::invalid_argument naming the field

  static ImuConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "noise off" or "noisy, seed 7"
};

// The samples taken since the last output, oldest first (empty: none this tick).
struct ImuSamples {
  std::vector<std::int64_t> utime;                // on the poses' clock
  std::vector<Eigen::Vector3d> specific_force_S;  // m/s^2, sensor frame
  std::vector<Eigen::Vector3d> angular_rate_S;    // rad/s, sensor frame
  void Clear() { utime.clear(), specific_force_S.clear(), angular_rate_S.clear(); }
};

// The ideal readings of a frame in motion: specific force R^T (a - g) and
// angular rate, in the frame.
void IdealImuReading(const FrameMotion& motion, const Eigen::Vector3d& gravity_W,
                     Eigen::Vector3d* specific_force_F, Eigen::Vector3d* angular_rate_F);

class Imu {
 public:
  using Config = ImuConfig;
  using Output = ImuSamples;
  static constexpr std::string_view kType = "imu";  // [[robot.sensor]] type

  explicit Imu(const ImuConfig& config);  // throws std::invalid_argument
  const ImuConfig& config() const { return config_; }
  // The loop's call, every tick: samples when a new pose has come
  // (at.pose_utime), nothing otherwise.
  void Run(const SensorContext& at, ImuSamples* out);

 private:
  void AddErrors(const ImuAxisErrors& errors, double dt_s, Eigen::Vector3d* bias,
                 Eigen::Vector3d* reading);

  ImuConfig config_;
  PoseSampler clock_;
  Eigen::Vector3d accel_bias_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_{Eigen::Vector3d::Zero()};
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

}  // namespace sandbox::sensors
