#include "app/scan_sheet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sandbox::app {
namespace {

// TURBO, 256 entries (BGR).
const cv::Mat& Turbo() {
  static const cv::Mat lut = [] {
    cv::Mat ramp(1, 256, CV_8U), colours;
    for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = std::uint8_t(i);
    cv::applyColorMap(ramp, colours, cv::COLORMAP_TURBO);
    return colours;
  }();
  return lut;
}

// Grid cell (column, row) of each face in the unfolded cube.
constexpr int kCell[6][2] = {{1, 1}, {3, 1}, {2, 1}, {0, 1}, {1, 0}, {1, 2}};
constexpr const char* kFaceName[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};

void Text(cv::Mat* image, const std::string& text, cv::Point at, double scale, int grey) {
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(grey, grey, grey), 1,
              cv::LINE_AA);
}

}  // namespace

cv::Vec3b DistanceColour(double distance_m, double half_extent_m) {
  const double t = std::clamp(distance_m / half_extent_m, 0.0, 1.0);
  return Turbo().at<cv::Vec3b>(0, int(std::lround(255.0 * t)));
}

ScanSheet DrawFaceScanSheet(const sensors::FaceScan& scan, double half_extent_m,
                            const std::string& title) {
  if (scan.n <= 0) throw std::invalid_argument("scan sheet: the scan is empty");
  if (!(half_extent_m > 0.0) || !std::isfinite(half_extent_m)) {
    throw std::invalid_argument("scan sheet: the half extent must be positive");
  }
  const int n = scan.n;
  ScanSheet sheet;
  sheet.sample_px = std::max(1, 160 / n);
  const int side = n * sheet.sample_px, gap = 6, top = 30, bar_width = 18;
  const int width = 4 * side + 5 * gap + bar_width + 70, height = top + 3 * side + 3 * gap + 24;
  sheet.bgr = cv::Mat(height, width, CV_8UC3, cv::Scalar(32, 32, 32));
  Text(&sheet.bgr, title.empty() ? "face scan" : title, {gap, 20}, 0.5, 230);

  for (int f = 0; f < 6; ++f) {
    const cv::Rect panel(gap + kCell[f][0] * (side + gap), top + kCell[f][1] * (side + gap), side,
                         side);
    sheet.panels[std::size_t(f)] = panel;
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const std::size_t k = std::size_t(r) * std::size_t(n) + std::size_t(c);
        cv::Vec3b colour(kUnvisitedSampleGrey, kUnvisitedSampleGrey, kUnvisitedSampleGrey);
        if (k < face.occupancy.size() && face.occupancy[k] == sensors::kOccupied) {
          colour = DistanceColour(face.distance_m[k], half_extent_m);
        } else if (k < face.occupancy.size() && face.occupancy[k] == sensors::kFree) {
          colour = cv::Vec3b(kFreeSampleGrey, kFreeSampleGrey, kFreeSampleGrey);
        }
        // v up: row 0 at the panel's bottom.
        const cv::Rect square(panel.x + c * sheet.sample_px,
                              panel.y + (n - 1 - r) * sheet.sample_px, sheet.sample_px,
                              sheet.sample_px);
        sheet.bgr(square).setTo(cv::Scalar(colour[0], colour[1], colour[2]));
      }
    }
    const std::string label =
        std::string(kFaceName[f]) +
        (face.tick >= 0 ? "  tick " + std::to_string(face.tick) : "  unscanned");
    Text(&sheet.bgr, label, {panel.x + 3, panel.y + 13}, 0.4, 0);
  }

  // The colour bar: 0 at the bottom, the half extent at the top.
  const cv::Rect bar(width - bar_width - 62, top, bar_width, 3 * side + 2 * gap);
  for (int y = 0; y < bar.height; ++y) {
    const double d = half_extent_m * (1.0 - double(y) / std::max(1, bar.height - 1));
    const cv::Vec3b colour = DistanceColour(d, half_extent_m);
    cv::line(sheet.bgr, {bar.x, bar.y + y}, {bar.x + bar.width - 1, bar.y + y},
             cv::Scalar(colour[0], colour[1], colour[2]));
  }
  for (int i = 0; i <= 4; ++i) {
    const double d = half_extent_m * i / 4.0;
    const int y = bar.y + int(std::lround((1.0 - i / 4.0) * (bar.height - 1)));
    char text[32];
    std::snprintf(text, sizeof(text), "%g m", std::round(d * 100.0) / 100.0);
    cv::line(sheet.bgr, {bar.x + bar.width, y}, {bar.x + bar.width + 4, y},
             cv::Scalar(230, 230, 230));
    Text(&sheet.bgr, text, {bar.x + bar.width + 7, y + 4}, 0.4, 230);
  }
  Text(&sheet.bgr, "distance along the face axis; white: free, grey: unvisited", {gap, height - 8},
       0.4, 230);
  return sheet;
}

void WriteFaceScanSheet(const sensors::FaceScan& scan, double half_extent_m,
                        const std::string& path, const std::string& title) {
  const ScanSheet sheet = DrawFaceScanSheet(scan, half_extent_m, title);
  bool written = false;
  try {
    written = cv::imwrite(path, sheet.bgr);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) throw std::runtime_error("cannot write " + path);
}

}  // namespace sandbox::app
