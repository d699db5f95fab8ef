#pragma once
// Coordinate and unit translation at the middleware edge: external publishers
// speak their own conventions, the sandbox's world is right-handed ENU, metres,
// with robot bodies x forward, y left, z up (../shared/DESIGN.md).

#include <Eigen/Geometry>
#include <optional>
#include <string>

namespace sandbox::bridge {

enum class Convention {
  kEnu,       // the world frame itself: x east, y north, z up, metres; body x fwd, y left, z up
  kNed,       // aerospace: x north, y east, z down, metres; body x fwd, y right, z down
  kUnreal,    // left-handed: x forward, y right, z up, centimetres, on world and body alike
  kGeodetic,  // latitude, longitude (degrees), altitude (metres, WGS84); attitude in local NED
};

// Parses "enu", "ned", "unreal", "geodetic"; nullopt otherwise.
std::optional<Convention> ParseConvention(const std::string& text);

// The WGS84 point the local tangent plane (world ENU) is centred on.
struct GeodeticOrigin {
  double latitude_deg{0.0};
  double longitude_deg{0.0};
  double altitude_m{0.0};
};

struct Translation {
  Convention convention{Convention::kEnu};
  GeodeticOrigin origin;  // for kGeodetic

  // A pose given in this convention as the world pose X_WB of a robot body.
  // `position` is (x, y, z) in the convention, or (lat_deg, lon_deg, alt_m)
  // for kGeodetic; `q` is the body's attitude (w, x, y, z) in the convention's
  // frame (local NED for kGeodetic). Geodetic points go through
  // scene/geodetic.h, as the terrain loader's do.
  Eigen::Isometry3d ToWorld(const Eigen::Vector3d& position, const Eigen::Quaterniond& q) const;
  // The inverse: a world pose as the convention's position and attitude.
  void FromWorld(const Eigen::Isometry3d& X_WB, Eigen::Vector3d* position,
                 Eigen::Quaterniond* q) const;
};

// Why a geodetic position cannot be a robot's (a latitude beyond +-90, a
// longitude beyond +-360, a height below the deepest trench or beyond
// geostationary orbit: kMinAltitude_m to kMaxAltitude_m), or "".
inline constexpr double kMinAltitude_m = -12000.0;
inline constexpr double kMaxAltitude_m = 1e8;
std::string GeodeticProblem(double latitude_deg, double longitude_deg, double altitude_m);
// The position of `translation` (only kGeodetic has limits), as above.
std::string PositionProblem(const Translation& translation, const Eigen::Vector3d& position);

// Aerospace attitude: R = Rz(yaw) Ry(pitch) Rx(roll) of body FRD in NED, radians.
Eigen::Quaterniond NedAttitude(double roll_rad, double pitch_rad, double yaw_rad);

}  // namespace sandbox::bridge
