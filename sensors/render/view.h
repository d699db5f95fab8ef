#pragma once
// What a camera sees and what the renderer gives back, without GL: the view
// (pose and lens), the debug overlay's marks and the rendered frame.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sandbox::render {

// A camera lens (sensors/render/lens.h): Brown-Conrady (OpenCV's k1, k2, p1,
// p2, k3) or the equidistant fisheye (cv::fisheye's k1..k4), with OpenCV's
// intrinsics (pixel indices, u right, v down; rays x right, y down, z forward).
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
  bool operator==(const Lens& other) const;
};

// A camera: pose X_WC with x forward, y left, z up (like a robot body); a
// pinhole unless it has a lens.
struct CameraView {
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};
  int width{640};
  int height{480};
  double fov_y_rad{0.9};  // vertical field of view
  double near_m{0.1};
  double far_m{2000.0};
  std::optional<Lens> lens;  // none: a pinhole of fov_y_rad
  // Below these a frame is blank or all one depth: refused, not drawn.
  static constexpr double kMinNear_m = 1e-4;
  static constexpr double kMinFov_rad = 0.1 * M_PI / 180.0;
  // The most pixels a camera may have unless its pixel_budget says more
  // (3840 x 2160), and the most any may have (4096 x 4096: about 1.4 GB of
  // buffers and images for one camera).
  static constexpr std::int64_t kDefaultPixelBudget = 3840 * 2160;
  static constexpr std::int64_t kMaxPixelBudget = std::int64_t(1) << 24;
  // Throws std::invalid_argument naming the field: sizes from 1 to 8192,
  // a field of view in [kMinFov_rad, pi), kMinNear_m <= near < far.
  void ValidateOrThrow() const;
};

// The images a render makes (a bit set).
enum ImageKind : unsigned {
  kColorImage = 1u,
  kDepthImage = 2u,
  kSegmentationImage = 4u,  // an id per actor, horizon and robot bone group (scene/surface_ids.h)
  kNormalsImage = 8u,       // unit surface normals in the camera frame
};
using ImageKinds = unsigned;

// "color", "depth", "segmentation", "normals" (also "all"), by name; throws
// std::invalid_argument naming the word and the choices.
ImageKind ParseImageKind(const std::string& word);
// A comma list of them ("color,depth"); throws as above, or on an empty list.
ImageKinds ParseImageKinds(const std::string& comma_list);
std::string ImageKindsText(ImageKinds kinds);  // "color,depth"

struct Frame {
  int width{0};
  int height{0};
  ImageKinds kinds{0};  // which of the images below are filled; row 0 at the top
  std::vector<std::uint8_t> rgb;
  std::vector<float> depth_m;          // distance along the optical axis; +inf where sky
  std::vector<std::uint32_t> segment;  // 0 where sky
  std::vector<float>
      normal_C;  // x, y, z a pixel, camera frame (x forward, y left, z up); 0 where sky
};

// Debug marks drawn over the scene, hidden behind nearer surfaces: points and
// short line segments in world coordinates, each with its own colour. They
// change the colour image only, never the depth image.
struct Overlay {
  std::vector<Eigen::Vector3d> points_W;
  std::vector<Eigen::Vector3f> point_rgb;  // one per point, 0..1
  std::vector<Eigen::Vector3d> lines_W;    // two ends per segment
  std::vector<Eigen::Vector3f> line_rgb;   // one per segment
  float point_size_px{3.0f};

  void AddPoint(const Eigen::Vector3d& p_W, const Eigen::Vector3f& rgb);
  void AddLine(const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W, const Eigen::Vector3f& rgb);
  bool empty() const { return points_W.empty() && lines_W.empty(); }
};

}  // namespace sandbox::render
