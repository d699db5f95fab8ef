#pragma once
// The ICAO standard atmosphere (ICAO Doc 7488, ISO 2533; the same as the U.S.
// Standard Atmosphere 1976 up to 86 km geometric): temperature, pressure,
// density and the speed of sound at a geopotential altitude, from its seven
// layers of constant temperature gradient. The layers' base pressures are
// integrated from the sea level's here, not copied from a table; the tests
// hold them against the published table. For the air data instruments.

namespace sandbox::sensors {

struct AtmosphereState {
  double temperature_k{0.0};
  double pressure_pa{0.0};
  double density_kg_m3{0.0};
  double speed_of_sound_m_s{0.0};
};

namespace standard_atmosphere {

inline constexpr double kSeaLevelPressurePa = 101325.0;
inline constexpr double kSeaLevelTemperatureK = 288.15;
inline constexpr double kStandardGravity = 9.80665;       // m/s^2, g0
inline constexpr double kGasConstantAir = 287.05287;      // J/(kg K), R
inline constexpr double kHeatCapacityRatio = 1.4;         // gamma
inline constexpr double kEarthRadiusM = 6356766.0;        // r0 of the geopotential
inline constexpr double kTopGeopotentialM = 84852.0;      // the model's top (86 km geometric)
inline constexpr double kBottomGeopotentialM = -5000.0;   // and its bottom, as ISO 2533's table

}  // namespace standard_atmosphere

// Geopotential altitude H (m') of a geometric height z above mean sea level:
// H = r0 z / (r0 + z), r0 = 6,356,766 m; and back.
double GeopotentialFromGeometric(double z_m);
double GeometricFromGeopotential(double h_m);

// The atmosphere at geopotential altitude `h_m`, clamped to the model's range
// (-5 km to 84.852 km).
AtmosphereState StandardAtmosphere(double h_m);

// The geopotential altitude at which the standard atmosphere has this static
// pressure: the barometric (pressure) altitude an altimeter set to 1013.25 hPa
// shows. Pressures outside the model's range give its bottom or top.
double PressureAltitude(double pressure_pa);

}  // namespace sandbox::sensors
