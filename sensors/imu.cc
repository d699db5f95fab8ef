#include "sensors/imu.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sensors/instrument_settings.h"
#include "sensors/normal_gravity.h"
#include "sensors/standard_atmosphere.h"

namespace sandbox::sensors {
namespace {

void CheckErrors(const ImuAxisErrors& errors, const std::string& prefix) {
  CheckNonNegative(prefix + "noise_density", errors.noise_density);
  CheckNonNegative(prefix + "bias_random_walk", errors.bias_random_walk);
  CheckNonNegative(prefix + "saturation", errors.saturation);
}

ImuAxisErrors ReadErrors(scene::SettingsReader& read, const std::string& prefix) {
  ImuAxisErrors errors;
  errors.noise_density = read.Number(prefix + "noise_density", errors.noise_density);
  errors.bias_random_walk = read.Number(prefix + "bias_random_walk", errors.bias_random_walk);
  errors.saturation = read.Number(prefix + "saturation", errors.saturation);
  return errors;
}

bool Noisy(const ImuAxisErrors& errors) {
  return errors.noise_density > 0.0 || errors.bias_random_walk > 0.0;
}

}  // namespace

void ImuConfig::ValidateOrThrow() const {
  CheckInstrumentClock(rate_hz, max_gap_s);
  CheckErrors(accel, "accel_");
  CheckErrors(gyro, "gyro_");
}

ImuConfig ImuConfig::Read(scene::SettingsReader& read) {
  ImuConfig config;
  config.accel = ReadErrors(read, "accel_");
  config.gyro = ReadErrors(read, "gyro_");
  config.seed = ReadSeed(read);
  config.max_gap_s = read.Number("max_gap_s", config.max_gap_s);
  return config;
}

std::string ImuConfig::Summary() const {
  std::ostringstream out;
  out << "specific force and rate, ";
  if (Noisy(accel) || Noisy(gyro)) {
    out << "noisy (seed " << seed << ")";
  } else {
    out << "noise off";
  }
  return out.str();
}

void IdealImuReading(const FrameMotion& motion, const Eigen::Vector3d& gravity_W,
                     Eigen::Vector3d* specific_force_F, Eigen::Vector3d* angular_rate_F) {
  *specific_force_F = motion.R_W.transpose() * (motion.a_W - gravity_W);
  *angular_rate_F = motion.omega_F;
}

Imu::Imu(const ImuConfig& config)
    : config_(config), clock_(config.rate_hz, config.max_gap_s), random_(config.seed) {
  config_.ValidateOrThrow();
}

void Imu::AddErrors(const ImuAxisErrors& errors, double dt_s, Eigen::Vector3d* bias,
                    Eigen::Vector3d* reading) {
  if (errors.bias_random_walk > 0.0) {
    const double step = errors.bias_random_walk * std::sqrt(dt_s);
    for (int k = 0; k < 3; ++k) (*bias)[k] += step * normal_(random_);
  }
  *reading += *bias;
  if (errors.noise_density > 0.0) {
    const double sigma = errors.noise_density / std::sqrt(dt_s);
    for (int k = 0; k < 3; ++k) (*reading)[k] += sigma * normal_(random_);
  }
  if (errors.saturation > 0.0) {
    *reading = reading->cwiseMax(-errors.saturation).cwiseMin(errors.saturation);
  }
}

void Imu::Run(const SensorContext& at, ImuSamples* out) {
  out->Clear();
  for (const std::int64_t utime : clock_.Add(at.pose_utime, at.X_WS)) {
    const FrameMotion motion = clock_.At(utime);
    const Eigen::Vector3d gravity_W =
        at.geodetic != nullptr ? GravityInWorld(*at.geodetic, motion.p_W)
                               : Eigen::Vector3d(0.0, 0.0, -standard_atmosphere::kStandardGravity);
    Eigen::Vector3d force, rate;
    IdealImuReading(motion, gravity_W, &force, &rate);
    AddErrors(config_.accel, clock_.period_s(), &accel_bias_, &force);
    AddErrors(config_.gyro, clock_.period_s(), &gyro_bias_, &rate);
    out->utime.push_back(utime);
    out->specific_force_S.push_back(force);
    out->angular_rate_S.push_back(rate);
  }
}

}  // namespace sandbox::sensors
