#pragma once
// From what GL reads back (rows bottom first) to the images a Frame holds
// (row 0 at the top), without GL; every image goes through one row flip.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sandbox::render {

struct RgbaImage;

// Calls row(from, to) for each of `height` rows: `from` a row as GL reads it
// back (bottom first), `to` the same row in an image (top first).
template <typename Row>
void FlipRows(int height, Row row) {
  for (int y = 0; y < height; ++y) row(std::size_t(height - 1 - y), std::size_t(y));
}

// A reversed depth buffer (projection.h) to metres along the optical axis.
void DepthImage(const std::vector<float>& depth, int width, int height, double near_m, double far_m,
                std::vector<float>* depth_m);
// `channels` values a pixel, rows flipped.
void FlippedImage(const std::vector<std::uint32_t>& values, int width, int height,
                  std::vector<std::uint32_t>* out);
void FlippedImage(const std::vector<float>& values, int width, int height, int channels,
                  std::vector<float>* out);
// RGBA8 to RGB8 (alpha dropped). With `marks` (RGBA8 of the same size, rows
// bottom first too), each pixel whose mark has alpha takes the mark's colour.
void RgbImage(const std::uint8_t* rgba, int width, int height,
              const std::vector<std::uint32_t>* marks, std::vector<std::uint8_t>* rgb);
// Each pixel of `rgba` (rows bottom first) whose mark has alpha takes the
// mark's colour: RgbImage's marks, kept in RGBA.
void MarkImage(const std::vector<std::uint32_t>& marks, std::vector<std::uint8_t>* rgba);
// A decoded image (row 0 at the top) upside down: GL's first texture row is t = 0.
void FlipImage(RgbaImage* image);

}  // namespace sandbox::render
