#include "sensors/render/view.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace sandbox::render {

void Overlay::AddPoint(const Eigen::Vector3d& p_W, const Eigen::Vector3f& rgb) {
  points_W.push_back(p_W);
  point_rgb.push_back(rgb);
}

void Overlay::AddLine(const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W,
                      const Eigen::Vector3f& rgb) {
  lines_W.push_back(a_W);
  lines_W.push_back(b_W);
  line_rgb.push_back(rgb);
}

void CameraView::ValidateOrThrow() const {
  if (width < 1 || width > 8192 || height < 1 || height > 8192) {
    throw std::invalid_argument("resolution must be 1 to 8192 pixels a side, got " +
                                std::to_string(width) + " x " + std::to_string(height));
  }
  if (!(fov_y_rad >= kMinFov_rad && fov_y_rad < M_PI)) {
    throw std::invalid_argument(
        "fov_deg must be at least " + std::to_string(kMinFov_rad * 180.0 / M_PI).substr(0, 4) +
        " and below 180 degrees, got " + std::to_string(fov_y_rad * 180.0 / M_PI));
  }
  if (!(near_m >= kMinNear_m && far_m > near_m && std::isfinite(far_m))) {
    throw std::invalid_argument("need " + std::to_string(kMinNear_m).substr(0, 6) +
                                " m <= near_m < far_m (finite), got near_m " +
                                std::to_string(near_m) + ", far_m " + std::to_string(far_m));
  }
  if (!X_WC.matrix().allFinite()) throw std::invalid_argument("non-finite camera pose");
}

namespace {
constexpr std::pair<ImageKind, const char*> kImageKindNames[] = {
    {kColorImage, "color"},
    {kDepthImage, "depth"},
    {kSegmentationImage, "segmentation"},
    {kNormalsImage, "normals"}};
}  // namespace

ImageKind ParseImageKind(const std::string& word) {
  for (const auto& [kind, name] : kImageKindNames) {
    if (word == name) return kind;
  }
  throw std::invalid_argument("unknown image kind '" + word +
                              "' (color, depth, segmentation or normals)");
}

ImageKinds ParseImageKinds(const std::string& comma_list) {
  ImageKinds kinds = 0;
  std::stringstream list(comma_list);
  for (std::string word; std::getline(list, word, ',');) kinds |= ParseImageKind(word);
  if (kinds == 0) throw std::invalid_argument("no image kind in '" + comma_list + "'");
  return kinds;
}

std::string ImageKindsText(ImageKinds kinds) {
  std::string text;
  for (const auto& [kind, name] : kImageKindNames) {
    if ((kinds & kind) != 0) text += (text.empty() ? "" : ",") + std::string(name);
  }
  return text;
}

}  // namespace sandbox::render
