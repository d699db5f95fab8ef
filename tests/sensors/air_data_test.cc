// The air data computer against the published standard atmosphere, the
// airspeed identities that hold whatever the formulas (calibrated equals true
// airspeed at sea level; tends to equivalent airspeed at low speed), the
// normal-shock table, flight geometry with wind and shear, the Dryden model's
// variance and correlation, and its noise's statistics.

#include "sensors/air_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/standard_atmosphere.h"
#include "sensors/wind_field.h"

namespace sandbox::sensors {
namespace {

using Eigen::Vector3d;

// Flies `sensor` on poses at 100 Hz for `poses` poses, position p(t), level
// attitude; every sample.
std::vector<AirDataSample> Fly(AirData& sensor, int poses,
                               const std::function<Vector3d(double)>& p_at,
                               const scene::WindSpec* wind = nullptr) {
  static const scene::Level empty;
  static const scene::CollisionWorld world(empty);
  RayCaster caster(1);
  std::vector<AirDataSample> samples;
  AirDataSamples out;
  for (int k = 0; k < poses; ++k) {
    const std::int64_t utime = 10000 * std::int64_t(k);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = p_at(double(utime) * 1e-6);
    sensor.Run({world, caster, {}, X, X, nullptr, 0.0, k, utime, nullptr, wind}, &out);
    samples.insert(samples.end(), out.samples.begin(), out.samples.end());
  }
  return samples;
}

// Level flight east at `speed`, at geometric height z.
std::function<Vector3d(double)> East(double speed, double z) {
  return [=](double t) { return Vector3d(speed * t, 0.0, z); };
}

// A climb through geopotential 0, 5, 11 and 20 km (flown at the geometric
// heights the documented conversion gives): the published table (ICAO Doc
// 7488 / U.S. Standard Atmosphere 1976) to 0.01%.
TEST(AirDataTest, AClimbGivesThePublishedStandardAtmosphere) {
  struct Row {
    double h_m, geometric_m, pressure_pa, temperature_k;
  };
  // Geometric heights from the 1976 table (geopotential 11 km = 11,019 m, 20 km = 20,063 m).
  for (const Row& row :
       {Row{0.0, 0.0, 101325.0, 288.15}, Row{5000.0, 5003.9, 54019.9, 255.65},
        Row{11000.0, 11019.1, 22632.1, 216.65}, Row{20000.0, 20063.1, 5474.89, 216.65}}) {
    EXPECT_NEAR(GeometricFromGeopotential(row.h_m), row.geometric_m, 0.1) << row.h_m;
    AirData sensor({});
    const auto samples = Fly(sensor, 5, East(100.0, GeometricFromGeopotential(row.h_m)));
    ASSERT_EQ(samples.size(), 4u);
    const AirDataSample& s = samples.back();
    EXPECT_NEAR(s.static_pressure_pa / row.pressure_pa, 1.0, 1e-4) << row.h_m;
    EXPECT_NEAR(s.temperature_k / row.temperature_k, 1.0, 1e-4) << row.h_m;
    EXPECT_NEAR(s.pressure_altitude_m, row.h_m, 0.05) << row.h_m;
    EXPECT_NEAR(s.true_airspeed_m_s, 100.0, 1e-9);
  }
}

// At sea level in the standard atmosphere calibrated airspeed is true
// airspeed, sub- and supersonic; at low speed it is equivalent airspeed,
// TAS sqrt(rho / rho0); at Mach 2 pitot over static is the normal-shock
// table's 5.640.
TEST(AirDataTest, AirspeedsObeyTheirIdentities) {
  for (const double tas : {10.0, 50.0, 200.0, 340.0, 500.0, 680.6}) {
    const AirDataSample s = IdealAirData(Vector3d(tas, 0, 0), 0.0);
    EXPECT_NEAR(s.indicated_airspeed_m_s / tas, 1.0, 1e-9) << tas;
  }
  // (Compressibility makes them differ by (M^2 - Mc^2) / 8: 1.1e-4 at 10 m/s, 1e-6 at 1 m/s.)
  const AirDataSample high = IdealAirData(Vector3d(1.0, 0, 0), 11019.1);
  EXPECT_NEAR(high.indicated_airspeed_m_s / std::sqrt(high.density_kg_m3 / 1.225), 1.0, 1e-5);
  EXPECT_NEAR(ImpactPressure(2.0, 1.0) + 1.0, 5.640, 1e-3);
  for (const double mach : {0.3, 0.99, 1.0, 1.5, 3.0}) {
    EXPECT_NEAR(MachFromImpactRatio(ImpactPressure(mach, 1.0)), mach, 1e-9) << mach;
  }
}

// Air from below gives a positive angle of attack, air from the right a
// positive sideslip (x forward, y left, z up); the wind is subtracted, its
// shear layer linear; Dryden gusts, when declared, move the airspeed and
// repeat with the seed.
TEST(AirDataTest, AnglesAndWindFromTheFlightsGeometry) {
  AirData descending({});
  const auto down =
      Fly(descending, 4, [](double t) { return Vector3d(50.0 * t, 0, 500 - 5.0 * t); });
  EXPECT_NEAR(down.back().angle_of_attack_rad, std::atan2(5.0, 50.0), 1e-9);
  EXPECT_NEAR(down.back().sideslip_rad, 0.0, 1e-12);
  scene::WindSpec wind;
  wind.velocity = Vector3d(10.0, 0.0, 0.0);  // a tailwind
  AirData tail({});
  EXPECT_NEAR(Fly(tail, 4, East(50.0, 300.0), &wind).back().true_airspeed_m_s, 40.0, 1e-9);
  wind.velocity = Vector3d(0.0, 10.0, 0.0);  // blowing north: from the right of an east flight
  AirData cross({});
  const AirDataSample crossed = Fly(cross, 4, East(50.0, 300.0), &wind).back();
  EXPECT_NEAR(crossed.sideslip_rad, std::asin(10.0 / std::sqrt(2600.0)), 1e-9);
  EXPECT_NEAR(crossed.true_airspeed_m_s, std::sqrt(2600.0), 1e-9);
  wind.velocity = Vector3d::Zero();
  wind.shear_velocity = Vector3d(20.0, 0.0, 0.0);
  wind.shear_bottom_m = 1000.0, wind.shear_top_m = 1200.0;
  for (const auto& [z, tas] : {std::pair{900.0, 50.0}, {1100.0, 40.0}, {1300.0, 30.0}}) {
    AirData sheared({});
    EXPECT_NEAR(Fly(sheared, 4, East(50.0, z), &wind).back().true_airspeed_m_s, tas, 1e-9) << z;
  }
  wind.gust_sigma_m_s = 3.0;
  wind.gust_length_m = 100.0;
  AirData gusty({}), again({});
  const auto a = Fly(gusty, 300, East(50.0, 1300.0), &wind);
  const auto b = Fly(again, 300, East(50.0, 1300.0), &wind);
  double spread = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].true_airspeed_m_s, b[i].true_airspeed_m_s) << i;
    spread = std::max(spread, std::abs(a[i].true_airspeed_m_s - 30.0));
  }
  EXPECT_GT(spread, 0.3);
}

// Dryden: each component's standard deviation is sigma, the longitudinal
// autocorrelation at one time scale T = L / V is e^-1 and the lateral's
// (1 - 1/2) e^-1 (MIL-F-8785C's correlation functions), over 10^6 steps.
TEST(AirDataTest, DrydenGustsHaveTheModelsVarianceAndCorrelation) {
  const double sigma = 2.0, length = 50.0, speed = 50.0, dt = 0.01;  // T = 1 s: 100 steps
  DrydenGusts gusts(sigma, length, 3);
  const int n = 1000000, lag = 100;
  std::vector<Vector3d> g(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) g[std::size_t(i)] = gusts.Step(speed, dt);
  for (int axis = 0; axis < 3; ++axis) {
    double sum2 = 0.0, lagged = 0.0;
    for (int i = 0; i < n; ++i) {
      sum2 += g[std::size_t(i)][axis] * g[std::size_t(i)][axis];
      if (i >= lag) lagged += g[std::size_t(i)][axis] * g[std::size_t(i - lag)][axis];
    }
    const double variance = sum2 / n;
    EXPECT_NEAR(std::sqrt(variance) / sigma, 1.0, 0.05) << axis;
    const double expected = axis == 0 ? std::exp(-1.0) : 0.5 * std::exp(-1.0);
    EXPECT_NEAR(lagged / (n - lag) / variance, expected, 0.03) << axis;
  }
}

// Noise per measurement within 3% over 100,000 samples; the computed values
// follow the noisy measurements (pressure altitude from the noisy static
// pressure).
TEST(AirDataTest, NoiseHasTheConfiguredSigmas) {
  AirDataConfig config;
  config.rate_hz = 1000.0;
  config.static_pressure_sigma_pa = 12.0;
  config.impact_pressure_sigma_pa = 5.0;
  config.temperature_sigma_k = 0.5;
  config.angle_sigma_deg = 0.2;
  config.seed = 9;
  AirData sensor(config);
  const auto samples = Fly(sensor, 10001, East(60.0, 2000.0));
  ASSERT_EQ(samples.size(), 100000u);
  const AirDataSample ideal = IdealAirData(Vector3d(60.0, 0, 0), 2000.0);
  auto sigma = [&](auto field, double truth) {
    double sum2 = 0.0;
    for (const AirDataSample& s : samples) sum2 += std::pow(field(s) - truth, 2);
    return std::sqrt(sum2 / double(samples.size()));
  };
  EXPECT_NEAR(
      sigma([](const auto& s) { return s.static_pressure_pa; }, ideal.static_pressure_pa) / 12.0,
      1.0, 0.03);
  EXPECT_NEAR(
      sigma([](const auto& s) { return s.impact_pressure_pa; }, ideal.impact_pressure_pa) / 5.0,
      1.0, 0.03);
  EXPECT_NEAR(sigma([](const auto& s) { return s.temperature_k; }, ideal.temperature_k) / 0.5, 1.0,
              0.03);
  EXPECT_NEAR(sigma([](const auto& s) { return s.angle_of_attack_rad; }, 0.0) / (0.2 * M_PI / 180),
              1.0, 0.03);
  EXPECT_NEAR(sigma([](const auto& s) { return s.sideslip_rad; }, 0.0) / (0.2 * M_PI / 180), 1.0,
              0.03);
  for (std::size_t i = 0; i < samples.size(); i += 9973) {
    EXPECT_NEAR(samples[i].pressure_altitude_m, PressureAltitude(samples[i].static_pressure_pa),
                1e-9);
  }
}

}  // namespace
}  // namespace sandbox::sensors
