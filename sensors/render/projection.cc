#include "sensors/render/projection.h"

#include <cmath>

namespace sandbox::render {

Eigen::Matrix4d ViewRotation(const Eigen::Isometry3d& X_WC) {
  Eigen::Matrix3d R_EyeCam;
  R_EyeCam << 0, -1, 0, 0, 0, 1, -1, 0, 0;  // camera x forward, y left, z up -> GL eye
  Eigen::Matrix4d view_rotation = Eigen::Matrix4d::Identity();
  view_rotation.topLeftCorner<3, 3>() = R_EyeCam * X_WC.linear().transpose();
  return view_rotation;
}

Eigen::Matrix4d ReversedDepthProjection(const CameraView& view) {
  const double f = 1.0 / std::tan(0.5 * view.fov_y_rad), aspect = double(view.width) / view.height;
  const double n = view.near_m, fa = view.far_m;
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  projection(0, 0) = f / aspect;
  projection(1, 1) = f;
  projection(2, 2) = n / (fa - n);
  projection(2, 3) = fa * n / (fa - n);
  projection(3, 2) = -1.0;
  return projection;
}

double NearReach(const CameraView& view) {
  const double f = 1.0 / std::tan(0.5 * view.fov_y_rad), aspect = double(view.width) / view.height;
  return view.near_m * std::sqrt(1.0 + (1.0 + aspect * aspect) / (f * f));
}

float PixelAngle(const CameraView& view) {
  return float(2.0 * std::tan(0.5 * view.fov_y_rad) / view.height);
}

bool InFrustum(const Eigen::Matrix4f& M, const Eigen::AlignedBox3f& box) {
  for (int plane = 0; plane < 6; ++plane) {
    const Eigen::Vector4f p = M.row(3) + (plane % 2 == 0 ? 1.f : -1.f) * M.row(plane / 2);
    // The box corner furthest along the plane's normal.
    const Eigen::Vector3f corner(p.x() >= 0 ? box.max().x() : box.min().x(),
                                 p.y() >= 0 ? box.max().y() : box.min().y(),
                                 p.z() >= 0 ? box.max().z() : box.min().z());
    if (p.head<3>().dot(corner) + p.w() < 0.f) return false;
  }
  return true;
}

Eigen::Matrix4f Relative(const Eigen::Affine3d& X, const Eigen::Vector3d& camera) {
  Eigen::Affine3d rel = X;
  rel.translation() -= camera;
  return rel.matrix().cast<float>();
}

}  // namespace sandbox::render
