#pragma once
// The analytic terrain of the bundled sample level. The generator samples it
// on a grid; tests compare ray hits against it, independently of the loader.

#include <cmath>

namespace sandbox::assets::sample {

constexpr double kTerrainHalfSize_m = 200.0;  // x and y in [-200, 200]
constexpr double kTerrainSpacing_m = 2.0;
constexpr int kTerrainPoints = 201;  // per side
constexpr double kWaterLevel_m = 6.0;

// Height of the terrain surface above world z = 0, in metres: rolling ground
// around 14 m, a hill of about 50 m in the north-east, a lake bed below the
// water level in the south-west.
inline double TerrainHeight(double x_m, double y_m) {
  const double hill = (x_m - 110.0) * (x_m - 110.0) + (y_m - 90.0) * (y_m - 90.0);
  const double lake = (x_m + 70.0) * (x_m + 70.0) + (y_m + 60.0) * (y_m + 60.0);
  return 14.0 + 6.0 * std::sin(x_m / 31.0) * std::cos(y_m / 43.0) +
         4.0 * std::sin((x_m - 0.5 * y_m) / 57.0) + 30.0 * std::exp(-hill / (2.0 * 40.0 * 40.0)) -
         14.0 * std::exp(-lake / (2.0 * 45.0 * 45.0));
}

// The grid: point (col, row) is at x = -200 + 2 col, y = 200 - 2 row, with
// z = TerrainHeight(x, y) rounded to float. Each cell is split along its
// south-west to north-east diagonal.
inline double GridX(int col) { return -kTerrainHalfSize_m + kTerrainSpacing_m * col; }
inline double GridY(int row) { return kTerrainHalfSize_m - kTerrainSpacing_m * row; }

}  // namespace sandbox::assets::sample
