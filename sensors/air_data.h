#pragma once
// An air data computer: static pressure, temperature and density of the ICAO
// standard atmosphere at the sensor (sensors/standard_atmosphere.h), pressure
// altitude, true and indicated airspeed, Mach number, angle of attack and
// sideslip, from the motion of the sensor frame (sensors/pose_track.h)
// relative to the level's wind ([wind]: a mean wind with an optional shear
// layer, and Dryden gusts, sensors/wind_field.h). Samples on the poses'
// clock at rate_hz like the IMU.
//
// It measures as an air data computer does: static pressure, impact pressure
// (pitot minus static), total air temperature taken as static, and the two
// vane angles, each with its own seeded Gaussian noise; pressure altitude,
// airspeeds, Mach and density are computed from those measurements, so they
// agree with each other whatever the noise.

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/pose_track.h"
#include "sensors/sensor_context.h"
#include "sensors/wind_field.h"

namespace sandbox::sensors {

struct AirDataConfig {
  double rate_hz{0.0};  // the table's rate_hz: samples a second; 0: one a pose
  double static_pressure_sigma_pa{0.0};
  double impact_pressure_sigma_pa{0.0};
  double temperature_sigma_k{0.0};
  double angle_sigma_deg{0.0};  // angle of attack and sideslip vanes
  std::uint64_t seed{0};
  double max_gap_s{1.0};         // a pose further than this after the one before starts afresh
  void ValidateOrThrow() const;  // throws std::invalid_argument naming the field

  static AirDataConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "noise off"
};

struct AirDataSample {
  std::int64_t utime{0};  // on the poses' clock
  double static_pressure_pa{0.0};
  double temperature_k{0.0};
  double density_kg_m3{0.0};
  double pressure_altitude_m{0.0};  // geopotential, the standard atmosphere's (1013.25 hPa)
  double impact_pressure_pa{0.0};   // pitot minus static
  double true_airspeed_m_s{0.0};
  double indicated_airspeed_m_s{0.0};  // calibrated: no instrument or position error
  double mach{0.0};
  double angle_of_attack_rad{0.0};
  double sideslip_rad{0.0};
};

struct AirDataSamples {
  std::vector<AirDataSample> samples;  // since the last output, oldest first
};

// Impact pressure (pitot minus static) at Mach `mach` and static pressure
// `pressure_pa`: isentropic below Mach 1, Rayleigh's pitot formula above.
double ImpactPressure(double mach, double pressure_pa);
// The Mach number at which impact pressure over static pressure is `ratio`.
double MachFromImpactRatio(double ratio);

// The ideal air data of air velocity `air_S` (the sensor's velocity through
// the air, in the sensor frame: x forward, y left, z up) at geometric height
// `height_m` above sea level.
AirDataSample IdealAirData(const Eigen::Vector3d& air_S, double height_m);

class AirData {
 public:
  using Config = AirDataConfig;
  using Output = AirDataSamples;
  static constexpr std::string_view kType = "air_data";  // [[robot.sensor]] type

  explicit AirData(const AirDataConfig& config);  // throws std::invalid_argument
  const AirDataConfig& config() const { return config_; }
  // The loop's call, every tick: samples when a new pose has come.
  void Run(const SensorContext& at, AirDataSamples* out);

 private:
  AirDataConfig config_;
  PoseSampler clock_;
  std::optional<DrydenGusts> gusts_;  // made at the first run from the level's wind
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

}  // namespace sandbox::sensors
