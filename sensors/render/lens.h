#pragma once
// Camera lenses: Brown-Conrady (OpenCV's k1, k2, p1, p2, k3) and the
// equidistant fisheye (OpenCV's cv::fisheye k1..k4), with their intrinsics
// fx, fy, cx, cy in OpenCV's image convention (pixel indices, u right, v
// down; rays in OpenCV's camera frame: x right, y down, z forward). A lens
// camera is to be drawn as a pinhole wide enough for every ray its image
// sees (SourceView) and remapped through the lens (LensRemap). Not yet read
// from camera tables: the model and its checks, for issue 43's lenses.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/render/view.h"

namespace sandbox::render {

struct Lens {
  enum class Model { kBrownConrady, kFisheye };
  Model model{Model::kBrownConrady};
  double fx{0.0}, fy{0.0}, cx{0.0}, cy{0.0};  // pixels
  double k1{0.0}, k2{0.0}, k3{0.0}, k4{0.0};  // radial (k4: fisheye only)
  double p1{0.0}, p2{0.0};                    // tangential (Brown-Conrady only)

  // The pixel a ray (OpenCV camera frame, z > 0 for Brown-Conrady) lands on.
  Eigen::Vector2d Pixel(const Eigen::Vector3d& ray) const;
  // The unit ray a pixel sees (the inverse, by Newton's method).
  Eigen::Vector3d Ray(const Eigen::Vector2d& pixel) const;
  // Throws std::invalid_argument naming the field: non-positive focal
  // lengths, or coefficients whose projection folds back (is not monotonic)
  // within a width x height image, or that see rays beyond `max_angle_deg`
  // off the axis (a pinhole source cannot hold them).
  void ValidateOrThrow(int width, int height, double max_angle_deg = 80.0) const;
  std::string ModelName() const;  // "brown_conrady" or "fisheye"
};

// The pinhole view that holds every ray of a `width` x `height` image
// through `lens`, at the lens's pixel density at the centre: its size and
// vertical field of view (square pixels, centred), the rest as `view`.
CameraView SourceView(const CameraView& view, const Lens& lens);

// Where each pixel of the lens image comes from in the source view's image,
// built once; Apply is a gather (bilinear for colour, nearest for depth,
// segmentation and normals, which must not blend across edges).
class LensRemap {
 public:
  LensRemap(const Lens& lens, int width, int height, const CameraView& source);
  void Apply(const Frame& source, Frame* out) const;

 private:
  int width_, height_, source_width_;
  std::vector<std::int32_t> corner_;   // top-left source pixel of the bilinear cell
  std::vector<std::uint16_t> weight_;  // x and y fractions in 1/256, two a pixel
  std::vector<std::int32_t> nearest_;
};

}  // namespace sandbox::render
