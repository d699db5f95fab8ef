#pragma once
// The camera's projection, without GL: the renderer draws a camera-centred
// world (positions relative to the camera in double, then float), with the
// view's rotation alone and reversed depth (1 at the near plane, 0 at the far
// one: with a float depth buffer, even precision from 0.1 m to hundreds of
// kilometres). Clip space as glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE).

#include <Eigen/Geometry>
#include <limits>

#include "sensors/render/view.h"

namespace sandbox::render {

// Camera-centred world to GL eye space: the view's rotation alone (camera x
// forward, y left, z up; the eye looks along -z with y up).
Eigen::Matrix4d ViewRotation(const Eigen::Isometry3d& X_WC);

// GL eye space to clip space, reversed depth: depth 1 at `near_m`, 0 at `far_m`.
Eigen::Matrix4d ReversedDepthProjection(const CameraView& view);

// The distance from the eye to the near plane's corners.
double NearReach(const CameraView& view);

// The angle one pixel spans at the image's centre (radians, small angles).
float PixelAngle(const CameraView& view);

// Reversed depth-buffer values to distances along the optical axis:
// n f / (d (f - n) + n); 0 (nothing drawn) is infinity. Inline: read-back
// converts every pixel of a depth image.
class ReversedDepth {
 public:
  ReversedDepth(double near_m, double far_m)
      : scale_(float(far_m - near_m)), numerator_(float(near_m * far_m)), near_(float(near_m)) {}
  float Metres(float depth) const {
    return depth <= 0.f ? std::numeric_limits<float>::infinity()
                        : numerator_ / (depth * scale_ + near_);
  }

 private:
  float scale_, numerator_, near_;
};

// False when the box lies wholly outside one plane of the frustum of clip
// matrix M (rows of M combined as in Gribb and Hartmann). Orthographic
// boxes (the sun's) too.
bool InFrustum(const Eigen::Matrix4f& M, const Eigen::AlignedBox3f& box);

// Column-major float matrix of X relative to the camera position (double).
Eigen::Matrix4f Relative(const Eigen::Affine3d& X, const Eigen::Vector3d& camera);

}  // namespace sandbox::render
