// The standard atmosphere against the published ICAO / U.S. 1976 table (its
// values typed in here, not computed), and its inverse, the pressure altitude.

#include "sensors/standard_atmosphere.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sandbox::sensors {
namespace {

struct Row {
  double geopotential_m, pressure_pa, temperature_k;
};

// ICAO Doc 7488 / U.S. Standard Atmosphere 1976: the layers' bases and 5 km.
constexpr Row kTable[] = {
    {0.0, 101325.0, 288.15},   {5000.0, 54019.9, 255.65},  {11000.0, 22632.1, 216.65},
    {20000.0, 5474.89, 216.65}, {32000.0, 868.019, 228.65}, {47000.0, 110.906, 270.65},
    {51000.0, 66.9389, 270.65}, {71000.0, 3.95642, 214.65},
};

TEST(StandardAtmosphereTest, MatchesThePublishedTableToAHundredthOfAPercent) {
  for (const Row& row : kTable) {
    const AtmosphereState state = StandardAtmosphere(row.geopotential_m);
    EXPECT_NEAR(state.pressure_pa, row.pressure_pa, 1e-4 * row.pressure_pa) << row.geopotential_m;
    EXPECT_NEAR(state.temperature_k, row.temperature_k, 1e-4 * row.temperature_k)
        << row.geopotential_m;
  }
  const AtmosphereState sea = StandardAtmosphere(0.0);
  EXPECT_NEAR(sea.density_kg_m3, 1.2250, 1e-4 * 1.2250);
  EXPECT_NEAR(sea.speed_of_sound_m_s, 340.294, 1e-4 * 340.294);
  EXPECT_NEAR(StandardAtmosphere(11000.0).density_kg_m3, 0.363918, 1e-4 * 0.363918);
}

TEST(StandardAtmosphereTest, GeometricAndGeopotentialAltitudesAsTheTableHasThem) {
  // The table's top: 86 km geometric is 84.852 km geopotential; its 11 km
  // tropopause (geopotential) is 11.019 km geometric.
  EXPECT_NEAR(GeopotentialFromGeometric(86000.0), 84852.0, 0.5);
  EXPECT_NEAR(GeometricFromGeopotential(11000.0), 11019.1, 0.05);
  for (double z = -5000.0; z <= 86000.0; z += 1000.0) {
    EXPECT_NEAR(GeometricFromGeopotential(GeopotentialFromGeometric(z)), z, 1e-8);
    EXPECT_LE(GeopotentialFromGeometric(z), z);
  }
}

TEST(StandardAtmosphereTest, PressureAltitudeIsTheAltitudeOfThatPressure) {
  EXPECT_NEAR(PressureAltitude(101325.0), 0.0, 1e-9);
  for (const Row& row : kTable) {
    EXPECT_NEAR(PressureAltitude(row.pressure_pa), row.geopotential_m, 1.0) << row.pressure_pa;
  }
  for (double h = -5000.0; h <= 84852.0; h += 250.0) {
    EXPECT_NEAR(PressureAltitude(StandardAtmosphere(h).pressure_pa), h, 1e-6) << h;
  }
  // Continuous across the layers' bases; monotonic throughout.
  double last = StandardAtmosphere(-5000.0).pressure_pa;
  for (double h = -4999.0; h <= 84852.0; h += 1.0) {
    const double p = StandardAtmosphere(h).pressure_pa;
    ASSERT_LT(p, last) << h;
    ASSERT_GT(p, last * 0.999) << h;
    last = p;
  }
}

TEST(StandardAtmosphereTest, OutsideTheModelIsItsBottomOrTop) {
  EXPECT_EQ(StandardAtmosphere(-9000.0).pressure_pa, StandardAtmosphere(-5000.0).pressure_pa);
  EXPECT_EQ(StandardAtmosphere(1e6).temperature_k, StandardAtmosphere(84852.0).temperature_k);
  EXPECT_EQ(PressureAltitude(2e5), -5000.0);
  EXPECT_EQ(PressureAltitude(0.0), 84852.0);
  EXPECT_EQ(PressureAltitude(std::nan("")), -5000.0);
}

}  // namespace
}  // namespace sandbox::sensors
