#pragma once
// The air's motion a level declares ([wind]), for the air data instruments.

#include <Eigen/Core>
#include <cstdint>

namespace sandbox::scene {

// The [wind] table: how the air moves, for the air data instruments. The air's
// velocity (where it goes, world frame) is `velocity` at and below
// shear_bottom_m (world z), `shear_velocity` at and above shear_top_m, linear
// between; with gust_sigma_m_s, Dryden turbulence on top (sensors/wind_field.h).
struct WindSpec {
  Eigen::Vector3d velocity{Eigen::Vector3d::Zero()};        // m/s
  Eigen::Vector3d shear_velocity{Eigen::Vector3d::Zero()};  // m/s; without a layer: velocity
  double shear_bottom_m{0.0};
  double shear_top_m{0.0};  // bottom == top: no layer
  double gust_sigma_m_s{0.0};   // the gusts' intensity per axis; 0: none
  double gust_length_m{533.4};  // their scale length (MIL-F-8785C: 1750 ft above 2000 ft)
  std::int64_t seed{0};

  // The mean wind (without gusts) at world height z.
  Eigen::Vector3d At(double z_m) const {
    if (!(shear_top_m > shear_bottom_m) || z_m <= shear_bottom_m) return velocity;
    if (z_m >= shear_top_m) return shear_velocity;
    const double s = (z_m - shear_bottom_m) / (shear_top_m - shear_bottom_m);
    return (1.0 - s) * velocity + s * shear_velocity;
  }
};

}  // namespace sandbox::scene
