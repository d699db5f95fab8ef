#include "sensors/air_data.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sensors/instrument_settings.h"
#include "sensors/standard_atmosphere.h"

namespace sandbox::sensors {
namespace {

using namespace standard_atmosphere;
constexpr double kGamma = kHeatCapacityRatio;

// Pitot over static pressure, Rayleigh's formula (a normal shock ahead of the probe).
double RayleighPitotRatio(double mach) {
  const double m2 = mach * mach;
  return std::pow((kGamma + 1.0) / 2.0 * m2, kGamma / (kGamma - 1.0)) /
         std::pow(2.0 * kGamma / (kGamma + 1.0) * m2 - (kGamma - 1.0) / (kGamma + 1.0),
                  1.0 / (kGamma - 1.0));
}

}  // namespace

double ImpactPressure(double mach, double pressure_pa) {
  if (mach < 1.0) {
    return pressure_pa *
           (std::pow(1.0 + (kGamma - 1.0) / 2.0 * mach * mach, kGamma / (kGamma - 1.0)) - 1.0);
  }
  return pressure_pa * (RayleighPitotRatio(mach) - 1.0);
}

double MachFromImpactRatio(double ratio) {
  if (!(ratio > 0.0)) return 0.0;
  const double sonic = std::pow(1.0 + (kGamma - 1.0) / 2.0, kGamma / (kGamma - 1.0)) - 1.0;
  if (ratio < sonic) {
    return std::sqrt(2.0 / (kGamma - 1.0) * (std::pow(ratio + 1.0, (kGamma - 1.0) / kGamma) - 1.0));
  }
  double low = 1.0, high = 2.0;  // Rayleigh's ratio rises with Mach: bracket, then halve
  while (RayleighPitotRatio(high) - 1.0 < ratio && high < 1e3) high *= 2.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (low + high);
    (RayleighPitotRatio(mid) - 1.0 < ratio ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

AirDataSample IdealAirData(const Eigen::Vector3d& air_S, double height_m) {
  const AtmosphereState air = StandardAtmosphere(GeopotentialFromGeometric(height_m));
  AirDataSample sample;
  sample.static_pressure_pa = air.pressure_pa;
  sample.temperature_k = air.temperature_k;
  sample.density_kg_m3 = air.density_kg_m3;
  sample.true_airspeed_m_s = air_S.norm();
  sample.mach = sample.true_airspeed_m_s / air.speed_of_sound_m_s;
  sample.impact_pressure_pa = ImpactPressure(sample.mach, air.pressure_pa);
  sample.pressure_altitude_m = PressureAltitude(air.pressure_pa);
  const double a0 = std::sqrt(kGamma * kGasConstantAir * kSeaLevelTemperatureK);
  sample.indicated_airspeed_m_s =
      a0 * MachFromImpactRatio(sample.impact_pressure_pa / kSeaLevelPressurePa);
  // x forward, y left, z up: air from below and from the right are positive.
  sample.angle_of_attack_rad = std::atan2(-air_S.z(), air_S.x());
  sample.sideslip_rad =
      sample.true_airspeed_m_s > 0.0
          ? std::asin(std::clamp(-air_S.y() / sample.true_airspeed_m_s, -1.0, 1.0))
          : 0.0;
  return sample;
}

void AirDataConfig::ValidateOrThrow() const {
  CheckInstrumentClock(rate_hz, max_gap_s);
  CheckNonNegative("static_pressure_sigma_pa", static_pressure_sigma_pa);
  CheckNonNegative("impact_pressure_sigma_pa", impact_pressure_sigma_pa);
  CheckNonNegative("temperature_sigma_k", temperature_sigma_k);
  CheckNonNegative("angle_sigma_deg", angle_sigma_deg);
}

AirDataConfig AirDataConfig::Read(scene::SettingsReader& read) {
  AirDataConfig config;
  config.static_pressure_sigma_pa =
      read.Number("static_pressure_sigma_pa", config.static_pressure_sigma_pa);
  config.impact_pressure_sigma_pa =
      read.Number("impact_pressure_sigma_pa", config.impact_pressure_sigma_pa);
  config.temperature_sigma_k = read.Number("temperature_sigma_k", config.temperature_sigma_k);
  config.angle_sigma_deg = read.Number("angle_sigma_deg", config.angle_sigma_deg);
  config.seed = ReadSeed(read);
  config.max_gap_s = read.Number("max_gap_s", config.max_gap_s);
  return config;
}

std::string AirDataConfig::Summary() const {
  const bool noisy = static_pressure_sigma_pa > 0.0 || impact_pressure_sigma_pa > 0.0 ||
                     temperature_sigma_k > 0.0 || angle_sigma_deg > 0.0;
  return noisy ? "noisy (seed " + std::to_string(seed) + ")" : "noise off";
}

AirData::AirData(const AirDataConfig& config)
    : config_(config), clock_(config.rate_hz, config.max_gap_s), random_(config.seed) {
  config_.ValidateOrThrow();
}

void AirData::Run(const SensorContext& at, AirDataSamples* out) {
  out->samples.clear();
  if (!gusts_ && at.wind != nullptr && at.wind->gust_sigma_m_s > 0.0) {
    // The gusts' own stream: the sensor's seed and the level's.
    gusts_.emplace(at.wind->gust_sigma_m_s, at.wind->gust_length_m,
                   config_.seed * 1000003u + std::uint64_t(at.wind->seed));
  }
  for (const std::int64_t utime : clock_.Add(at.pose_utime, at.X_WS)) {
    const FrameMotion motion = clock_.At(utime);
    const double height_m =
        at.geodetic != nullptr ? at.geodetic->ToGeodetic(motion.p_W).height_m : motion.p_W.z();
    const Eigen::Vector3d wind_W =
        at.wind != nullptr ? at.wind->At(motion.p_W.z()) : Eigen::Vector3d::Zero();
    Eigen::Vector3d air_S = motion.R_W.transpose() * (motion.v_W - wind_W);
    if (gusts_) air_S -= gusts_->Step(air_S.norm(), clock_.period_s());
    const AirDataSample ideal = IdealAirData(air_S, height_m);
    // The measurements, then what the computer makes of them.
    const auto noisy = [this](double value, double sigma) {
      return sigma > 0.0 ? value + sigma * normal_(random_) : value;
    };
    AirDataSample sample = ideal;
    sample.utime = utime;
    sample.static_pressure_pa = noisy(ideal.static_pressure_pa, config_.static_pressure_sigma_pa);
    sample.impact_pressure_pa =
        std::max(0.0, noisy(ideal.impact_pressure_pa, config_.impact_pressure_sigma_pa));
    sample.temperature_k = noisy(ideal.temperature_k, config_.temperature_sigma_k);
    const double angle_sigma = config_.angle_sigma_deg * M_PI / 180.0;
    sample.angle_of_attack_rad = noisy(ideal.angle_of_attack_rad, angle_sigma);
    sample.sideslip_rad = noisy(ideal.sideslip_rad, angle_sigma);
    if (config_.static_pressure_sigma_pa > 0.0 || config_.impact_pressure_sigma_pa > 0.0 ||
        config_.temperature_sigma_k > 0.0) {
      using namespace standard_atmosphere;
      sample.pressure_altitude_m = PressureAltitude(sample.static_pressure_pa);
      sample.density_kg_m3 = sample.static_pressure_pa / (kGasConstantAir * sample.temperature_k);
      sample.mach = MachFromImpactRatio(sample.impact_pressure_pa / sample.static_pressure_pa);
      sample.true_airspeed_m_s =
          sample.mach * std::sqrt(kGamma * kGasConstantAir * sample.temperature_k);
      const double a0 = std::sqrt(kGamma * kGasConstantAir * kSeaLevelTemperatureK);
      sample.indicated_airspeed_m_s =
          a0 * MachFromImpactRatio(sample.impact_pressure_pa / kSeaLevelPressurePa);
    }
    out->samples.push_back(sample);
  }
}

}  // namespace sandbox::sensors
