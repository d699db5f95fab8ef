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
#include "sensors/worker_pool.h"

namespace sandbox::render {

// The pinhole view that holds every ray of a `width` x `height` image
// through `lens`, at twice the lens's pixel density at the centre: its size
// and vertical field of view (square pixels, centred), the rest as `view`.
CameraView SourceView(const CameraView& view, const Lens& lens);

// A source view's images as the renderer reads them back from GL, before
// any conversion: rows bottom first; colour RGBA8 (alpha ignored); depth the
// reversed depth buffer (projection.h) of near_m .. far_m; segment ids;
// normals three floats a pixel. An image left null is not gathered.
struct RawImages {
  int width{0}, height{0};
  const std::uint8_t* rgba{nullptr};
  const float* depth{nullptr};
  double near_m{0.0}, far_m{0.0};
  const std::uint32_t* segment{nullptr};
  const float* normal{nullptr};
};

// Where each pixel of the lens image comes from in the source view's image,
// built once; Apply gathers the lens frame (row 0 at the top, depth in
// metres) straight from the source's read-back: colour bilinear (in 1/128
// of a source pixel), depth, segment and normal from the nearest source
// pixel (they must not blend across edges); in bands of rows on `pool`'s
// threads when given. Throws std::invalid_argument for a source of another size.
class LensRemap {
 public:
  LensRemap(const Lens& lens, int width, int height, const CameraView& source);
  void Apply(const RawImages& source, Frame* out, sensors::WorkerPool* pool = nullptr) const;

 private:
  int width_, height_, source_width_, source_height_;
  // In InTiles order (lens.cc), source pixels as indices in GL's rows: the
  // bilinear cell's upper-left pixel, its four pixels' weights in 1/16384
  // as two pairs of 16 bits (Bilinear in lens.cc), the nearest pixel.
  std::vector<std::int32_t> corner_;
  std::vector<std::int32_t> weight_;
  std::vector<std::int32_t> nearest_;
};

}  // namespace sandbox::render
