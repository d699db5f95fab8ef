#include "sensors/standard_atmosphere.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace sandbox::sensors {
namespace {

using namespace standard_atmosphere;

// A layer: its base geopotential altitude and temperature gradient (K/m').
struct Layer {
  double base_m;
  double gradient_k_m;
};
constexpr std::array<Layer, 7> kLayers{{{0.0, -0.0065},
                                        {11000.0, 0.0},
                                        {20000.0, 0.001},
                                        {32000.0, 0.0028},
                                        {47000.0, 0.0},
                                        {51000.0, -0.0028},
                                        {71000.0, -0.002}}};

// Temperature and pressure at `h_m` within the layer whose base is at
// (base temperature, base pressure).
void WithinLayer(const Layer& layer, double base_t, double base_p, double h_m, double* t,
                 double* p) {
  const double dh = h_m - layer.base_m;
  if (layer.gradient_k_m == 0.0) {
    *t = base_t;
    *p = base_p * std::exp(-kStandardGravity * dh / (kGasConstantAir * base_t));
  } else {
    *t = base_t + layer.gradient_k_m * dh;
    *p = base_p *
         std::pow(*t / base_t, -kStandardGravity / (kGasConstantAir * layer.gradient_k_m));
  }
}

// Each layer's base temperature and pressure, from the sea level's upwards.
struct Bases {
  std::array<double, kLayers.size()> temperature_k, pressure_pa;
  Bases() {
    temperature_k[0] = kSeaLevelTemperatureK;
    pressure_pa[0] = kSeaLevelPressurePa;
    for (std::size_t i = 1; i < kLayers.size(); ++i) {
      WithinLayer(kLayers[i - 1], temperature_k[i - 1], pressure_pa[i - 1], kLayers[i].base_m,
                  &temperature_k[i], &pressure_pa[i]);
    }
  }
};
const Bases& LayerBases() {
  static const Bases bases;
  return bases;
}

std::size_t LayerOf(double h_m) {
  std::size_t i = 0;
  while (i + 1 < kLayers.size() && h_m >= kLayers[i + 1].base_m) ++i;
  return i;
}

}  // namespace

double GeopotentialFromGeometric(double z_m) { return kEarthRadiusM * z_m / (kEarthRadiusM + z_m); }

double GeometricFromGeopotential(double h_m) { return kEarthRadiusM * h_m / (kEarthRadiusM - h_m); }

AtmosphereState StandardAtmosphere(double h_m) {
  h_m = std::clamp(h_m, kBottomGeopotentialM, kTopGeopotentialM);
  const std::size_t i = LayerOf(h_m);
  AtmosphereState state;
  WithinLayer(kLayers[i], LayerBases().temperature_k[i], LayerBases().pressure_pa[i], h_m,
              &state.temperature_k, &state.pressure_pa);
  state.density_kg_m3 = state.pressure_pa / (kGasConstantAir * state.temperature_k);
  state.speed_of_sound_m_s =
      std::sqrt(kHeatCapacityRatio * kGasConstantAir * state.temperature_k);
  return state;
}

double PressureAltitude(double pressure_pa) {
  const Bases& bases = LayerBases();
  if (!(pressure_pa < StandardAtmosphere(kBottomGeopotentialM).pressure_pa)) {
    return kBottomGeopotentialM;
  }
  if (!(pressure_pa > StandardAtmosphere(kTopGeopotentialM).pressure_pa)) {
    return kTopGeopotentialM;
  }
  std::size_t i = 0;  // the layer whose base pressure is the first at or above it
  while (i + 1 < kLayers.size() && pressure_pa <= bases.pressure_pa[i + 1]) ++i;
  const Layer& layer = kLayers[i];
  const double t0 = bases.temperature_k[i], p0 = bases.pressure_pa[i];
  if (layer.gradient_k_m == 0.0) {
    return layer.base_m - kGasConstantAir * t0 / kStandardGravity * std::log(pressure_pa / p0);
  }
  const double exponent = -kGasConstantAir * layer.gradient_k_m / kStandardGravity;
  return layer.base_m + t0 / layer.gradient_k_m * (std::pow(pressure_pa / p0, exponent) - 1.0);
}

}  // namespace sandbox::sensors
