#pragma once
// Offscreen rendering of the world (OSMesa, OpenGL 4.5 core, llvmpipe): level
// meshes with their base colours and textures, terrain tiles with their
// imagery, the robots skinned as posed, a directional sun, a sky with a
// horizon gradient, the ground beyond the level out to the horizon and
// distance haze; colour and depth read back. Depth is reversed (1 near, 0
// far, in a float buffer): precise from 0.1 m to hundreds of kilometres.
// GL stays inside renderer.cc; nothing else sees a GL header (the types it
// takes and gives are in view.h).
//
// Threads: a Renderer and everything it renders belong to one thread (the
// render thread); make it there.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
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

struct RenderSettings {
  Eigen::Vector3f sky_rgb{0.62f, 0.76f, 0.92f};
  Eigen::Vector3f sun_direction_W{0.35f, -0.45f, 0.82f};  // towards the sun
  float fog_start_m{300.0f};
  float fog_end_m{1500.0f};
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // Uploads the level's actors (meshes, materials, textures). Warns once on
  // `warnings` for each texture that cannot be decoded (the base colour stays).
  virtual void SetLevel(const scene::Level& level, const TextureDecoder& decoder) = 0;
  // Renders the level (movable actors at `actor_poses`, indexed like
  // Level::actors; empty: load-time poses), `robots` as posed and, when given,
  // the overlay on top.
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
// when the context cannot be made.
std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend = RendererBackend::kOsMesa);

}  // namespace sandbox::render
