#include "bridge/translation.h"

#include <cmath>

#include "scene/geodetic.h"

namespace sandbox::bridge {
namespace {

// World ENU from NED axes, and body FLU from FRD axes (both self-inverse).
const Eigen::Matrix3d kEnuFromNed = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
const Eigen::Matrix3d kFluFromFrd = Eigen::Vector3d(1, -1, -1).asDiagonal();
// Unreal's left-handed axes to right-handed ones: y flips (world and body).
const Eigen::Matrix3d kMirrorY = Eigen::Vector3d(1, -1, 1).asDiagonal();

scene::LocalTangentPlane Plane(const GeodeticOrigin& origin) {
  return scene::LocalTangentPlane({origin.latitude_deg, origin.longitude_deg, origin.altitude_m});
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
      const scene::LocalTangentPlane world = Plane(origin);
      X.translation() = world.ToWorld({position.x(), position.y(), position.z()});
      // Attitude is in the NED frame at the point; the world is ENU at the origin.
      const Eigen::Matrix3d R_EcefLocal = scene::EcefFromEnu(position.x(), position.y());
      X.linear() = world.R_WorldEcef() * R_EcefLocal * kEnuFromNed * R * kFluFromFrd;
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
      const scene::LocalTangentPlane world = Plane(origin);
      const scene::GeodeticPoint point = world.ToGeodetic(X_WB.translation());
      *position = {point.latitude_deg, point.longitude_deg, point.height_m};
      const Eigen::Matrix3d R_EcefLocal = scene::EcefFromEnu(position->x(), position->y());
      *q = Eigen::Quaterniond(kEnuFromNed * R_EcefLocal.transpose() *
                              world.R_WorldEcef().transpose() * R * kFluFromFrd);
      break;
    }
  }
}

std::string GeodeticProblem(double latitude_deg, double longitude_deg, double altitude_m) {
  if (!(std::abs(latitude_deg) <= 90.0)) return "latitude beyond +-90 deg";
  if (!(std::abs(longitude_deg) <= 360.0)) return "longitude beyond +-360 deg";
  if (!(altitude_m >= kMinAltitude_m && altitude_m <= kMaxAltitude_m)) {
    return "altitude outside -12 km to 1e8 m";
  }
  return "";
}

std::string PositionProblem(const Translation& translation, const Eigen::Vector3d& position) {
  if (translation.convention != Convention::kGeodetic) return "";
  return GeodeticProblem(position.x(), position.y(), position.z());
}

}  // namespace sandbox::bridge
