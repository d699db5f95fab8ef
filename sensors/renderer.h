#pragma once
// Offscreen rendering of the world (OSMesa, OpenGL 4.5 core, llvmpipe): level
// meshes with their base colours and textures, the robots skinned as posed,
// a directional sun, sky colour and distance fog; colour and depth read back.
// GL stays inside renderer.cc; nothing else sees a GL header.
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

namespace sandbox::sensors {

struct RgbaImage {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> rgba;  // row 0 at the top
};

// Decodes an embedded (compressed) texture or an image file; returns "" or
// why it cannot. The app supplies one (OpenCV); the renderer itself decodes nothing.
using TextureDecoder = std::function<std::string(const scene::EmbeddedTexture* embedded,
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

// Debug marks drawn over the scene, hidden behind nearer surfaces: points and
// short line segments in world coordinates, each with its own colour. They
// change the colour image only, never the depth image.
struct Overlay {
  std::vector<Eigen::Vector3d> points_W;
  std::vector<Eigen::Vector3f> point_rgb;  // one per point, 0..1
  std::vector<Eigen::Vector3d> lines_W;    // two ends per segment
  std::vector<Eigen::Vector3f> line_rgb;   // one per segment
  float point_size_px{3.0f};

  void AddPoint(const Eigen::Vector3d& p_W, const Eigen::Vector3f& rgb);
  void AddLine(const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W, const Eigen::Vector3f& rgb);
  bool empty() const { return points_W.empty() && lines_W.empty(); }
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
  virtual const std::vector<std::string>& warnings() const = 0;
  virtual std::string description() const = 0;  // "OpenGL 4.5 (Core Profile) Mesa ... llvmpipe"
};

enum class RendererBackend { kOsMesa };

// Creates a renderer with its own offscreen context. Throws std::runtime_error
// when the context cannot be made.
std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend = RendererBackend::kOsMesa);

}  // namespace sandbox::sensors
