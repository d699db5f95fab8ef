#pragma once
// Deferred shading on the CPU: the renderer's G-buffer pass (OpenGL) leaves,
// per pixel, the nearest opaque surface's depth, albedo, normal and material,
// and the nearest translucent surface's; this lights each pixel once with the
// look's model (sun and its cascaded shadows, sky light, highlights, the
// ground's layers and detail, water, the sky with the sun's disc, haze,
// sRGB), in vectors of 16 pixels (AVX-512), or 8 (AVX2 or SSE2), over a few
// threads. On llvmpipe the same lighting as a fragment shader costs about
// seven times as much: its per-pixel overhead and texture fetches dominate.
// The forward shaders (shaders.h) are the reference this is compared with.
//
// No GL here. Images are in GL's order: row 0 at the bottom.
// Threads: one caller at a time (the render thread); it runs its work on
// helper threads of its own and returns when done.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/worker_pool.h"

namespace sandbox::render {

// G-buffer codes: a surface's kind in the low 3 bits, metalness (0..31) above.
enum class SurfaceKind : std::uint8_t {
  kLit = 0,            // sun, sky and highlights on its albedo
  kGround = 1,         // the ground's layers on the grass colour (with materials)
  kGroundImagery = 2,  // the ground's layers on imagery
  kPrelit = 3,         // lit already (lightmaps): haze only
  kWater = 4,          // ripples, the sky's reflection, the sun's glint; its own alpha
};

// One layer of surfaces, `width` x `height`, row 0 at the bottom: the
// opaque layer, or the translucent one (the nearest translucent surface where
// its depth is nearer than the opaque layer's; elsewhere its words are stale).
struct SurfaceLayer {
  int width{0}, height{0};
  // Reversed depth (1 near, 0 nothing drawn), as the depth buffer holds it.
  std::vector<float> depth;
  // RGBA8: the square root of the albedo (shading space) in r, g, b; in a,
  // the code (opaque layer) or the alpha (translucent layer).
  std::vector<std::uint32_t> albedo;
  // RGBA8. Opaque: the world normal, octahedral, 12 + 12 bits in r, g, b;
  // roughness in a. Translucent: octahedral 8 + 8 bits in r, g; roughness in
  // b, the code in a.
  std::vector<std::uint32_t> normal;
};

// The sun's shadow in one cascade: a depth map seen from the sun.
struct ShadowMapView {
  Eigen::Matrix4f light_clip{
      Eigen::Matrix4f::Identity()};  // camera-centred world to the map's clip
  float far_m{0.f};                  // along the optical axis
  float texel_m{0.f};
  int px{0};
  const float* depth{nullptr};  // px x px, row 0 at t = 0, window depth 0..1
};

// What a frame is lit with; colours in the shading space (linear light)
// unless said.
struct LightingFrame {
  Eigen::Matrix4f clip_to_world{Eigen::Matrix4f::Identity()};  // clip to camera-centred world
  Eigen::Vector3f sun{0.f, 0.f, 1.f};                          // unit, towards the sun
  Eigen::Vector3f horizon{Eigen::Vector3f::Zero()}, zenith{Eigen::Vector3f::Zero()};
  Eigen::Vector3f sky_horizon_display{Eigen::Vector3f::Zero()},
      sky_zenith_display{Eigen::Vector3f::Zero()};
  Eigen::Vector2f fog{Eigen::Vector2f::Zero()};  // start, end in metres; end <= 0: none
  float camera_z{0.f};
  Eigen::Vector2f camera_xy{Eigen::Vector2f::Zero()};  // modulo the patterns' period
  float water_level{-1e9f}, snow_line{2800.f};
  std::array<Eigen::Vector3f, 4> ground{};  // grass, rock, snow, sand
  Eigen::Vector3f view_axis{1.f, 0.f, 0.f};
  bool materials{true};
  // The levels of detail's allowance a metre of distance (lod_px times a
  // pixel's angle): meshes were drawn up to that far from their shape, so
  // shadow lookups move that much further off the surface (no acne).
  float lod_offset_per_m{0.f};
  std::vector<ShadowMapView> cascades;  // empty: no shadows
  // Casters that move (robots, movable actors) in a map of their own around
  // them (not in the cascades), infinitely deep where none was drawn; px 0: none.
  ShadowMapView moving_casters;
};

// The ground's detail textures on the CPU: layers of one channel with their
// mip levels (each texel the rounded mean of the four below, as GL makes
// them), sampled as GL samples a repeating trilinear texture. Each texel is
// stored with its right, upper and upper right neighbours (repeating), a byte
// each: one load gives a bilinear sample's four texels.
class DetailTextures {
 public:
  DetailTextures() = default;
  // `rgba`: `layers` images of size x size RGBA8 (the red channel is used).
  DetailTextures(const std::vector<std::uint8_t>& rgba, int size, int layers);
  int size() const { return size_; }
  int levels() const { return int(level_offset_.size()); }
  // Texel (x, y) of a level: bytes (x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1).
  const std::int32_t* data() const { return quads_.data(); }
  // Offsets of each level of layer 0 in data(); a layer's levels follow each other.
  const std::int32_t* level_offsets() const { return level_offset_.data(); }
  int layer_stride() const { return layer_stride_; }

 private:
  int size_{0}, layer_stride_{0};
  std::vector<std::int32_t> level_offset_;
  std::vector<std::int32_t> quads_;
};

class DeferredShader {
 public:
  // Runs on `threads` threads (0: one per core), the caller one of them. `kernel`: "avx512", "avx2"
  // or "sse2" (all give the same bytes); empty: $SANDBOX_SHADE_KERNEL if set, else the widest the
  // CPU runs. Throws std::invalid_argument for an unknown kernel or one the CPU lacks.
  explicit DeferredShader(int threads = 0, const std::string& kernel = "");

  // Lights `opaque`, then blends `translucent` (when given) over it, into
  // `rgba` (4 bytes a pixel, display values, alpha 255, row 0 at the bottom).
  void Shade(const LightingFrame& frame, const DetailTextures& detail, const SurfaceLayer& opaque,
             const SurfaceLayer* translucent, std::vector<std::uint8_t>* rgba);

  // The edge filter (FXAA, as shaders.h's kEdgeFilterFragment) from `in`
  // into `out` (both rgba, row 0 at the bottom, width x height).
  void FilterEdges(const std::vector<std::uint8_t>& in, int width, int height,
                   std::vector<std::uint8_t>* out);

  // Its threads, for the renderer's other per-pixel work between frames' shading.
  sensors::WorkerPool& pool() { return pool_; }

  // The kernel in use, and those this CPU runs (widest first).
  const std::string& kernel() const { return kernel_; }
  static std::vector<std::string> Kernels();

 private:
  std::string kernel_;
  enum class Simd { kSse2, kAvx2, kAvx512 } simd_{Simd::kSse2};
  sensors::WorkerPool pool_;
  std::vector<float> luma_;               // of the last image made or filtered
  const std::uint8_t* luma_of_{nullptr};  // that image
};

// The shading space to display values (sRGB), one level of 255.
std::uint8_t EncodeSrgb(float linear);

}  // namespace sandbox::render
