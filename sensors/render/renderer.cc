#include "sensors/render/renderer.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

namespace sandbox::render {
namespace {

const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec2 lightmap_uv;
uniform mat4 model;       // object to camera-centred world (world axes, origin at the camera)
uniform mat4 view_proj;   // camera-centred world to clip
out vec3 world_normal;
out vec2 tex_uv;
out vec2 baked_uv;
out float distance_m;
void main() {
  vec4 p = model * vec4(position, 1.0);
  world_normal = mat3(model) * normal;
  tex_uv = uv;
  baked_uv = lightmap_uv;
  distance_m = length(p.xyz);
  gl_Position = view_proj * p;
}
)";

const char* kFragmentShader = R"(#version 450 core
in vec3 world_normal;
in vec2 tex_uv;
in vec2 baked_uv;
in float distance_m;
uniform vec4 base_color;
uniform bool has_lightmap;        // baked lighting replaces the sun (Quake 3 maps)
uniform sampler2D lightmap;
uniform bool has_texture;
uniform sampler2D base_texture;
uniform vec3 sun;
uniform vec3 sky;
uniform vec2 fog;  // start, end
out vec4 color;
void main() {
  vec4 albedo = base_color;
  if (has_texture) albedo *= texture(base_texture, tex_uv);
  vec3 n = normalize(world_normal);
  float light = 0.35 + 0.65 * abs(dot(n, sun));  // two-sided: thin surfaces lit from both sides
  // Quake 3 stores lightmaps at half brightness (its "overbright" bit).
  vec3 lit = has_lightmap ? albedo.rgb * min(2.0 * texture(lightmap, baked_uv).rgb, vec3(1.0))
                          : albedo.rgb * light;
  float f = clamp((distance_m - fog.x) / max(fog.y - fog.x, 1e-3), 0.0, 1.0);
  color = vec4(mix(lit, sky, f), albedo.a);
}
)";

// The overlay: coloured points and lines, pulled 0.2% towards the camera so
// that marks lying on a surface are not hidden by it.
const char* kOverlayVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;  // camera-centred world
layout(location = 1) in vec3 rgb;
uniform mat4 view_proj;
out vec3 mark_rgb;
void main() {
  mark_rgb = rgb;
  gl_Position = view_proj * vec4(0.998 * position, 1.0);
}
)";

const char* kOverlayFragmentShader = R"(#version 450 core
in vec3 mark_rgb;
out vec4 color;
void main() { color = vec4(mark_rgb, 1.0); }
)";

// The sky: a full-screen triangle behind everything, light at the horizon
// (the haze colour, so distant ground fades into it), deeper overhead, with the sun's disc.
const char* kSkyVertexShader = R"(#version 450 core
out vec2 ndc;
void main() {
  ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(ndc, 0.0, 1.0);
}
)";

const char* kSkyFragmentShader = R"(#version 450 core
in vec2 ndc;
uniform mat4 clip_to_world;  // directions: clip to camera-centred world
uniform vec3 horizon;
uniform vec3 zenith;
uniform vec3 sun;
out vec4 color;
void main() {
  vec4 far_point = clip_to_world * vec4(ndc, 0.5, 1.0);
  vec3 d = normalize(far_point.xyz / far_point.w);
  float up = clamp(d.z, 0.0, 1.0);
  vec3 c = mix(horizon, zenith, pow(up, 0.6));
  float s = dot(d, sun);
  c = mix(c, vec3(1.0, 0.98, 0.9), smoothstep(0.99985, 0.99995, s));
  color = vec4(c, 1.0);
}
)";

GLuint Compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("Renderer: shader does not compile: ") + log);
  }
  return shader;
}

GLuint Link(const char* vertex, const char* fragment) {
  const GLuint program = glCreateProgram();
  glAttachShader(program, Compile(GL_VERTEX_SHADER, vertex));
  glAttachShader(program, Compile(GL_FRAGMENT_SHADER, fragment));
  glLinkProgram(program);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) throw std::runtime_error("Renderer: shaders do not link");
  return program;
}

// A mesh on the GPU.
struct GpuMesh {
  GLuint vao{0}, positions{0}, normals{0}, uvs{0}, lightmap_uvs{0}, indices{0};
  GLsizei index_count{0};
  int material{-1};
};

GpuMesh Upload(const std::vector<Eigen::Vector3f>& positions,
               const std::vector<Eigen::Vector3f>& normals, const std::vector<Eigen::Vector2f>& uvs,
               const std::vector<Eigen::Vector2f>& lightmap_uvs,
               const std::vector<std::uint32_t>& indices, int material, GLenum usage) {
  GpuMesh mesh;
  mesh.material = material;
  mesh.index_count = GLsizei(indices.size());
  glGenVertexArrays(1, &mesh.vao);
  glBindVertexArray(mesh.vao);
  auto attribute = [&](GLuint* buffer, GLuint location, int size, const void* data,
                       std::size_t bytes) {
    glGenBuffers(1, buffer);
    glBindBuffer(GL_ARRAY_BUFFER, *buffer);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(bytes), data, usage);
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
  };
  attribute(&mesh.positions, 0, 3, positions.data(), positions.size() * 12);
  attribute(&mesh.normals, 1, 3, normals.data(), normals.size() * 12);
  if (uvs.size() == positions.size()) {
    attribute(&mesh.uvs, 2, 2, uvs.data(), uvs.size() * 8);
  } else {
    glDisableVertexAttribArray(2);
    glVertexAttrib2f(2, 0.f, 0.f);
  }
  if (lightmap_uvs.size() == positions.size()) {
    attribute(&mesh.lightmap_uvs, 3, 2, lightmap_uvs.data(), lightmap_uvs.size() * 8);
  } else {
    glDisableVertexAttribArray(3);
    glVertexAttrib2f(3, 0.f, 0.f);
  }
  glGenBuffers(1, &mesh.indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * 4), indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  return mesh;
}

// Static geometry, merged: one buffer set per material and ground cell, with
// its bounds for culling. Positions are relative to `origin` (double) so that
// floats keep their precision in large levels.
struct StaticChunk {
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs, lightmap_uvs;
  std::vector<std::uint32_t> indices;
  Eigen::AlignedBox3f bounds;
  bool any_uvs{false}, any_lightmap_uvs{false};
};
constexpr double kChunkCell_m = 128.0;

// False when the box lies wholly outside one plane of the frustum of clip
// matrix M (rows of M combined as in Gribb and Hartmann).
bool InFrustum(const Eigen::Matrix4f& M, const Eigen::AlignedBox3f& box) {
  for (int plane = 0; plane < 6; ++plane) {
    const Eigen::Vector4f p = M.row(3) + (plane % 2 == 0 ? 1.f : -1.f) * M.row(plane / 2);
    // The box corner furthest along the plane's normal.
    const Eigen::Vector3f corner(p.x() >= 0 ? box.max().x() : box.min().x(),
                                 p.y() >= 0 ? box.max().y() : box.min().y(),
                                 p.z() >= 0 ? box.max().z() : box.min().z());
    if (p.head<3>().dot(corner) + p.w() < 0.f) return false;
  }
  return true;
}

// Column-major float matrix of X relative to the camera position (double).
Eigen::Matrix4f Relative(const Eigen::Affine3d& X, const Eigen::Vector3d& camera) {
  Eigen::Affine3d rel = X;
  rel.translation() -= camera;
  return rel.matrix().cast<float>();
}

class OsMesaRenderer : public Renderer {
 public:
  OsMesaRenderer() {
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              24,
                              OSMESA_PROFILE,
                              OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              4,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              5,
                              0};
    context_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (context_ == nullptr)
      throw std::runtime_error("Renderer: cannot create an OSMesa GL 4.5 context");
    backing_.resize(4);
    if (!OSMesaMakeCurrent(context_, backing_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      throw std::runtime_error("Renderer: cannot make the OSMesa context current");
    }
    description_ = std::string("OpenGL ") + reinterpret_cast<const char*>(glGetString(GL_VERSION)) +
                   ", " + reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    program_ = Link(kVertexShader, kFragmentShader);
    overlay_program_ = Link(kOverlayVertexShader, kOverlayFragmentShader);
    overlay_view_proj_ = glGetUniformLocation(overlay_program_, "view_proj");
    // GL 4.5 calls libOSMesa does not export are found through it.
    clip_control_ = reinterpret_cast<PFNGLCLIPCONTROLPROC>(OSMesaGetProcAddress("glClipControl"));
    if (clip_control_ == nullptr) throw std::runtime_error("Renderer: no glClipControl");
    sky_program_ = Link(kSkyVertexShader, kSkyFragmentShader);
    const char* sky_names[] = {"clip_to_world", "horizon", "zenith", "sun"};
    for (int i = 0; i < 4; ++i) sky_uniforms_[i] = glGetUniformLocation(sky_program_, sky_names[i]);
    glGenVertexArrays(1, &overlay_vao_);
    glGenBuffers(2, overlay_buffers_);
    auto location = [&](const char* name) { return glGetUniformLocation(program_, name); };
    uniforms_ = {location("model"),       location("view_proj"),    location("base_color"),
                 location("has_texture"), location("base_texture"), location("sun"),
                 location("sky"),         location("fog"),          location("has_lightmap"),
                 location("lightmap")};
  }
  ~OsMesaRenderer() override { OSMesaDestroyContext(context_); }

  void SetLevel(const scene::Level& level, const TextureDecoder& decoder) override {
    level_ = &level;
    MergeStatic(level);
    BuildHorizon(level);
    for (std::size_t a = 0; a < level.actors.size(); ++a) {
      if (!level.actors[a].movable) continue;  // merged above
      for (const scene::Mesh& mesh : level.actors[a].meshes) {
        actor_meshes_.push_back(
            {int(a), Upload(mesh.positions_A, mesh.normals_A, mesh.uvs, mesh.lightmap_uvs,
                            mesh.indices, mesh.material, GL_STATIC_DRAW)});
      }
    }
    // Textures: decoded once, by the decoder the app gives.
    for (std::size_t m = 0; m < level.materials.size(); ++m) {
      const scene::Material& material = level.materials[m];
      const bool embedded = material.base_color_texture_embedded >= 0 &&
                            material.base_color_texture_embedded < int(level.textures.size());
      if (embedded || !material.base_color_texture_path.empty()) {
        RgbaImage image;
        const scene::EmbeddedTexture* texture =
            embedded ? &level.textures[std::size_t(material.base_color_texture_embedded)] : nullptr;
        const std::string problem =
            decoder ? decoder(texture, material.base_color_texture_path, &image) : "no decoder";
        if (problem.empty() && image.width > 0 && image.height > 0) {
          textures_[int(m)] = UploadTexture(image, GL_REPEAT);
        } else {
          warnings_.push_back("material '" + material.name + "': texture " +
                              (embedded ? "(embedded)" : material.base_color_texture_path) +
                              " cannot be read (" + (problem.empty() ? "empty" : problem) +
                              "); drawn with its base colour");
        }
      }
      if (material.lightmap_texture_embedded >= 0 &&
          material.lightmap_texture_embedded < int(level.textures.size())) {
        RgbaImage image;
        const std::string problem =
            decoder ? decoder(&level.textures[std::size_t(material.lightmap_texture_embedded)], "",
                              &image)
                    : "no decoder";
        if (problem.empty() && image.width > 0 && image.height > 0) {
          lightmaps_[int(m)] = UploadTexture(image, GL_CLAMP_TO_EDGE);
        } else {
          warnings_.push_back("material '" + material.name + "': its lightmap cannot be read (" +
                              (problem.empty() ? "empty" : problem) + "); lit by the sun instead");
        }
      }
    }
  }

  void Render(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
              const std::vector<const scene::RobotState*>& robots, const RenderSettings& settings,
              Frame* frame, const Overlay* overlay) override {
    view.ValidateOrThrow();
    Resize(view.width, view.height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, view.width, view.height);
    glClearColor(settings.sky_rgb.x(), settings.sky_rgb.y(), settings.sky_rgb.z(), 1.f);
    clip_control_(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDepthFunc(GL_GREATER);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);

    // Camera-centred world: rotation only in the view; positions relative to the camera.
    const Eigen::Vector3d camera = view.X_WC.translation();
    Eigen::Matrix3d R_EyeCam;
    R_EyeCam << 0, -1, 0, 0, 0, 1, -1, 0, 0;  // camera x forward, y left, z up -> GL eye
    Eigen::Matrix4d view_rotation = Eigen::Matrix4d::Identity();
    view_rotation.topLeftCorner<3, 3>() = R_EyeCam * view.X_WC.linear().transpose();
    const double f = 1.0 / std::tan(0.5 * view.fov_y_rad),
                 aspect = double(view.width) / view.height;
    // Reversed depth: 1 at near, 0 at far (with a float buffer, even precision over the range).
    const double n = view.near_m, fa = view.far_m;
    Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
    projection(0, 0) = f / aspect;
    projection(1, 1) = f;
    projection(2, 2) = n / (fa - n);
    projection(2, 3) = fa * n / (fa - n);
    projection(3, 2) = -1.0;
    const Eigen::Matrix4d view_proj_d = projection * view_rotation;
    const Eigen::Matrix4f view_proj = view_proj_d.cast<float>();
    const Eigen::Vector3f sun = settings.sun_direction_W.normalized();
    DrawSky(view_proj_d.inverse().cast<float>(), settings.sky_rgb, sun);
    glUseProgram(program_);
    glUniformMatrix4fv(uniforms_.view_proj, 1, GL_FALSE, view_proj.data());
    glUniform3f(uniforms_.sun, sun.x(), sun.y(), sun.z());
    glUniform3f(uniforms_.sky, settings.sky_rgb.x(), settings.sky_rgb.y(), settings.sky_rgb.z());
    // The haze: the level's visibility when it gives one.
    const bool default_fog = settings.fog_end_m == RenderSettings{}.fog_end_m;
    const double visibility = level_->horizon ? level_->horizon->visibility_m : 0.0;
    if (default_fog && visibility > 0.0) {
      glUniform2f(uniforms_.fog, float(0.1 * visibility), float(visibility));
    } else {
      glUniform2f(uniforms_.fog, settings.fog_start_m, settings.fog_end_m);
    }
    glUniform1i(uniforms_.base_texture, 0);
    glUniform1i(uniforms_.lightmap, 1);

    // Opaque first, then the translucent (water) on top. Static chunks outside
    // the view are skipped.
    const Eigen::Matrix4f static_model =
        Relative(Eigen::Affine3d(Eigen::Translation3d(origin_)), camera);
    const Eigen::Matrix4f static_clip = view_proj * static_model;
    if (horizon_.index_count > 0) {
      const Eigen::Vector3f& rgb = level_->horizon->rgb;
      DrawWith(horizon_, static_model, Eigen::Vector4f(rgb.x(), rgb.y(), rgb.z(), 1.f), 0);
      glDrawElements(GL_TRIANGLES, horizon_.index_count, GL_UNSIGNED_INT, nullptr);
    }
    DrawTerrain(view_proj, camera);
    for (const bool translucent : {false, true}) {
      for (const auto& [bounds, mesh] : static_meshes_) {
        if (IsTranslucent(mesh.material) != translucent || !InFrustum(static_clip, bounds))
          continue;
        Draw(mesh, static_model);
      }
      for (const auto& [actor, mesh] : actor_meshes_) {
        if (IsTranslucent(mesh.material) != translucent) continue;
        const Eigen::Isometry3d& X_WA = actor_poses.size() == level_->actors.size()
                                            ? actor_poses[std::size_t(actor)]
                                            : level_->actors[std::size_t(actor)].X_WA;
        Draw(mesh, Relative(Eigen::Affine3d(X_WA.matrix()), camera));
      }
    }
    // Robots: their posed meshes, uploaded afresh.
    for (std::size_t r = 0; r < robots.size(); ++r) {
      const scene::RobotState& state = *robots[r];
      std::vector<GpuMesh>& meshes = robot_meshes_[&state.model()];
      const auto& model = state.model();
      for (std::size_t m = 0; m < model.meshes.size(); ++m) {
        if (meshes.size() <= m) {
          meshes.push_back(Upload(state.positions_B(int(m)), state.normals_B(int(m)),
                                  model.meshes[m].bind.uvs, model.meshes[m].bind.lightmap_uvs,
                                  model.meshes[m].bind.indices, model.meshes[m].bind.material,
                                  GL_DYNAMIC_DRAW));
        } else {
          glBindBuffer(GL_ARRAY_BUFFER, meshes[m].positions);
          glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(state.positions_B(int(m)).size() * 12),
                          state.positions_B(int(m)).data());
          glBindBuffer(GL_ARRAY_BUFFER, meshes[m].normals);
          glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(state.normals_B(int(m)).size() * 12),
                          state.normals_B(int(m)).data());
        }
        Draw(meshes[m], Relative(Eigen::Affine3d(state.pose().matrix()), camera));
      }
    }
    // Read back, bottom row first in GL (flipped below); depth before the overlay.
    const int w = view.width, h = view.height;
    pixels_.resize(std::size_t(w) * h * 4);
    depth_.resize(std::size_t(w) * h);
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth_.data());
    if (overlay != nullptr && !overlay->empty()) DrawOverlay(*overlay, camera, view_proj);
    glFinish();
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels_.data());
    frame->width = w;
    frame->height = h;
    frame->rgb.resize(std::size_t(w) * h * 3);
    frame->depth_m.resize(std::size_t(w) * h);
    for (int y = 0; y < h; ++y) {
      const std::size_t src = std::size_t(h - 1 - y) * std::size_t(w),
                        dst = std::size_t(y) * std::size_t(w);
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c)
          frame->rgb[3 * (dst + std::size_t(x)) + std::size_t(c)] =
              pixels_[4 * (src + std::size_t(x)) + std::size_t(c)];
        const double d = depth_[src + std::size_t(x)];
        frame->depth_m[dst + std::size_t(x)] =
            d <= 0.0 ? std::numeric_limits<float>::infinity() : float(n * fa / (d * (fa - n) + n));
      }
    }
  }

  void SetTerrain(std::shared_ptr<const scene::TileList> tiles) override {
    terrain_ = std::move(tiles);
  }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  std::string description() const override { return description_; }

 private:
  // Static actors' meshes in world coordinates, grouped by material and by
  // ground cell, uploaded once: few draws, and whole cells culled.
  void MergeStatic(const scene::Level& level) {
    origin_ = level.bounds_W().isEmpty() ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                         : Eigen::Vector3d(level.bounds_W().center());
    std::map<std::tuple<int, long, long>, StaticChunk> chunks;
    for (const scene::Actor& actor : level.actors) {
      if (actor.movable) continue;
      const Eigen::Matrix3d R = actor.X_WA.linear();
      for (const scene::Mesh& mesh : actor.meshes) {
        // This mesh's vertices already copied into each chunk.
        std::map<std::tuple<int, long, long>, std::vector<std::int64_t>> copied;
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
          Eigen::Vector3d p[3];
          for (int k = 0; k < 3; ++k) {
            p[k] = actor.X_WA * mesh.positions_A[mesh.indices[t + std::size_t(k)]].cast<double>() -
                   origin_;
          }
          const Eigen::Vector3d c = (p[0] + p[1] + p[2]) / 3.0;
          const std::tuple<int, long, long> key{mesh.material,
                                                std::lround(std::floor(c.x() / kChunkCell_m)),
                                                std::lround(std::floor(c.y() / kChunkCell_m))};
          StaticChunk& chunk = chunks[key];
          std::vector<std::int64_t>& map = copied[key];
          if (map.empty()) map.assign(mesh.positions_A.size(), -1);
          const bool has_uvs = mesh.uvs.size() == mesh.positions_A.size();
          const bool has_lightmap_uvs = mesh.lightmap_uvs.size() == mesh.positions_A.size();
          chunk.any_uvs = chunk.any_uvs || has_uvs;
          chunk.any_lightmap_uvs = chunk.any_lightmap_uvs || has_lightmap_uvs;
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = mesh.indices[t + std::size_t(k)];
            if (map[v] < 0) {
              map[v] = std::int64_t(chunk.positions.size());
              chunk.positions.push_back(p[k].cast<float>());
              chunk.normals.push_back((R * mesh.normals_A[v].cast<double>()).cast<float>());
              chunk.uvs.push_back(has_uvs ? mesh.uvs[v] : Eigen::Vector2f::Zero());
              chunk.lightmap_uvs.push_back(has_lightmap_uvs ? mesh.lightmap_uvs[v]
                                                            : Eigen::Vector2f::Zero());
              chunk.bounds.extend(chunk.positions.back());
            }
            chunk.indices.push_back(std::uint32_t(map[v]));
          }
        }
      }
    }
    for (auto& [key, chunk] : chunks) {
      if (!chunk.any_uvs) chunk.uvs.clear();
      if (!chunk.any_lightmap_uvs) chunk.lightmap_uvs.clear();
      static_meshes_.push_back(
          {chunk.bounds, Upload(chunk.positions, chunk.normals, chunk.uvs, chunk.lightmap_uvs,
                                chunk.indices, std::get<0>(key), GL_STATIC_DRAW)});
    }
  }

  bool IsTranslucent(int material) const {
    return material >= 0 && material < int(level_->materials.size()) &&
           level_->materials[std::size_t(material)].base_color.w() < 0.999f;
  }

  // An RGBA8 texture with mipmaps.
  static GLuint UploadTexture(const RgbaImage& image, GLint wrap) {
    GLuint id = 0;
    glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, image.rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
    return id;
  }

  // A mesh with its own colour and texture (0: none), all of it.
  void DrawWith(const GpuMesh& mesh, const Eigen::Matrix4f& model, const Eigen::Vector4f& color,
                GLuint texture) {
    glUniformMatrix4fv(uniforms_.model, 1, GL_FALSE, model.data());
    glUniform4f(uniforms_.base_color, color.x(), color.y(), color.z(), color.w());
    glUniform1i(uniforms_.has_texture, texture != 0 && mesh.uvs != 0);
    glUniform1i(uniforms_.has_lightmap, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, texture);
    glBindVertexArray(mesh.vao);
  }

  void DrawSky(const Eigen::Matrix4f& clip_to_world, const Eigen::Vector3f& horizon,
               const Eigen::Vector3f& sun) {
    glUseProgram(sky_program_);
    glUniformMatrix4fv(sky_uniforms_[0], 1, GL_FALSE, clip_to_world.data());
    glUniform3f(sky_uniforms_[1], horizon.x(), horizon.y(), horizon.z());
    const Eigen::Vector3f zenith = 0.55f * horizon + Eigen::Vector3f(0.02f, 0.08f, 0.25f);
    glUniform3f(sky_uniforms_[2], zenith.x(), zenith.y(), zenith.z());
    glUniform3f(sky_uniforms_[3], sun.x(), sun.y(), sun.z());
    glDepthMask(GL_FALSE);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(overlay_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
  }

  // Terrain tiles: uploaded when first seen, freed when gone; a coarse tile
  // leaves out the blocks a fine tile covers.
  void DrawTerrain(const Eigen::Matrix4f& view_proj, const Eigen::Vector3d& camera) {
    std::map<const scene::TerrainTile*, TileGpu> kept;
    std::set<std::uint64_t> fine;
    if (terrain_) {
      for (const auto& tile : *terrain_) {
        if (tile->id.lod == 0) fine.insert(tile->id.key());
      }
    }
    const int factor = level_->terrain ? level_->terrain->coarse_factor : 1;
    const Eigen::Vector4f plain(level_->horizon ? level_->horizon->rgb.x() : 0.45f,
                                level_->horizon ? level_->horizon->rgb.y() : 0.5f,
                                level_->horizon ? level_->horizon->rgb.z() : 0.35f, 1.f);
    for (const auto& tile : terrain_ ? *terrain_ : scene::TileList{}) {
      auto found = tile_gpu_.find(tile.get());
      TileGpu gpu;
      if (found != tile_gpu_.end()) {
        gpu = found->second;
        tile_gpu_.erase(found);
      } else {
        gpu = UploadTile(*tile);
      }
      kept[tile.get()] = gpu;
      if (tile->indices.empty() || tile->bounds_W.isEmpty()) continue;
      const Eigen::AlignedBox3f box((tile->bounds_W.min() - camera).cast<float>(),
                                    (tile->bounds_W.max() - camera).cast<float>());
      if (!InFrustum(view_proj, box)) continue;
      const Eigen::Matrix4f model =
          Relative(Eigen::Affine3d(Eigen::Translation3d(tile->origin_W)), camera);
      DrawWith(gpu.mesh, model, gpu.texture ? Eigen::Vector4f(1.f, 1.f, 1.f, 1.f) : plain,
               gpu.texture);
      // Index ranges: the surface (coarse: without the blocks fine tiles cover), the skirts.
      std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
      if (tile->id.lod == 0) {
        ranges.push_back({0, std::uint32_t(tile->indices.size())});
      } else {
        for (int k = 0; k + 1 < int(tile->block_first.size()); ++k) {
          const scene::TileId under{0, tile->id.file, tile->id.tx * factor + k % factor,
                                    tile->id.ty * factor + k / factor};
          if (fine.count(under.key())) continue;
          const std::uint32_t a = tile->block_first[std::size_t(k)],
                              b = tile->block_first[std::size_t(k) + 1];
          if (!ranges.empty() && ranges.back().second == a) {
            ranges.back().second = b;
          } else if (b > a) {
            ranges.push_back({a, b});
          }
        }
      }
      ranges.push_back({std::uint32_t(tile->indices.size()),
                        std::uint32_t(tile->indices.size() + tile->skirt_indices.size())});
      for (const auto& [a, b] : ranges) {
        if (b <= a) continue;
        glDrawElements(GL_TRIANGLES, GLsizei(b - a), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(std::uintptr_t(a) * 4));
      }
    }
    for (auto& [tile, gpu] : tile_gpu_) Free(gpu);
    tile_gpu_.swap(kept);
  }

  struct TileGpu {
    GpuMesh mesh;
    GLuint texture{0};
  };

  TileGpu UploadTile(const scene::TerrainTile& tile) {
    std::vector<std::uint32_t> indices = tile.indices;
    indices.insert(indices.end(), tile.skirt_indices.begin(), tile.skirt_indices.end());
    TileGpu gpu;
    gpu.mesh = Upload(tile.positions, tile.normals, tile.uvs, {}, indices, -1, GL_STATIC_DRAW);
    if (!tile.texture_rgba.empty()) {
      gpu.texture = UploadTexture({tile.texture_width, tile.texture_height, tile.texture_rgba},
                                  GL_CLAMP_TO_EDGE);
    }
    return gpu;
  }

  static void Free(const TileGpu& gpu) {
    const GpuMesh& m = gpu.mesh;
    const GLuint buffers[] = {m.positions, m.normals, m.uvs, m.lightmap_uvs, m.indices};
    for (const GLuint buffer : buffers) {
      if (buffer != 0) glDeleteBuffers(1, &buffer);
    }
    glDeleteVertexArrays(1, &m.vao);
    if (gpu.texture != 0) glDeleteTextures(1, &gpu.texture);
  }

  // The ground beyond the level: a grid around the level's hole, its cells
  // growing with distance out to 1000 km, falling away with the Earth's curvature.
  void BuildHorizon(const scene::Level& level) {
    if (!level.horizon || level.horizon->hole_W.isEmpty()) return;
    const scene::Horizon& h = *level.horizon;
    constexpr double kExtent_m = 1.0e6;
    auto axis = [&](double lo, double hi) {
      std::vector<double> out;
      for (double d = 500.0 * (1.5 - 1.0), k = 1.5; lo - d > -kExtent_m;
           k *= 1.5, d = 500.0 * (k - 1.0)) {
        out.insert(out.begin(), lo - d);
      }
      out.insert(out.begin(), -kExtent_m);
      for (int i = 0; i <= 8; ++i) out.push_back(lo + (hi - lo) * i / 8.0);
      for (double d = 500.0 * (1.5 - 1.0), k = 1.5; hi + d < kExtent_m;
           k *= 1.5, d = 500.0 * (k - 1.0)) {
        out.push_back(hi + d);
      }
      out.push_back(kExtent_m);
      return out;
    };
    const std::vector<double> xs = axis(h.hole_W.min().x(), h.hole_W.max().x());
    const std::vector<double> ys = axis(h.hole_W.min().y(), h.hole_W.max().y());
    std::vector<Eigen::Vector3f> positions, normals;
    std::vector<std::uint32_t> indices;
    for (const double y : ys) {
      for (const double x : xs) {
        const double drop = (x * x + y * y) / (2.0 * scene::kEarthRadius_m);
        positions.push_back((Eigen::Vector3d(x, y, h.height_m - drop) - origin_).cast<float>());
        normals.push_back(
            Eigen::Vector3d(-x / scene::kEarthRadius_m, -y / scene::kEarthRadius_m, 1.0)
                .normalized()
                .cast<float>());
      }
    }
    const std::uint32_t nx = std::uint32_t(xs.size());
    for (std::uint32_t j = 0; j + 1 < ys.size(); ++j) {
      for (std::uint32_t i = 0; i + 1 < nx; ++i) {
        const Eigen::Vector2d centre(0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]));
        if (h.hole_W.contains(centre)) continue;
        const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
        for (const std::uint32_t v : {a, b, d, a, d, c}) indices.push_back(v);
      }
    }
    horizon_ = Upload(positions, normals, {}, {}, indices, -1, GL_STATIC_DRAW);
  }

  void Draw(const GpuMesh& mesh, const Eigen::Matrix4f& model) {
    glUniformMatrix4fv(uniforms_.model, 1, GL_FALSE, model.data());
    Eigen::Vector4f color(0.8f, 0.8f, 0.8f, 1.f);
    if (mesh.material >= 0 && mesh.material < int(level_->materials.size())) {
      color = level_->materials[std::size_t(mesh.material)].base_color;
    }
    glUniform4f(uniforms_.base_color, color.x(), color.y(), color.z(), color.w());
    const auto texture = textures_.find(mesh.material);
    glUniform1i(uniforms_.has_texture, texture != textures_.end() && mesh.uvs != 0);
    if (texture != textures_.end()) {
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, texture->second);
    }
    const auto lightmap = lightmaps_.find(mesh.material);
    glUniform1i(uniforms_.has_lightmap, lightmap != lightmaps_.end() && mesh.lightmap_uvs != 0);
    if (lightmap != lightmaps_.end()) {
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, lightmap->second);
      glActiveTexture(GL_TEXTURE0);
    }
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
  }

  // Points and lines with one colour each, relative to the camera.
  void DrawOverlay(const Overlay& overlay, const Eigen::Vector3d& camera,
                   const Eigen::Matrix4f& view_proj) {
    if (overlay.point_rgb.size() != overlay.points_W.size() ||
        overlay.line_rgb.size() * 2 != overlay.lines_W.size()) {
      throw std::invalid_argument("Renderer: an overlay needs one colour per point and per line");
    }
    overlay_positions_.clear();
    overlay_colors_.clear();
    for (std::size_t i = 0; i < overlay.points_W.size(); ++i) {
      overlay_positions_.push_back((overlay.points_W[i] - camera).cast<float>());
      overlay_colors_.push_back(overlay.point_rgb[i]);
    }
    for (std::size_t i = 0; i < overlay.lines_W.size(); ++i) {
      overlay_positions_.push_back((overlay.lines_W[i] - camera).cast<float>());
      overlay_colors_.push_back(overlay.line_rgb[i / 2]);
    }
    glUseProgram(overlay_program_);
    glUniformMatrix4fv(overlay_view_proj_, 1, GL_FALSE, view_proj.data());
    glBindVertexArray(overlay_vao_);
    const std::pair<GLuint, const std::vector<Eigen::Vector3f>*> attributes[] = {
        {overlay_buffers_[0], &overlay_positions_}, {overlay_buffers_[1], &overlay_colors_}};
    for (GLuint location = 0; location < 2; ++location) {
      glBindBuffer(GL_ARRAY_BUFFER, attributes[location].first);
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(attributes[location].second->size() * 12),
                   attributes[location].second->data(), GL_STREAM_DRAW);
      glEnableVertexAttribArray(location);
      glVertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    glDisable(GL_BLEND);
    glPointSize(overlay.point_size_px);
    glDrawArrays(GL_POINTS, 0, GLsizei(overlay.points_W.size()));
    glDrawArrays(GL_LINES, GLsizei(overlay.points_W.size()), GLsizei(overlay.lines_W.size()));
    glBindVertexArray(0);
  }

  void Resize(int width, int height) {
    if (width == width_ && height == height_) return;
    if (fbo_ == 0) {
      glGenFramebuffers(1, &fbo_);
      glGenRenderbuffers(2, buffers_);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glBindRenderbuffer(GL_RENDERBUFFER, buffers_[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, buffers_[0]);
    glBindRenderbuffer(GL_RENDERBUFFER, buffers_[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, buffers_[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("Renderer: framebuffer of " + std::to_string(width) + " x " +
                               std::to_string(height) + " is incomplete");
    }
    width_ = width, height_ = height;
  }

  OSMesaContext context_{nullptr};
  std::vector<std::uint8_t> backing_;
  std::string description_;
  GLuint program_{0}, fbo_{0}, buffers_[2]{0, 0};
  GLuint overlay_program_{0}, overlay_vao_{0}, overlay_buffers_[2]{0, 0};
  GLint overlay_view_proj_{-1};
  std::vector<Eigen::Vector3f> overlay_positions_, overlay_colors_;
  struct {
    GLint model, view_proj, base_color, has_texture, base_texture, sun, sky, fog, has_lightmap,
        lightmap;
  } uniforms_{};
  int width_{0}, height_{0};
  const scene::Level* level_{nullptr};
  Eigen::Vector3d origin_{Eigen::Vector3d::Zero()};  // of the static chunks
  std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> static_meshes_;
  std::vector<std::pair<int, GpuMesh>> actor_meshes_;  // movable actors'
  std::map<const scene::RobotModel*, std::vector<GpuMesh>> robot_meshes_;
  std::shared_ptr<const scene::TileList> terrain_;
  std::map<const scene::TerrainTile*, TileGpu> tile_gpu_;
  GpuMesh horizon_;
  GLuint sky_program_{0};
  PFNGLCLIPCONTROLPROC clip_control_{nullptr};
  GLint sky_uniforms_[4]{-1, -1, -1, -1};
  std::map<int, GLuint> textures_;   // by material
  std::map<int, GLuint> lightmaps_;  // by material
  std::vector<std::string> warnings_;
  std::vector<std::uint8_t> pixels_;
  std::vector<float> depth_;
};

}  // namespace

std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend) {
  switch (backend) {
    case RendererBackend::kOsMesa:
      return std::make_unique<OsMesaRenderer>();
  }
  return nullptr;
}

}  // namespace sandbox::render
