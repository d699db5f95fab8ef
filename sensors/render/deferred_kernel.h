#pragma once
// The deferred shading kernel (deferred_kernel.cc), one build per
// instruction set in a namespace named after it (sandbox_isa_kernel in
// CMakeLists.txt): avx512, 16 pixels at a time; avx2 (with FMA), 8; sse2,
// any x86-64, 8 in SSE2 halves. DeferredShader picks one by what the CPU has.

#include <cstdint>

#include "sensors/render/deferred_shading.h"

namespace sandbox::render {

// The display byte of a linear value, in this many steps from 0 to 1 (fine
// enough that a step never spans half a display level, even near black).
constexpr int kSrgbSteps = 16383;

// What the kernel reads besides the layers.
struct ShadeConstants {
  const LightingFrame* frame;
  const DetailTextures* detail;
  const std::int32_t* srgb;  // kSrgbSteps + 1 entries: display byte of a linear value
  const float* shadow;       // the cascades' maps, one after the other
  int width, height;
};

// Each build's two functions:
// ShadeRows: rows [row_begin, row_end) (even row_begin) of `rgba` from the
// layers, and their luma (0..1) into `luma` when given.
// EdgesOfRow: the columns of row `row` that the edge filter changes, in
// `columns` (width entries), ascending; returns how many. A pixel changes
// where its luma and its four diagonal neighbours' (clamped at the image's
// edges) differ by at least max(1/32, their highest / 8).
namespace avx512 {
void ShadeRows(const ShadeConstants& k, const SurfaceLayer& opaque, const SurfaceLayer* translucent,
               int row_begin, int row_end, std::uint32_t* rgba, float* luma);
int EdgesOfRow(const float* luma, int width, int height, int row, int* columns);
}  // namespace avx512

namespace avx2 {
void ShadeRows(const ShadeConstants& k, const SurfaceLayer& opaque, const SurfaceLayer* translucent,
               int row_begin, int row_end, std::uint32_t* rgba, float* luma);
int EdgesOfRow(const float* luma, int width, int height, int row, int* columns);
}  // namespace avx2

namespace sse2 {
void ShadeRows(const ShadeConstants& k, const SurfaceLayer& opaque, const SurfaceLayer* translucent,
               int row_begin, int row_end, std::uint32_t* rgba, float* luma);
int EdgesOfRow(const float* luma, int width, int height, int row, int* columns);
}  // namespace sse2

}  // namespace sandbox::render
