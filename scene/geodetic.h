#pragma once
// WGS84 geodesy for the world frame: the world is the local tangent plane
// (east, north, up; metres) at a geodetic anchor. The bridge's geodetic pose
// convention and the terrain loader both go through these functions, so a pose
// given in latitude, longitude and altitude lands on the terrain where the
// elevation raster says.

#include <Eigen/Geometry>

namespace sandbox::scene {

// A WGS84 point: latitude and longitude in degrees, height above the ellipsoid in metres.
struct GeodeticPoint {
  double latitude_deg{0.0};
  double longitude_deg{0.0};
  double height_m{0.0};
};

// WGS84 geodetic to earth-centred earth-fixed metres, and back (the inverse
// is iterated to well under a millimetre).
Eigen::Vector3d GeodeticToEcef(const GeodeticPoint& point);
GeodeticPoint EcefToGeodetic(const Eigen::Vector3d& p_ecef);

// The east, north and up axes at a geodetic point, as columns in ECEF.
Eigen::Matrix3d EcefFromEnu(double latitude_deg, double longitude_deg);

// The world frame: the tangent plane (ENU) at `anchor`, the world origin.
class LocalTangentPlane {
 public:
  explicit LocalTangentPlane(const GeodeticPoint& anchor = {});
  const GeodeticPoint& anchor() const { return anchor_; }
  Eigen::Vector3d ToWorld(const GeodeticPoint& point) const;
  GeodeticPoint ToGeodetic(const Eigen::Vector3d& p_W) const;
  // World from ECEF rotation (rows: east, north, up at the anchor).
  const Eigen::Matrix3d& R_WorldEcef() const { return R_WorldEcef_; }

 private:
  GeodeticPoint anchor_;
  Eigen::Vector3d anchor_ecef_;
  Eigen::Matrix3d R_WorldEcef_;
};

// Mean Earth radius (m), for horizon distances.
constexpr double kEarthRadius_m = 6371008.8;

}  // namespace sandbox::scene
