#pragma once
// Offscreen rendering of the world (OSMesa, OpenGL 4.5 core, llvmpipe): level
// meshes with their materials (base colours, textures, vertex colours,
// cut-outs, normal maps, highlights), terrain tiles with their imagery, ground
// shaded by slope and height with detail textures, water with reflections, the
// robots skinned as posed, a sun with cascaded shadow maps, sky light, a sky
// with a horizon gradient, the ground beyond the level out to the horizon,
// distance haze, FXAA or 4x multisampling; colour, depth, segmentation and normal
// images read back. Depth is reversed (1 near, 0 far, in a float buffer):
// precise from 0.1 m to hundreds of kilometres.
// GL stays inside the renderer's parts (renderer.cc lists them); nothing
// else sees a GL header (the types it takes and gives are in view.h).
//
// Threads: a Renderer and everything it renders belong to one thread (the
// render thread); make it there. Several renderers on one thread may take
// turns (each makes its own context current). Besides llvmpipe's threads, a
// renderer keeps a helper thread per further core for deferred shading.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/terrain_streamer.h"
#include "sensors/render/view.h"

namespace sandbox::render {

struct RgbaImage {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> rgba;  // row 0 at the top
};

// Decodes an embedded (compressed) texture or an image file; returns "" or
// why it cannot. The app supplies one (OpenCV); the renderer itself decodes nothing.
using TextureDecoder = std::function<std::string(const scene::EmbeddedTexture* embedded,
                                                 const std::string& path, RgbaImage* image)>;

// How much of the look a camera pays for. kPlain is the flat look of before
// (a reference for benchmarks); kFast adds gamma-correct shading with sky
// light, the ground's and the water's materials, normal maps and highlights;
// kHigh adds sun shadows and FXAA (4x multisampling is a setting of its own:
// on llvmpipe it costs 2.5-3.5x a frame, FXAA about 0.1x).
enum class Quality { kPlain, kFast, kHigh };

// "plain", "fast", "high"; throws std::invalid_argument naming the word.
Quality ParseQuality(const std::string& word);

struct RenderSettings {
  Eigen::Vector3f sky_rgb{0.62f, 0.76f, 0.92f};
  Eigen::Vector3f sun_direction_W{0.35f, -0.45f, 0.82f};  // towards the sun
  float fog_start_m{300.0f};
  float fog_end_m{1500.0f};
  // The look (each switchable; Preset sets them together).
  bool gamma_correct{true};  // shade in linear light with sky light; write sRGB
  bool materials{true};      // ground layers, water, normal maps, highlights
  bool haze{true};
  bool shadows{true};
  int msaa_samples{0};  // 0 or 1: none
  // Deferred shading (gamma-correct looks without multisampling): GL draws
  // each pixel's nearest opaque and translucent surfaces' albedo, normal and
  // material, and the CPU lights each pixel once (deferred_shading.h), about
  // seven times cheaper than llvmpipe shading the same look. False: lit as
  // drawn (forward), the reference it is compared with.
  bool deferred{true};
  // FXAA: an edge-directed filter over the finished colour image that
  // smooths jagged edges for about the cost of one full-screen pass.
  bool fxaa{true};
  // Anisotropic filtering of material textures (1: trilinear mipmaps only).
  // Off by default: llvmpipe takes about 9 s to compile each shader variant that uses it.
  int anisotropy{1};
  // Levels of detail, in frames of colour alone: meshes are drawn simplified
  // where that moves their surface by no more than `lod_px` pixels and, under
  // shadows, a fifth of a shadow-map texel. Frames with a depth, segmentation
  // or normals image (measurements) are drawn as given, and so is everything
  // with 0.
  float lod_px{1.0f};
  // Back faces culled where they cannot be seen (hidden_faces.h: closed
  // solids from outside, terrain-like height fields from above): the same
  // images (but a few pixels on silhouettes' edges) for about a tenth less
  // work on llvmpipe. False: every face drawn, the reference.
  bool cull_hidden_back_faces{true};
  int shadow_map_px{1024};
  int shadow_cascades{2};
  double shadow_distance_m{300.0};  // shadows end this far along the optical axis
  ImageKinds images{kColorImage | kDepthImage};

  static RenderSettings Preset(Quality quality);

  // A field outside its range (render_settings.cc): the field's name and why.
  struct Problem {
    std::string field, why;
  };
  std::optional<Problem> FindProblem() const;
  // Throws std::invalid_argument "RenderSettings::ValidateOrThrow(): 'field' why". The renderer
  // calls it for every frame: it fixes no setting itself.
  void ValidateOrThrow() const;
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // Uploads the level's actors (meshes, materials, textures). Warns once on
  // `warnings` for each texture that cannot be decoded (the base colour stays).
  virtual void SetLevel(const scene::Level& level, const TextureDecoder& decoder) = 0;
  // Renders the level (movable actors at `actor_poses`, indexed like
  // Level::actors; empty: load-time poses), `robots` as posed and, when given,
  // the overlay on top (colour only), into the images `settings.images` names.
  virtual void Render(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
                      const std::vector<const scene::RobotState*>& robots,
                      const RenderSettings& settings, Frame* frame,
                      const Overlay* overlay = nullptr) = 0;
  // Terrain tiles to draw from the next Render on (scene/terrain_streamer.h):
  // uploaded when first seen, freed when no longer given.
  virtual void SetTerrain(std::shared_ptr<const scene::TileList> tiles) = 0;
  virtual const std::vector<std::string>& warnings() const = 0;
  virtual std::string description() const = 0;  // "OpenGL 4.5 (Core Profile) Mesa ... llvmpipe"
};

enum class RendererBackend { kOsMesa };

// Creates a renderer with its own offscreen context. Throws std::runtime_error
// when the context cannot be made. The first call sets the process's malloc to
// keep freed memory (up to 64 MiB at the heap's top; blocks under 32 MiB from
// the heap): llvmpipe's per-frame allocations would otherwise be faulted in
// anew every frame.
std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend = RendererBackend::kOsMesa);

}  // namespace sandbox::render
