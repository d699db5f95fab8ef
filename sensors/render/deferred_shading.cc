#include "sensors/render/deferred_shading.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "sensors/render/deferred_kernel.h"

namespace sandbox::render {
namespace {

const std::int32_t* SrgbTable() {
  static const std::vector<std::int32_t> table = [] {
    std::vector<std::int32_t> t(kSrgbSteps + 1);
    for (int i = 0; i <= kSrgbSteps; ++i) t[std::size_t(i)] = EncodeSrgb(float(i) / kSrgbSteps);
    return t;
  }();
  return table.data();
}

}  // namespace

std::uint8_t EncodeSrgb(float linear) {
  const float c = std::clamp(linear, 0.f, 1.f);
  const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(std::clamp(s, 0.f, 1.f) * 255.f));
}

std::vector<std::string> DeferredShader::Kernels() {
  std::vector<std::string> kernels;
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq")) {
    kernels.push_back("avx512");
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) kernels.push_back("avx2");
  kernels.push_back("sse2");
  return kernels;
}

DetailTextures::DetailTextures(const std::vector<std::uint8_t>& rgba, int size, int layers)
    : size_(size) {
  // Each layer's levels as GL makes them (each texel the mean of the four below).
  int offset = 0;
  for (int s = size; s >= 1; s /= 2) {
    level_offset_.push_back(offset);
    offset += s * s;
  }
  layer_stride_ = offset;
  std::vector<std::uint8_t> texels(std::size_t(layers) * std::size_t(offset));
  quads_.assign(texels.size(), 0);
  for (int layer = 0; layer < layers; ++layer) {
    std::uint8_t* base = &texels[std::size_t(layer) * std::size_t(offset)];
    for (int i = 0; i < size * size; ++i) {
      base[i] = rgba[4 * (std::size_t(layer) * std::size_t(size * size) + std::size_t(i))];
    }
    for (std::size_t l = 1; l < level_offset_.size(); ++l) {
      const int s = size >> l, below = s * 2;
      const std::uint8_t* src = base + level_offset_[l - 1];
      std::uint8_t* dst = base + level_offset_[l];
      for (int y = 0; y < s; ++y) {
        for (int x = 0; x < s; ++x) {
          const int sum = src[2 * y * below + 2 * x] + src[2 * y * below + 2 * x + 1] +
                          src[(2 * y + 1) * below + 2 * x] + src[(2 * y + 1) * below + 2 * x + 1];
          dst[y * s + x] = std::uint8_t((sum + 2) / 4);
        }
      }
    }
    // Each texel with its neighbours, repeating at the edges.
    for (std::size_t l = 0; l < level_offset_.size(); ++l) {
      const int s = size >> l;
      const std::uint8_t* t = base + level_offset_[l];
      std::int32_t* q =
          &quads_[std::size_t(layer) * std::size_t(offset) + std::size_t(level_offset_[l])];
      for (int y = 0; y < s; ++y) {
        for (int x = 0; x < s; ++x) {
          const int x1 = (x + 1) % s, y1 = (y + 1) % s;
          q[y * s + x] = std::int32_t(
              std::uint32_t(t[y * s + x]) | std::uint32_t(t[y * s + x1]) << 8 |
              std::uint32_t(t[y1 * s + x]) << 16 | std::uint32_t(t[y1 * s + x1]) << 24);
        }
      }
    }
  }
}

DeferredShader::DeferredShader(int threads, const std::string& kernel)
    : kernel_(kernel), pool_(threads) {
  const std::vector<std::string> kernels = Kernels();
  const char* chosen = std::getenv("SANDBOX_SHADE_KERNEL");
  if (kernel_.empty()) kernel_ = chosen != nullptr && *chosen != 0 ? chosen : kernels.front();
  if (std::find(kernels.begin(), kernels.end(), kernel_) == kernels.end()) {
    std::string known;
    for (const std::string& k : kernels) known += (known.empty() ? "" : ", ") + k;
    throw std::invalid_argument("DeferredShader::DeferredShader(): kernel '" + kernel_ +
                                "' is not one this CPU runs (" + known + ")");
  }
  simd_ = kernel_ == "avx512" ? Simd::kAvx512 : kernel_ == "avx2" ? Simd::kAvx2 : Simd::kSse2;
}

void DeferredShader::Shade(const LightingFrame& frame, const DetailTextures& detail,
                           const SurfaceLayer& opaque, const SurfaceLayer* translucent,
                           std::vector<std::uint8_t>* rgba) {
  const int w = opaque.width, h = opaque.height;
  rgba->resize(4 * std::size_t(w) * std::size_t(h));
  std::uint32_t* words = reinterpret_cast<std::uint32_t*>(rgba->data());
  // The cascades' maps, one after the other, as the kernel gathers from them.
  const float* shadow = frame.cascades.empty() ? nullptr : frame.cascades.front().depth;
  // Bands of 16 rows (whole 2 x 2 quads), drawn from a counter.
  constexpr int kBand = 16;
  const int bands = (h + kBand - 1) / kBand;
  luma_.resize(std::size_t(w) * std::size_t(h));
  luma_of_ = rgba->data();
  pool_.RunParallel(bands, [&](int band) {
    const int begin = band * kBand, end = std::min(h, begin + kBand);
    if (simd_ == Simd::kAvx512) {
      const ShadeConstants k{&frame, &detail, SrgbTable(), shadow, w, h};
      avx512::ShadeRows(k, opaque, translucent, begin, end, words, luma_.data());
    } else if (simd_ == Simd::kAvx2) {
      const ShadeConstants k{&frame, &detail, SrgbTable(), shadow, w, h};
      avx2::ShadeRows(k, opaque, translucent, begin, end, words, luma_.data());
    } else {
      const ShadeConstants k{&frame, &detail, SrgbTable(), shadow, w, h};
      sse2::ShadeRows(k, opaque, translucent, begin, end, words, luma_.data());
    }
  });
}

void DeferredShader::FilterEdges(const std::vector<std::uint8_t>& in, int width, int height,
                                 std::vector<std::uint8_t>* out) {
  const std::size_t count = std::size_t(width) * std::size_t(height);
  *out = in;
  // The luma: Shade's own when `in` is its image, else made here.
  if (luma_of_ != in.data() || luma_.size() != count) {
    luma_.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      luma_[i] = (0.299f * in[4 * i] + 0.587f * in[4 * i + 1] + 0.114f * in[4 * i + 2]) / 255.f;
    }
  }
  const float* luma = luma_.data();
  auto l = [&](int x, int y) {
    return luma[std::size_t(std::clamp(y, 0, height - 1)) * std::size_t(width) +
                std::size_t(std::clamp(x, 0, width - 1))];
  };
  // Bilinear, clamped to the edge, at (u, v) in texture coordinates.
  auto sample = [&](float u, float v, float* rgb) {
    const float fx = u * width - 0.5f, fy = v * height - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float ax = fx - x0f, ay = fy - y0f;
    const int x0 = std::clamp(int(x0f), 0, width - 1), x1 = std::clamp(int(x0f) + 1, 0, width - 1);
    const int y0 = std::clamp(int(y0f), 0, height - 1),
              y1 = std::clamp(int(y0f) + 1, 0, height - 1);
    const std::uint8_t* c00 = &in[4 * (std::size_t(y0) * std::size_t(width) + std::size_t(x0))];
    const std::uint8_t* c10 = &in[4 * (std::size_t(y0) * std::size_t(width) + std::size_t(x1))];
    const std::uint8_t* c01 = &in[4 * (std::size_t(y1) * std::size_t(width) + std::size_t(x0))];
    const std::uint8_t* c11 = &in[4 * (std::size_t(y1) * std::size_t(width) + std::size_t(x1))];
    for (int c = 0; c < 3; ++c) {
      const float top = c00[c] + (c10[c] - c00[c]) * ax, bottom = c01[c] + (c11[c] - c01[c]) * ax;
      rgb[c] = (top + (bottom - top) * ay) * (1.f / 255.f);
    }
  };
  // An edge pixel averaged along the edge (shaders.h's kEdgeFilterFragment).
  auto filter = [&](int x, int y) {
    const float l_m = l(x, y);
    const float l_a = l(x - 1, y - 1), l_b = l(x + 1, y - 1), l_c = l(x - 1, y + 1),
                l_d = l(x + 1, y + 1);
    const float lo = std::min({l_m, l_a, l_b, l_c, l_d});
    const float hi = std::max({l_m, l_a, l_b, l_c, l_d});
    // Along the edge: the luma gradient (x, y) turned to (y, -x).
    float dx = (l_c + l_d) - (l_a + l_b), dy = (l_a + l_c) - (l_b + l_d);
    const float reduce = std::max((l_a + l_b + l_c + l_d) / 32.f, 1.f / 128.f);
    const float scale = 1.f / (std::min(std::abs(dx), std::abs(dy)) + reduce);
    dx = std::clamp(dx * scale, -8.f, 8.f) / float(width);
    dy = std::clamp(dy * scale, -8.f, 8.f) / float(height);
    const float u = (float(x) + 0.5f) / float(width), v = (float(y) + 0.5f) / float(height);
    float a[3], b[3], c[3], d[3];
    sample(u - dx / 6.f, v - dy / 6.f, a);
    sample(u + dx / 6.f, v + dy / 6.f, b);
    sample(u - dx / 2.f, v - dy / 2.f, c);
    sample(u + dx / 2.f, v + dy / 2.f, d);
    float near_pair[3], wide[3];
    for (int k = 0; k < 3; ++k) {
      near_pair[k] = 0.5f * (a[k] + b[k]);
      wide[k] = 0.5f * near_pair[k] + 0.25f * (c[k] + d[k]);
    }
    const float l_wide = 0.299f * wide[0] + 0.587f * wide[1] + 0.114f * wide[2];
    const float* chosen = l_wide < lo || l_wide > hi ? near_pair : wide;
    std::uint8_t* dst = &(*out)[4 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
    for (int k = 0; k < 3; ++k)
      dst[k] = std::uint8_t(std::lround(std::clamp(chosen[k], 0.f, 1.f) * 255.f));
  };
  constexpr int kBand = 32;
  int (*const edges_of_row)(const float*, int, int, int, int*) =
      simd_ == Simd::kAvx512 ? avx512::EdgesOfRow
      : simd_ == Simd::kAvx2 ? avx2::EdgesOfRow
                             : sse2::EdgesOfRow;
  pool_.RunParallel((height + kBand - 1) / kBand, [&](int band) {
    std::vector<int> columns(static_cast<std::size_t>(width));
    for (int y = band * kBand; y < std::min(height, (band + 1) * kBand); ++y) {
      const int edges = edges_of_row(luma, width, height, y, columns.data());
      for (int i = 0; i < edges; ++i) filter(columns[std::size_t(i)], y);
    }
  });
}

}  // namespace sandbox::render
