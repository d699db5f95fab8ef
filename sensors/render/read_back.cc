#include "sensors/render/read_back.h"

#include <algorithm>
#include <cstring>

#include "sensors/render/projection.h"
#include "sensors/render/renderer.h"

namespace sandbox::render {

void DepthImage(const std::vector<float>& depth, int width, int height, double near_m, double far_m,
                std::vector<float>* depth_m) {
  const std::size_t w = std::size_t(width);
  depth_m->resize(w * std::size_t(height));
  const ReversedDepth depth_to_m(near_m, far_m);
  FlipRows(height, [&](std::size_t from, std::size_t to) {
    const float* src = &depth[from * w];
    float* dst = &(*depth_m)[to * w];
    for (std::size_t x = 0; x < w; ++x) dst[x] = depth_to_m.Metres(src[x]);
  });
}

void FlippedImage(const std::vector<std::uint32_t>& values, int width, int height,
                  std::vector<std::uint32_t>* out) {
  const std::size_t w = std::size_t(width);
  out->resize(w * std::size_t(height));
  FlipRows(height, [&](std::size_t from, std::size_t to) {
    std::copy_n(&values[from * w], w, &(*out)[to * w]);
  });
}

void FlippedImage(const std::vector<float>& values, int width, int height, int channels,
                  std::vector<float>* out) {
  const std::size_t row = std::size_t(channels) * std::size_t(width);
  out->resize(row * std::size_t(height));
  FlipRows(height, [&](std::size_t from, std::size_t to) {
    std::copy_n(&values[from * row], row, &(*out)[to * row]);
  });
}

void RgbImage(const std::uint8_t* rgba, int width, int height,
              const std::vector<std::uint32_t>* marks, std::vector<std::uint8_t>* rgb) {
  const std::size_t w = std::size_t(width);
  rgb->resize(3 * w * std::size_t(height));
  FlipRows(height, [&](std::size_t from, std::size_t to) {
    const std::uint8_t* src = &rgba[4 * w * from];
    std::uint8_t* dst = &(*rgb)[3 * w * to];
    // Four bytes a pixel written three apart (the fourth overwritten next).
    for (std::size_t x = 0; x + 1 < w; ++x) std::memcpy(dst + 3 * x, src + 4 * x, 4);
    std::memcpy(dst + 3 * (w - 1), src + 4 * (w - 1), 3);
    for (std::size_t x = 0; marks != nullptr && x < w; ++x) {
      const std::uint32_t mark = (*marks)[w * from + x];
      if ((mark >> 24) == 0) continue;
      dst[3 * x] = std::uint8_t(mark), dst[3 * x + 1] = std::uint8_t(mark >> 8),
              dst[3 * x + 2] = std::uint8_t(mark >> 16);
    }
  });
}

void MarkImage(const std::vector<std::uint32_t>& marks, std::vector<std::uint8_t>* rgba) {
  for (std::size_t i = 0; i < marks.size(); ++i) {
    const std::uint32_t mark = marks[i];
    if ((mark >> 24) == 0) continue;
    std::uint8_t* p = &(*rgba)[4 * i];
    p[0] = std::uint8_t(mark), p[1] = std::uint8_t(mark >> 8), p[2] = std::uint8_t(mark >> 16);
  }
}

void FlipImage(RgbaImage* image) {
  const std::size_t row = 4 * std::size_t(image->width);
  const std::vector<std::uint8_t> given = image->rgba;
  FlipRows(image->height, [&](std::size_t from, std::size_t to) {
    std::copy_n(&given[from * row], row, &image->rgba[to * row]);
  });
}

}  // namespace sandbox::render
