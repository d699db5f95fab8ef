#include "sensors/render/detail_textures.h"

#include <algorithm>
#include <cmath>

namespace sandbox::render {
namespace {

// A hash of a lattice point in [0, 1), wrapping at `period` so the texture tiles.
float Lattice(int x, int y, int period, std::uint32_t seed) {
  x = ((x % period) + period) % period;
  y = ((y % period) + period) % period;
  std::uint32_t h =
      std::uint32_t(x) * 374761393u + std::uint32_t(y) * 668265263u + seed * 2654435761u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return float((h ^ (h >> 16)) & 0xffffff) / float(0x1000000);
}

// Smoothly interpolated value noise at (u, v) in lattice cells.
float ValueNoise(float u, float v, int period, std::uint32_t seed) {
  const int x = int(std::floor(u)), y = int(std::floor(v));
  const float fx = u - float(x), fy = v - float(y);
  const float sx = fx * fx * (3.f - 2.f * fx), sy = fy * fy * (3.f - 2.f * fy);
  const float a = Lattice(x, y, period, seed), b = Lattice(x + 1, y, period, seed);
  const float c = Lattice(x, y + 1, period, seed), d = Lattice(x + 1, y + 1, period, seed);
  return (a + (b - a) * sx) * (1.f - sy) + (c + (d - c) * sx) * sy;
}

// Fractal noise in [0, 1]: octaves from `cells` lattice cells across the texture.
float Fractal(int px, int py, int size, int cells, int octaves, std::uint32_t seed) {
  float sum = 0.f, amplitude = 0.5f, total = 0.f;
  for (int o = 0; o < octaves; ++o, cells *= 2, amplitude *= 0.5f) {
    const float scale = float(cells) / float(size);
    sum += amplitude *
           ValueNoise(float(px) * scale, float(py) * scale, cells, seed + std::uint32_t(o));
    total += amplitude;
  }
  return sum / total;
}

}  // namespace

std::vector<std::uint8_t> MakeDetailTextures(int size) {
  std::vector<std::uint8_t> out(std::size_t(size) * std::size_t(size) * 4 * kNumDetailLayers);
  for (int layer = 0; layer < kNumDetailLayers; ++layer) {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        float b = 1.f;  // brightness around 1
        switch (layer) {
          case kGrass:  // blades: fine speckle over soft patches
            b = 0.75f + 0.3f * Fractal(x, y, size, 4, 3, 11) +
                0.25f * Fractal(x, y, size, 64, 2, 17);
            break;
          case kRock:  // strata and cracks
            b = 0.6f + 0.6f * Fractal(x, y, size, 8, 5, 23) *
                           (0.7f + 0.3f * std::sin(6.2831853f * 8.f * float(y) / float(size) +
                                                   6.f * Fractal(x, y, size, 4, 2, 29)));
            break;
          case kSnow:  // soft, faint
            b = 0.92f + 0.12f * Fractal(x, y, size, 8, 3, 31);
            break;
          default:  // sand: fine grain
            b = 0.85f + 0.2f * Fractal(x, y, size, 32, 3, 37);
            break;
        }
        const std::uint8_t v = std::uint8_t(std::clamp(b * 0.5f, 0.f, 1.f) * 255.f + 0.5f);
        std::uint8_t* texel = &out[4 * ((std::size_t(layer) * std::size_t(size) + std::size_t(y)) *
                                            std::size_t(size) +
                                        std::size_t(x))];
        texel[0] = texel[1] = texel[2] = v;
        texel[3] = 255;
      }
    }
  }
  return out;
}

}  // namespace sandbox::render
