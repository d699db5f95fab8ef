#include "scene/geodetic.h"

#include <cmath>

namespace sandbox::scene {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kWgs84A = 6378137.0;
constexpr double kWgs84F = 1.0 / 298.257223563;
constexpr double kWgs84E2 = kWgs84F * (2.0 - kWgs84F);

}  // namespace

Eigen::Vector3d GeodeticToEcef(const GeodeticPoint& point) {
  const double lat = point.latitude_deg * kDeg, lon = point.longitude_deg * kDeg;
  const double N = kWgs84A / std::sqrt(1.0 - kWgs84E2 * std::sin(lat) * std::sin(lat));
  return {(N + point.height_m) * std::cos(lat) * std::cos(lon),
          (N + point.height_m) * std::cos(lat) * std::sin(lon),
          (N * (1.0 - kWgs84E2) + point.height_m) * std::sin(lat)};
}

GeodeticPoint EcefToGeodetic(const Eigen::Vector3d& p) {
  // Bowring's method, refined by iteration: converges to well under a millimetre.
  const double lon = std::atan2(p.y(), p.x());
  const double r = std::hypot(p.x(), p.y());
  double lat = std::atan2(p.z(), r * (1.0 - kWgs84E2));
  double height = 0.0;
  for (int i = 0; i < 10; ++i) {
    const double N = kWgs84A / std::sqrt(1.0 - kWgs84E2 * std::sin(lat) * std::sin(lat));
    height = r / std::cos(lat) - N;
    lat = std::atan2(p.z(), r * (1.0 - kWgs84E2 * N / (N + height)));
  }
  return {lat / kDeg, lon / kDeg, height};
}

Eigen::Matrix3d EcefFromEnu(double latitude_deg, double longitude_deg) {
  const double lat = latitude_deg * kDeg, lon = longitude_deg * kDeg;
  Eigen::Matrix3d R;
  R.col(0) << -std::sin(lon), std::cos(lon), 0.0;
  R.col(1) << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat);
  R.col(2) << std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return R;
}

LocalTangentPlane::LocalTangentPlane(const GeodeticPoint& anchor)
    : anchor_(anchor),
      anchor_ecef_(GeodeticToEcef(anchor)),
      R_WorldEcef_(EcefFromEnu(anchor.latitude_deg, anchor.longitude_deg).transpose()) {}

Eigen::Vector3d LocalTangentPlane::ToWorld(const GeodeticPoint& point) const {
  return R_WorldEcef_ * (GeodeticToEcef(point) - anchor_ecef_);
}

GeodeticPoint LocalTangentPlane::ToGeodetic(const Eigen::Vector3d& p_W) const {
  return EcefToGeodetic(anchor_ecef_ + R_WorldEcef_.transpose() * p_W);
}

}  // namespace sandbox::scene
