#include "sensors/render/shadow_cascades.h"

#include <algorithm>
#include <cmath>

namespace sandbox::render {

namespace {

// Light axes (rows): x and y across the map, z towards the sun.
Eigen::Matrix3d SunAxes(const Eigen::Vector3d& sun_W) {
  const Eigen::Vector3d z = sun_W.normalized();
  const Eigen::Vector3d x =
      (std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX())
          .cross(z)
          .normalized();
  Eigen::Matrix3d R_LW;
  R_LW.row(0) = x;
  R_LW.row(1) = z.cross(x);
  R_LW.row(2) = z;
  return R_LW;
}

// Camera-centred world to the clip space of the box centred at centre_L (light
// axes) with half size r across and depth from `top` to `bottom` along the sun.
Eigen::Matrix4d LightClip(const Eigen::Matrix3d& R_LW, const Eigen::Vector3d& centre_L, double r,
                          double top, double bottom) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  M.block<1, 3>(0, 0) = R_LW.row(0) / r;
  M(0, 3) = -centre_L.x() / r;
  M.block<1, 3>(1, 0) = R_LW.row(1) / r;
  M(1, 3) = -centre_L.y() / r;
  M.block<1, 3>(2, 0) = -R_LW.row(2) / (top - bottom);
  M(2, 3) = top / (top - bottom);
  M(3, 3) = 1.0;
  return M;
}

}  // namespace

ShadowCascade FitCasterShadow(const Eigen::Vector3d& centre_C, double radius_m,
                              const Eigen::Vector3d& sun_W, int map_px) {
  const Eigen::Matrix3d R_LW = SunAxes(sun_W);
  const Eigen::Vector3d centre_L = R_LW * centre_C;
  ShadowCascade box;
  box.light_clip =
      LightClip(R_LW, centre_L, radius_m, centre_L.z() + radius_m, centre_L.z() - radius_m);
  box.texel_m = 2.0 * radius_m / map_px;
  box.half_size_m = radius_m;
  return box;
}

std::vector<ShadowCascade> FitShadowCascades(const CameraView& view, const Eigen::Vector3d& sun_W,
                                             double distance_m, int count, int map_px,
                                             double caster_reach_m) {
  const Eigen::Matrix3d R_LW = SunAxes(sun_W);
  const double near = view.near_m, far = std::max(distance_m, 2.0 * near);
  const double ty = std::tan(0.5 * view.fov_y_rad), tx = ty * view.width / view.height;
  const Eigen::Matrix3d R_WC = view.X_WC.linear();
  const Eigen::Vector3d camera_L = R_LW * view.X_WC.translation();
  std::vector<ShadowCascade> cascades;
  double d0 = near;
  for (int i = 1; i <= count; ++i) {
    // Split between logarithmic and uniform spacing.
    const double f = double(i) / count;
    const double d1 = 0.75 * near * std::pow(far / near, f) + 0.25 * (near + (far - near) * f);
    Eigen::Vector3d corners[8];
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < 8; ++k) {
      const double d = k < 4 ? d0 : d1;
      corners[k] = R_WC * Eigen::Vector3d(d, (k & 1 ? 1 : -1) * tx * d, (k & 2 ? 1 : -1) * ty * d);
      centre += corners[k] / 8.0;
    }
    double radius = 0.0;
    for (const Eigen::Vector3d& c : corners) radius = std::max(radius, (c - centre).norm());
    radius = std::ceil(radius * 16.0) / 16.0;  // a size that changes in steps: steady texels
    // The box's half size r: the slice's sphere plus half a step of the
    // centre (a step is r / 4, px / 8 whole texels).
    const double r = radius * 16.0 / 15.0, step = r / 8.0;
    const double texel = 2.0 * r / map_px;
    // Snap the box centre to whole steps in absolute light coordinates.
    Eigen::Vector3d centre_L = R_LW * centre + camera_L;
    std::array<std::int64_t, 3> cell;
    for (int k = 0; k < 3; ++k) {
      cell[std::size_t(k)] = std::llround(centre_L[k] / step);
      centre_L[k] = double(cell[std::size_t(k)]) * step;
    }
    centre_L -= camera_L;
    const double top = centre_L.z() + r + caster_reach_m, bottom = centre_L.z() - r;
    cascades.push_back({LightClip(R_LW, centre_L, r, top, bottom), d1, texel, cell, r});
    d0 = d1;
  }
  return cascades;
}

}  // namespace sandbox::render
