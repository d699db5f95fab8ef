#pragma once
// Offscreen rendering of the world (OSMesa, OpenGL 4.5 core, llvmpipe): level
// meshes with their base colours and textures, the robots skinned as posed,
// a directional sun, sky colour and distance fog; colour and depth read back.
// GL stays inside renderer.cc; nothing else sees a GL header.
//
// Threads: a Renderer and everything it renders belong to one thread (the
// render thread); make it there.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "scene/level.h"
#include "scene/robot_state.h"

namespace sandbox::sensors {

struct RgbaImage {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> rgba;  // row 0 at the top
};

// Decodes an embedded (compressed) texture or an image file; false when it
// cannot. The app supplies one (OpenCV); the renderer itself decodes nothing.
using TextureDecoder = std::function<bool(const scene::EmbeddedTexture* embedded,
                                          const std::string& path, RgbaImage* image)>;

// A pinhole camera: pose X_WC with x forward, y left, z up (like a robot body).
struct CameraView {
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};
  int width{640};
  int height{480};
  double fov_y_rad{0.9};  // vertical field of view
  double near_m{0.1};
  double far_m{2000.0};
  // Throws std::invalid_argument naming the field: sizes from 1 to 8192,
  // a field of view in (0, pi), 0 < near < far.
  void ValidateOrThrow() const;
};

struct RenderSettings {
  Eigen::Vector3f sky_rgb{0.62f, 0.76f, 0.92f};
  Eigen::Vector3f sun_direction_W{0.35f, -0.45f, 0.82f};  // towards the sun
  float fog_start_m{300.0f};
  float fog_end_m{1500.0f};
};

struct Frame {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> rgb;  // row 0 at the top
  std::vector<float> depth_m;     // distance along the optical axis; +inf where sky
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // Uploads the level's actors (meshes, materials, textures). Warns once on
  // `warnings` for each texture that cannot be decoded (the base colour stays).
  virtual void SetLevel(const scene::Level& level, const TextureDecoder& decoder) = 0;
  // Renders the level (movable actors at `actor_poses`, indexed like
  // Level::actors; empty: load-time poses) and `robots` as posed.
  virtual void Render(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
                      const std::vector<const scene::RobotState*>& robots,
                      const RenderSettings& settings, Frame* frame) = 0;
  virtual const std::vector<std::string>& warnings() const = 0;
  virtual std::string description() const = 0;  // "OpenGL 4.5 (Core Profile) Mesa ... llvmpipe"
};

enum class RendererBackend { kOsMesa };

// Creates a renderer with its own offscreen context. Throws std::runtime_error
// when the context cannot be made.
std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend = RendererBackend::kOsMesa);

}  // namespace sandbox::sensors
