#pragma once
// WGS84 normal gravity (NIMA TR8350.2, section 4): the gravity (gravitation
// and the Earth's centrifugal acceleration) of the reference ellipsoid, along
// its normal. What an accelerometer at rest measures, up to the local anomaly.

#include <Eigen/Core>

#include "scene/geodetic.h"

namespace sandbox::sensors {

// Somigliana's formula on the ellipsoid, with the second-order correction for
// the height above it (TR8350.2 eq. 4-1 and 4-3), m/s^2.
double NormalGravity(double latitude_deg, double height_m);

// Gravity in the world frame of `frame` at world point p_W: NormalGravity
// along the ellipsoid normal there, pointing down it.
Eigen::Vector3d GravityInWorld(const scene::LocalTangentPlane& frame, const Eigen::Vector3d& p_W);

}  // namespace sandbox::sensors
