#include "bridge/translation.h"

#include <cmath>

namespace sandbox::bridge {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kWgs84A = 6378137.0;
constexpr double kWgs84F = 1.0 / 298.257223563;
constexpr double kWgs84E2 = kWgs84F * (2.0 - kWgs84F);

// World ENU from NED axes, and body FLU from FRD axes (both self-inverse).
const Eigen::Matrix3d kEnuFromNed = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
const Eigen::Matrix3d kFluFromFrd = Eigen::Vector3d(1, -1, -1).asDiagonal();
// Unreal's left-handed axes to right-handed ones: y flips (world and body).
const Eigen::Matrix3d kMirrorY = Eigen::Vector3d(1, -1, 1).asDiagonal();

// ENU axes at a geodetic point, as columns in ECEF.
Eigen::Matrix3d EcefFromEnu(double latitude_deg, double longitude_deg) {
  const double lat = latitude_deg * kDeg, lon = longitude_deg * kDeg;
  Eigen::Matrix3d R;
  R.col(0) << -std::sin(lon), std::cos(lon), 0.0;
  R.col(1) << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat);
  R.col(2) << std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return R;
}

}  // namespace

std::optional<Convention> ParseConvention(const std::string& text) {
  if (text == "enu") return Convention::kEnu;
  if (text == "ned") return Convention::kNed;
  if (text == "unreal") return Convention::kUnreal;
  if (text == "geodetic") return Convention::kGeodetic;
  return std::nullopt;
}

Eigen::Quaterniond NedAttitude(double roll_rad, double pitch_rad, double yaw_rad) {
  return Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX());
}

Eigen::Vector3d GeodeticToEcef(double latitude_deg, double longitude_deg, double altitude_m) {
  const double lat = latitude_deg * kDeg, lon = longitude_deg * kDeg;
  const double N = kWgs84A / std::sqrt(1.0 - kWgs84E2 * std::sin(lat) * std::sin(lat));
  return {(N + altitude_m) * std::cos(lat) * std::cos(lon),
          (N + altitude_m) * std::cos(lat) * std::sin(lon),
          (N * (1.0 - kWgs84E2) + altitude_m) * std::sin(lat)};
}

Eigen::Vector3d EcefToGeodetic(const Eigen::Vector3d& p) {
  // Bowring's method, refined by iteration: converges to well under a millimetre.
  const double lon = std::atan2(p.y(), p.x());
  const double r = std::hypot(p.x(), p.y());
  double lat = std::atan2(p.z(), r * (1.0 - kWgs84E2));
  double altitude = 0.0;
  for (int i = 0; i < 10; ++i) {
    const double N = kWgs84A / std::sqrt(1.0 - kWgs84E2 * std::sin(lat) * std::sin(lat));
    altitude = r / std::cos(lat) - N;
    lat = std::atan2(p.z(), r * (1.0 - kWgs84E2 * N / (N + altitude)));
  }
  return {lat / kDeg, lon / kDeg, altitude};
}

Eigen::Isometry3d Translation::ToWorld(const Eigen::Vector3d& position,
                                       const Eigen::Quaterniond& q) const {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  switch (convention) {
    case Convention::kEnu:
      X.translation() = position;
      X.linear() = R;
      break;
    case Convention::kNed:
      X.translation() = kEnuFromNed * position;
      X.linear() = kEnuFromNed * R * kFluFromFrd;
      break;
    case Convention::kUnreal:
      X.translation() = kMirrorY * position / 100.0;
      X.linear() = kMirrorY * R * kMirrorY;
      break;
    case Convention::kGeodetic: {
      const Eigen::Vector3d p_ecef = GeodeticToEcef(position.x(), position.y(), position.z());
      const Eigen::Vector3d o_ecef =
          GeodeticToEcef(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
      const Eigen::Matrix3d R_EcefWorld = EcefFromEnu(origin.latitude_deg, origin.longitude_deg);
      X.translation() = R_EcefWorld.transpose() * (p_ecef - o_ecef);
      // Attitude is in the NED frame at the point; the world is ENU at the origin.
      const Eigen::Matrix3d R_EcefLocal = EcefFromEnu(position.x(), position.y());
      X.linear() = R_EcefWorld.transpose() * R_EcefLocal * kEnuFromNed * R * kFluFromFrd;
      break;
    }
  }
  return X;
}

void Translation::FromWorld(const Eigen::Isometry3d& X_WB, Eigen::Vector3d* position,
                            Eigen::Quaterniond* q) const {
  const Eigen::Matrix3d R = X_WB.linear();
  switch (convention) {
    case Convention::kEnu:
      *position = X_WB.translation();
      *q = Eigen::Quaterniond(R);
      break;
    case Convention::kNed:
      *position = kEnuFromNed * X_WB.translation();
      *q = Eigen::Quaterniond(kEnuFromNed * R * kFluFromFrd);
      break;
    case Convention::kUnreal:
      *position = 100.0 * (kMirrorY * X_WB.translation());
      *q = Eigen::Quaterniond(kMirrorY * R * kMirrorY);
      break;
    case Convention::kGeodetic: {
      const Eigen::Matrix3d R_EcefWorld = EcefFromEnu(origin.latitude_deg, origin.longitude_deg);
      const Eigen::Vector3d o_ecef =
          GeodeticToEcef(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
      *position = EcefToGeodetic(o_ecef + R_EcefWorld * X_WB.translation());
      const Eigen::Matrix3d R_EcefLocal = EcefFromEnu(position->x(), position->y());
      *q =
          Eigen::Quaterniond(kEnuFromNed * R_EcefLocal.transpose() * R_EcefWorld * R * kFluFromFrd);
      break;
    }
  }
}

}  // namespace sandbox::bridge
