#pragma once
// A face scan as one picture: the six faces as false-colour distance images
// (TURBO: blue near the sensor, red at the box's edge) laid out as an
// unfolded cube, with a colour bar in metres, so that a scanner is checked
// by looking. `sandbox scan --out sheet.png` draws one; `sandbox run
// --scans-every S` draws one beside each PLY.
//
// Layout (faces 0..5 = +X, -X, +Y, -Y, +Z, -Z of the scanner's box):
//
//          +Z
//    -Y    +X    +Y    -X
//          -Z
//
// Each face is drawn with its grid's u axis to the right and its v axis up
// (face_scanner.h: (u, v) = (+Y, +Z) for the X faces, (+X, +Z) for the Y
// faces, (+X, +Y) for the Z faces), one square of pixels per sample. A
// sample's distance is how far its ray ran along the face axis before it hit;
// free samples (nothing within the half extent) are white, unvisited ones
// dark grey.

#include <array>
#include <opencv2/core.hpp>
#include <string>

#include "sensors/face_scanner.h"

namespace sandbox::app {

struct ScanSheet {
  cv::Mat bgr;                     // 8-bit, 3 channels
  std::array<cv::Rect, 6> panels;  // where each face is drawn, by face index
  int sample_px{1};                // side of one sample's square
};

constexpr int kFreeSampleGrey = 255;
constexpr int kUnvisitedSampleGrey = 64;

// `half_extent_m`: the scanner's (the colour bar's end). Throws
// std::invalid_argument for an empty scan or a half extent that is not positive.
ScanSheet DrawFaceScanSheet(const sensors::FaceScan& scan, double half_extent_m,
                            const std::string& title = "");

// The colour a distance is drawn in (TURBO over 0 .. half extent).
cv::Vec3b DistanceColour(double distance_m, double half_extent_m);

// Draws and writes it (PNG); throws std::runtime_error naming the file when it cannot.
void WriteFaceScanSheet(const sensors::FaceScan& scan, double half_extent_m,
                        const std::string& path, const std::string& title = "");

}  // namespace sandbox::app
