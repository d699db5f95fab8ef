#include "sensors/normal_gravity.h"

#include <cmath>

namespace sandbox::sensors {
namespace {

// WGS84 defining and derived constants (TR8350.2 tables 3.1 to 3.3).
constexpr double kA = 6378137.0;                   // semi-major axis, m
constexpr double kF = 1.0 / 298.257223563;         // flattening
constexpr double kGammaEquator = 9.7803253359;     // normal gravity at the equator
constexpr double kSomiglianaK = 0.00193185265241;  // (b gamma_p) / (a gamma_e) - 1
constexpr double kE2 = 6.69437999014e-3;           // first eccentricity squared
constexpr double kM = 0.00344978650684;            // omega^2 a^2 b / GM
constexpr double kDegree = 3.14159265358979323846 / 180.0;

}  // namespace

double NormalGravity(double latitude_deg, double height_m) {
  const double s2 = std::pow(std::sin(latitude_deg * kDegree), 2);
  const double surface = kGammaEquator * (1.0 + kSomiglianaK * s2) / std::sqrt(1.0 - kE2 * s2);
  return surface * (1.0 - 2.0 / kA * (1.0 + kF + kM - 2.0 * kF * s2) * height_m +
                    3.0 / (kA * kA) * height_m * height_m);
}

Eigen::Vector3d GravityInWorld(const scene::LocalTangentPlane& frame, const Eigen::Vector3d& p_W) {
  const scene::GeodeticPoint point = frame.ToGeodetic(p_W);
  const Eigen::Vector3d up_ecef =
      scene::EcefFromEnu(point.latitude_deg, point.longitude_deg).col(2);
  return -NormalGravity(point.latitude_deg, point.height_m) * (frame.R_WorldEcef() * up_ecef);
}

}  // namespace sandbox::sensors
