#pragma once
// Camera lenses: Brown-Conrady (OpenCV's k1, k2, p1, p2, k3) and the
// equidistant fisheye (OpenCV's cv::fisheye k1..k4), with their intrinsics
// fx, fy, cx, cy in OpenCV's image convention (pixel indices, u right, v
// down; rays in OpenCV's camera frame: x right, y down, z forward; the
// struct itself is in view.h, a camera view's value). A lens camera is drawn
// as a pinhole wide enough for every ray its image sees (SourceView) and
// remapped through the lens (LensRemap): the renderer does it for any view
// with a lens.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/render/view.h"

namespace sandbox::render {

// The pinhole view that holds every ray of a `width` x `height` image
// through `lens`, at twice the lens's pixel density at the centre: its size
// and vertical field of view (square pixels, centred), the rest as `view`.
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
