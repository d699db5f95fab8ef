// Over 600 lines: one renderer class (context, shaders, scene, passes) until issue 38
// splits it into parts with one job each.
#include "sensors/render/renderer.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
#include <malloc.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <tuple>

#include "sensors/render/deferred_shading.h"
#include "sensors/render/detail_textures.h"
#include "sensors/render/hidden_faces.h"
#include "sensors/render/mesh_lods.h"
#include "sensors/render/segmentation.h"
#include "sensors/render/shaders.h"
#include "sensors/render/shadow_cascades.h"

namespace sandbox::render {

Quality ParseQuality(const std::string& word) {
  if (word == "plain") return Quality::kPlain;
  if (word == "fast") return Quality::kFast;
  if (word == "high") return Quality::kHigh;
  throw std::invalid_argument("quality must be \"fast\" or \"high\" (or \"plain\"), got '" + word +
                              "'");
}

RenderSettings RenderSettings::Preset(Quality quality) {
  RenderSettings settings;
  settings.shadows = quality == Quality::kHigh;
  settings.msaa_samples = 0;
  settings.fxaa = quality == Quality::kHigh;
  settings.gamma_correct = quality != Quality::kPlain;
  settings.materials = quality != Quality::kPlain;
  return settings;
}

namespace {

constexpr double kPatternPeriod_m = 6900.0;  // the ground's and water's patterns repeat here
constexpr int kDetailPx = 256;
constexpr float kSnowLine_m = 2800.f;
constexpr int kMovingShadowPx = 512;  // the moving casters' map (deferred shading)

GLuint Compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("Renderer: shader does not compile: ") + log);
  }
  return shader;
}

GLuint Link(const char* vertex, const char* fragment) {
  const GLuint program = glCreateProgram();
  const GLuint v = Compile(GL_VERTEX_SHADER, vertex), f = Compile(GL_FRAGMENT_SHADER, fragment);
  glAttachShader(program, v);
  glAttachShader(program, f);
  glLinkProgram(program);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("Renderer: shaders do not link: ") + log);
  }
  return program;
}

void FlipRows(RgbaImage* image) {
  const std::size_t row = 4 * std::size_t(image->width);
  for (int y = 0; y < image->height / 2; ++y) {
    std::swap_ranges(
        image->rgba.begin() + std::ptrdiff_t(row * std::size_t(y)),
        image->rgba.begin() + std::ptrdiff_t(row * std::size_t(y + 1)),
        image->rgba.begin() + std::ptrdiff_t(row * std::size_t(image->height - 1 - y)));
  }
}

// A mesh on the GPU, with what it is drawn as.
struct GpuMesh {
  GLuint vao{0}, positions{0}, normals{0}, uvs{0}, lightmap_uvs{0}, colors{0}, segments{0},
      indices{0};
  GLsizei index_count{0};             // of the mesh as given (level 0)
  std::vector<MeshLods::Level> lods;  // its levels of detail in `indices`; empty: level 0 only
  // What moves (robots, movable actors) takes one level a frame for every
  // pass, shadows too (its own shadow then falls on the surface drawn);
  // what stays, its last level in colour.
  bool moving{false};
  mutable std::size_t level{0};
  HiddenBackFaces hidden;  // where its back faces cannot be seen, in its own frame
  int material{-1};
  int surface{-1};  // a scene::Surface over the material's, -1: the material's
  std::uint32_t segment_base{0};
  GLuint triangle_segments{0}, triangle_segment_buffer{0};  // a buffer texture, 0: none
};

// What a mesh is made of, for Upload.
struct MeshData {
  const std::vector<Eigen::Vector3f>* positions{nullptr};
  const std::vector<Eigen::Vector3f>* normals{nullptr};
  const std::vector<Eigen::Vector2f>* uvs{nullptr};
  const std::vector<Eigen::Vector2f>* lightmap_uvs{nullptr};
  const std::vector<Eigen::Vector4f>* colors{nullptr};
  const std::vector<std::uint32_t>* vertex_segments{nullptr};
  const std::vector<std::uint32_t>* indices{nullptr};
  const MeshLods* lods{nullptr};  // instead of `indices`: the levels of detail
};

GpuMesh Upload(const MeshData& data, int material, GLenum usage) {
  GpuMesh mesh;
  mesh.material = material;
  const std::vector<std::uint32_t>& indices = data.lods ? data.lods->indices : *data.indices;
  mesh.index_count = GLsizei(data.lods ? data.lods->levels[0].count : indices.size());
  if (data.lods != nullptr && data.lods->levels.size() > 1) mesh.lods = data.lods->levels;
  const std::size_t n = data.positions->size();
  glGenVertexArrays(1, &mesh.vao);
  glBindVertexArray(mesh.vao);
  auto attribute = [&](GLuint* buffer, GLuint location, int size, const void* bytes,
                       std::size_t count) {
    glGenBuffers(1, buffer);
    glBindBuffer(GL_ARRAY_BUFFER, *buffer);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(count), bytes, usage);
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
  };
  attribute(&mesh.positions, 0, 3, data.positions->data(), n * 12);
  attribute(&mesh.normals, 1, 3, data.normals->data(), data.normals->size() * 12);
  if (data.uvs != nullptr && data.uvs->size() == n) {
    attribute(&mesh.uvs, 2, 2, data.uvs->data(), n * 8);
  } else {
    glVertexAttrib2f(2, 0.f, 0.f);
  }
  if (data.lightmap_uvs != nullptr && data.lightmap_uvs->size() == n) {
    attribute(&mesh.lightmap_uvs, 3, 2, data.lightmap_uvs->data(), n * 8);
  } else {
    glVertexAttrib2f(3, 0.f, 0.f);
  }
  if (data.colors != nullptr && data.colors->size() == n) {
    attribute(&mesh.colors, 4, 4, data.colors->data(), n * 16);
  } else {
    glVertexAttrib4f(4, 1.f, 1.f, 1.f, 1.f);
  }
  if (data.vertex_segments != nullptr && data.vertex_segments->size() == n) {
    glGenBuffers(1, &mesh.segments);
    glBindBuffer(GL_ARRAY_BUFFER, mesh.segments);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 4), data.vertex_segments->data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(5);
    glVertexAttribIPointer(5, 1, GL_UNSIGNED_INT, 0, nullptr);
  } else {
    glVertexAttribI1ui(5, 0);
  }
  glGenBuffers(1, &mesh.indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * 4), indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  return mesh;
}

void Free(const GpuMesh& m) {
  const GLuint buffers[] = {m.positions, m.normals,  m.uvs,     m.lightmap_uvs,
                            m.colors,    m.segments, m.indices, m.triangle_segment_buffer};
  for (const GLuint buffer : buffers) {
    if (buffer != 0) glDeleteBuffers(1, &buffer);
  }
  if (m.triangle_segments != 0) glDeleteTextures(1, &m.triangle_segments);
  glDeleteVertexArrays(1, &m.vao);
}

// `indices` with vertices equal in every attribute (and `ids`) joined, for
// the simplifier (an attribute not given per vertex does not count).
std::vector<std::uint32_t> WeldedIndices(const std::vector<Eigen::Vector3f>& positions,
                                         const std::vector<Eigen::Vector3f>& normals,
                                         const std::vector<Eigen::Vector2f>& uvs,
                                         const std::vector<Eigen::Vector2f>& lightmap_uvs,
                                         const std::vector<Eigen::Vector4f>& colors,
                                         const std::vector<std::uint32_t>* ids,
                                         const std::vector<std::uint32_t>& indices) {
  const std::size_t n = positions.size();
  auto stream = [n](const auto& values) {
    return VertexStream{values.size() == n ? values.data() : nullptr, sizeof(values[0])};
  };
  return WeldIdentical(indices, n,
                       {stream(positions), stream(normals), stream(uvs), stream(lightmap_uvs),
                        stream(colors), ids ? stream(*ids) : VertexStream{nullptr, 4}});
}

// A per-triangle id table for gl_PrimitiveID lookups.
void SetTriangleSegments(GpuMesh* mesh, const std::vector<std::uint32_t>& ids) {
  if (ids.empty()) return;
  glGenBuffers(1, &mesh->triangle_segment_buffer);
  glBindBuffer(GL_TEXTURE_BUFFER, mesh->triangle_segment_buffer);
  glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(ids.size() * 4), ids.data(), GL_STATIC_DRAW);
  glGenTextures(1, &mesh->triangle_segments);
  glBindTexture(GL_TEXTURE_BUFFER, mesh->triangle_segments);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_R32UI, mesh->triangle_segment_buffer);
}

// Static geometry, merged: one buffer set per material, surface and ground
// cell, with its bounds for culling. Positions are relative to `origin`
// (double) so that floats keep their precision in large levels.
struct StaticChunk {
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs, lightmap_uvs;
  std::vector<Eigen::Vector4f> colors;
  std::vector<std::uint32_t> segments, indices;
  Eigen::AlignedBox3f bounds;
  HiddenBackFaces hidden;  // of the meshes it holds pieces of (one kind, see MergeStatic)
  bool any_uvs{false}, any_lightmap_uvs{false}, any_colors{false};
};
constexpr double kChunkCell_m = 128.0;

// False when the box lies wholly outside one plane of the frustum of clip
// matrix M (rows of M combined as in Gribb and Hartmann). Orthographic
// shadow boxes too.
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

// The passes a frame is drawn in.
enum class Pass {
  kColor,   // colour (and, without multisampling, segment and normal too)
  kData,    // segment and normal only, one sample at each pixel centre
  kShadow,  // depth from the sun
};

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
    MakeCurrent();
    description_ = std::string("OpenGL ") + reinterpret_cast<const char*>(glGetString(GL_VERSION)) +
                   ", " + reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    // GL 4.5 calls libOSMesa does not export are found through it.
    clip_control_ = reinterpret_cast<PFNGLCLIPCONTROLPROC>(OSMesaGetProcAddress("glClipControl"));
    if (clip_control_ == nullptr) throw std::runtime_error("Renderer: no glClipControl");
    for (const bool masked : {false, true}) {
      const std::string fragment = std::string("#version 450 core\n#define ALPHA_MASK ") +
                                   (masked ? "1" : "0") + "\n" + shaders::kShadowFragment;
      const GLuint program = shadow_programs_[masked] =
          Link(shaders::kShadowVertex, fragment.c_str());
      shadow_uniforms_[masked] = {glGetUniformLocation(program, "model"),
                                  glGetUniformLocation(program, "view_proj"),
                                  glGetUniformLocation(program, "alpha_cutoff")};
      glUseProgram(program);
      glUniform1i(glGetUniformLocation(program, "base_texture"), 0);
    }
    overlay_program_ = Link(shaders::kOverlayVertex, shaders::kOverlayFragment);
    sky_program_ = Link(shaders::kFullScreenVertex, shaders::kSkyFragment);
    edge_filter_program_ = Link(shaders::kFullScreenVertex, shaders::kEdgeFilterFragment);
    glGenVertexArrays(1, &overlay_vao_);
    glGenBuffers(2, overlay_buffers_);
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &max_anisotropy_);
    if (glGetError() != GL_NO_ERROR) max_anisotropy_ = 1.f;
    glGenSamplers(1, &anisotropic_);
    glSamplerParameteri(anisotropic_, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glSamplerParameteri(anisotropic_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    program_key_ = -1;
    // The ground's detail textures.
    const std::vector<std::uint8_t> detail = MakeDetailTextures(kDetailPx);
    detail_cpu_ = DetailTextures(detail, kDetailPx, kNumDetailLayers);
    deferred_ = std::make_unique<DeferredShader>();
    glGenTextures(1, &detail_);
    glBindTexture(GL_TEXTURE_2D_ARRAY, detail_);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA8, kDetailPx, kDetailPx, kNumDetailLayers, 0,
                 GL_RGBA, GL_UNSIGNED_BYTE, detail.data());
    glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  ~OsMesaRenderer() override { OSMesaDestroyContext(context_); }

  void SetLevel(const scene::Level& level, const TextureDecoder& decoder) override {
    MakeCurrent();
    level_ = &level;
    static_shadow_keys_.clear();
    legend_ = std::make_unique<SegmentationLegend>(level);
    water_level_ = -1e9f;
    for (const scene::Actor& actor : level.actors) {
      if (actor.surface == scene::Surface::kWater && !actor.bounds_W.isEmpty()) {
        water_level_ = std::max(water_level_, float(actor.bounds_W.max().z()));
      }
    }
    MergeStatic(level);
    BuildHorizon(level);
    for (std::size_t a = 0; a < level.actors.size(); ++a) {
      if (!level.actors[a].movable) continue;  // merged above
      Eigen::AlignedBox3d& bounds_A = actor_bounds_A_[int(a)];
      for (const scene::Mesh& mesh : level.actors[a].meshes) {
        for (const Eigen::Vector3f& p : mesh.positions_A) bounds_A.extend(p.cast<double>());
        const MeshLods lods = MakeMeshLods(
            mesh.positions_A, WeldedIndices(mesh.positions_A, mesh.normals_A, mesh.uvs,
                                            mesh.lightmap_uvs, mesh.colors, nullptr, mesh.indices));
        GpuMesh gpu = Upload({&mesh.positions_A, &mesh.normals_A, &mesh.uvs, &mesh.lightmap_uvs,
                              &mesh.colors, nullptr, nullptr, &lods},
                             mesh.material, GL_STATIC_DRAW);
        gpu.surface = level.actors[a].surface ? int(*level.actors[a].surface) : -1;
        gpu.segment_base = legend_->actor(int(a));
        gpu.moving = true;
        if (DrawnWhole(mesh.material, gpu.surface)) {
          gpu.hidden = HiddenBackFaces::Of(mesh.positions_A, mesh.indices);
        }
        actor_meshes_.push_back({int(a), gpu});
      }
    }
    // Textures: decoded once, by the decoder the app gives.
    for (std::size_t m = 0; m < level.materials.size(); ++m) {
      const scene::Material& material = level.materials[m];
      auto load = [&](int embedded_index, const std::string& path, const std::string& what,
                      const std::string& fallback, GLint wrap, bool srgb,
                      std::map<int, GLuint>* to) {
        const bool embedded = embedded_index >= 0 && embedded_index < int(level.textures.size());
        if (!embedded && path.empty()) return;
        RgbaImage image;
        const scene::EmbeddedTexture* texture =
            embedded ? &level.textures[std::size_t(embedded_index)] : nullptr;
        const std::string problem = decoder ? decoder(texture, path, &image) : "no decoder";
        if (problem.empty() && image.width > 0 && image.height > 0) {
          // Model files' texture coordinates come from assimp with v = 0 at the
          // image's bottom row (it flips glTF's); GL's t = 0 is the first row given.
          if (what != "lightmap") FlipRows(&image);
          (*to)[int(m)] = UploadTexture(image, wrap, srgb);
        } else {
          warnings_.push_back("material '" + material.name + "': " + what + " " +
                              (embedded ? "(embedded)" : path) + " cannot be read (" +
                              (problem.empty() ? "empty" : problem) + "); " + fallback);
        }
      };
      load(material.base_color_texture_embedded, material.base_color_texture_path, "texture",
           "drawn with its base colour", GL_REPEAT, true, &textures_);
      load(material.normal_texture_embedded, material.normal_texture_path, "normal map",
           "drawn without it", GL_REPEAT, false, &normal_maps_);
      if (material.lightmap_texture_embedded >= 0) {
        load(material.lightmap_texture_embedded, "", "lightmap", "lit by the sun instead",
             GL_CLAMP_TO_EDGE, true, &lightmaps_);
      }
    }
    // The robots' bone groups, per triangle, for segmentation.
    for (std::size_t r = 0; r < level.robots.size(); ++r) {
      std::vector<std::vector<std::uint32_t>>& groups = robot_groups_[&level.robots[r]];
      for (std::size_t m = 0; m < level.robots[r].meshes.size(); ++m) {
        groups.push_back(BoneGroupPerTriangle(level.robots[r], int(m)));
      }
    }
  }

  void Render(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
              const std::vector<const scene::RobotState*>& robots, const RenderSettings& settings,
              Frame* frame, const Overlay* overlay) override {
    MakeCurrent();
    view.ValidateOrThrow();
    if (overlay != nullptr && (overlay->point_rgb.size() != overlay->points_W.size() ||
                               overlay->line_rgb.size() * 2 != overlay->lines_W.size())) {
      throw std::invalid_argument("Renderer: an overlay needs one colour per point and per line");
    }
    settings.ValidateOrThrow();
    const ImageKinds kinds = settings.images;
    const int samples = settings.msaa_samples > 1 ? settings.msaa_samples : 0;
    Resize(view.width, view.height, samples);
    clip_control_(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    actor_poses_ = &actor_poses;
    UploadRobots(robots);
    UploadTerrain();

    // Camera-centred world: rotation only in the view; positions relative to the camera.
    camera_ = view.X_WC.translation();
    cull_hidden_back_faces_ = settings.cull_hidden_back_faces;
    Eigen::Matrix3d R_EyeCam;
    R_EyeCam << 0, -1, 0, 0, 0, 1, -1, 0, 0;  // camera x forward, y left, z up -> GL eye
    Eigen::Matrix4d view_rotation = Eigen::Matrix4d::Identity();
    view_rotation.topLeftCorner<3, 3>() = R_EyeCam * view.X_WC.linear().transpose();
    const double f = 1.0 / std::tan(0.5 * view.fov_y_rad),
                 aspect = double(view.width) / view.height;
    near_reach_m_ = view.near_m * std::sqrt(1.0 + (1.0 + aspect * aspect) / (f * f));
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

    // Levels of detail in colour-only frames; depth, segmentation and normals are measurements.
    lod_px_ = kinds == kColorImage ? settings.lod_px : 0.f;
    pixel_angle_ = float(2.0 * std::tan(0.5 * view.fov_y_rad) / view.height);
    ChooseMovingLevels();

    // Shadow maps first (they need the scene's upload above).
    const bool shadows = settings.shadows && kinds & kColorImage && sun.z() > 0.02f;
    // Deferred shading (on the CPU) for the gamma-correct looks without multisampling.
    const bool deferred =
        kinds & kColorImage && settings.deferred && settings.gamma_correct && samples == 0;
    std::vector<ShadowCascade> cascades;
    if (shadows) {
      cascades = FitShadowCascades(view, sun.cast<double>(), settings.shadow_distance_m,
                                   settings.shadow_cascades, settings.shadow_map_px, 1500.0);
      DrawShadowMaps(cascades, sun, settings.shadow_map_px, deferred);
    }

    // The look; each program gets this frame's uniforms at its first use in it.
    ++frame_number_;
    gamma_ = settings.gamma_correct;
    const int look = (settings.gamma_correct ? kGamma : 0) | (settings.materials ? kMaterials : 0) |
                     (shadows ? kShadows : 0);
    SetFrameUniforms(view, view_proj, settings, sun, cascades);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDisable(GL_CULL_FACE);
    const GLenum color_only[] = {GL_COLOR_ATTACHMENT0};
    const GLenum all[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    const GLenum data_only[] = {GL_NONE, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    const bool want_data = (kinds & (kSegmentationImage | kNormalsImage)) != 0;
    const bool want_depth = (kinds & kDepthImage) != 0;
    const Eigen::Vector3f horizon = settings.sky_rgb;

    // Colour: into the multisampled buffer, or straight into the data buffer
    // (then with segment and normal in the same pass).
    const Eigen::Matrix4f clip_to_world = view_proj_d.inverse().cast<float>();
    if (deferred) {
      // The opaque surfaces into the G-buffer, read back; the nearest
      // translucent surfaces into a layer of their own over that depth; each
      // pixel lit once on the CPU.
      // (Without segment and normal images, into a framebuffer without them:
      // llvmpipe pays for every target attached.)
      glBindFramebuffer(GL_FRAMEBUFFER, want_data ? gbuffer_fbo_ : gbuffer_lean_fbo_);
      glViewport(0, 0, view.width, view.height);
      ClearTargets(want_data, horizon, /*keep_color=*/true);
      const GLenum data = want_data ? GL_COLOR_ATTACHMENT1 : GL_NONE;
      const GLenum normals = want_data ? GL_COLOR_ATTACHMENT2 : GL_NONE;
      const GLenum opaque[] = {GL_COLOR_ATTACHMENT0, data, normals, GL_COLOR_ATTACHMENT3};
      glDrawBuffers(4, opaque);
      look_ = look | kGBuffer | (want_data ? kData : 0);
      translucent_drawn_ = false;
      DrawScene(Pass::kColor, view_proj, [&] {
        ReadLayer(view.width, view.height, &opaque_);
        glBindFramebuffer(GL_FRAMEBUFFER, want_data ? translucent_fbo_ : translucent_lean_fbo_);
        const GLenum layer[] = {GL_COLOR_ATTACHMENT0, data, normals, GL_COLOR_ATTACHMENT3};
        glDrawBuffers(4, layer);
        look_ = look | kGBuffer | kTranslucent | (want_data ? kData : 0);
      });
      if (translucent_drawn_) ReadLayer(view.width, view.height, &translucent_);
      deferred_->Shade(LightingOf(settings, clip_to_world), detail_cpu_, opaque_,
                       translucent_drawn_ ? &translucent_ : nullptr, &lit_);
    } else if (kinds & kColorImage) {
      glBindFramebuffer(GL_FRAMEBUFFER, samples > 0 ? msaa_fbo_ : fbo_);
      glViewport(0, 0, view.width, view.height);
      const bool data_too = samples == 0 && want_data;
      ClearTargets(data_too, horizon);
      glDrawBuffers(data_too ? 3 : 1, data_too ? all : color_only);
      look_ = look | (data_too ? kData : 0);
      DrawScene(Pass::kColor, view_proj, [&] {
        glDrawBuffers(1, color_only);
        DrawSky(clip_to_world, horizon, sun);
        glDrawBuffers(data_too ? 3 : 1, data_too ? all : color_only);
      });
      if (samples > 0) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glDrawBuffers(1, color_only);
        glBlitFramebuffer(0, 0, view.width, view.height, 0, 0, view.width, view.height,
                          GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
      }
      if (settings.fxaa) FilterEdges(view.width, view.height);
    }
    // Depth, segment and normal at pixel centres, when colour did not give
    // them (the overlay is hidden by this depth too).
    const bool marks = overlay != nullptr && !overlay->empty() && (kinds & kColorImage);
    if ((want_data || want_depth || marks) && (samples > 0 || !(kinds & kColorImage))) {
      glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
      glViewport(0, 0, view.width, view.height);
      ClearTargets(true, horizon, /*keep_color=*/true);
      glDrawBuffers(3, data_only);
      look_ = kDataOnly;
      DrawScene(Pass::kData, view_proj);
    }

    // Read back, bottom row first in GL (flipped below); depth before the overlay.
    const int w = view.width, h = view.height;
    const std::size_t count = std::size_t(w) * std::size_t(h);
    frame->width = w;
    frame->height = h;
    frame->kinds = kinds;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    if (want_depth) {
      depth_.resize(count);
      glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth_.data());
      frame->depth_m.resize(count);
      // Reversed depth d to metres: n f / (d (f - n) + n); 0 (nothing drawn): infinity.
      const float scale = float(fa - n), numerator = float(n * fa), near = float(n);
      for (int y = 0; y < h; ++y) {
        const float* src = &depth_[std::size_t(h - 1 - y) * std::size_t(w)];
        float* dst = &frame->depth_m[std::size_t(y) * std::size_t(w)];
        for (int x = 0; x < w; ++x) {
          dst[x] = src[x] <= 0.f ? std::numeric_limits<float>::infinity()
                                 : numerator / (src[x] * scale + near);
        }
      }
    } else {
      frame->depth_m.clear();
    }
    if (kinds & kSegmentationImage) {
      segment_.resize(count);
      glReadBuffer(GL_COLOR_ATTACHMENT1);
      glReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, segment_.data());
      frame->segment.resize(count);
      for (int y = 0; y < h; ++y) {
        std::copy_n(&segment_[std::size_t(h - 1 - y) * std::size_t(w)], w,
                    &frame->segment[std::size_t(y) * std::size_t(w)]);
      }
    } else {
      frame->segment.clear();
    }
    if (kinds & kNormalsImage) {
      normal_.resize(3 * count);
      glReadBuffer(GL_COLOR_ATTACHMENT2);
      glReadPixels(0, 0, w, h, GL_RGB, GL_FLOAT, normal_.data());
      frame->normal_C.resize(3 * count);
      for (int y = 0; y < h; ++y) {
        std::copy_n(&normal_[3 * std::size_t(h - 1 - y) * std::size_t(w)], 3 * w,
                    &frame->normal_C[3 * std::size_t(y) * std::size_t(w)]);
      }
    } else {
      frame->normal_C.clear();
    }
    if (deferred) {
      // The edge filter and the overlay on the CPU's image; rows flipped.
      const std::vector<std::uint8_t>* image = &lit_;
      if (settings.fxaa) {
        deferred_->FilterEdges(lit_, w, h, &filtered_);
        image = &filtered_;
      }
      if (marks) {
        glBindFramebuffer(GL_FRAMEBUFFER, overlay_fbo_);
        const float clear[] = {0.f, 0.f, 0.f, 0.f};
        glDrawBuffers(1, color_only);
        glClearBufferfv(GL_COLOR, 0, clear);
        DrawOverlay(*overlay, view_proj);
        overlay_rgba_.resize(count);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, overlay_fbo_);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, overlay_rgba_.data());
      }
      frame->rgb.resize(3 * count);
      for (int y = 0; y < h; ++y) {
        const std::size_t row = std::size_t(h - 1 - y) * std::size_t(w);
        const std::uint8_t* src = &(*image)[4 * row];
        std::uint8_t* dst = &frame->rgb[3 * std::size_t(y) * std::size_t(w)];
        // Four bytes a pixel written three apart (the fourth overwritten next).
        for (int x = 0; x + 1 < w; ++x) std::memcpy(dst + 3 * x, src + 4 * x, 4);
        std::memcpy(dst + 3 * (w - 1), src + 4 * (w - 1), 3);
        for (int x = 0; marks && x < w; ++x) {
          const std::uint32_t mark = overlay_rgba_[row + std::size_t(x)];
          if ((mark >> 24) == 0) continue;
          dst[3 * x] = std::uint8_t(mark), dst[3 * x + 1] = std::uint8_t(mark >> 8),
                  dst[3 * x + 2] = std::uint8_t(mark >> 16);
        }
      }
    } else if (kinds & kColorImage) {
      glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
      if (marks) {
        glDrawBuffers(1, color_only);
        DrawOverlay(*overlay, view_proj);
      }
      glFinish();
      pixels_.resize(4 * count);
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels_.data());
      frame->rgb.resize(3 * count);
      for (int y = 0; y < h; ++y) {
        const std::uint8_t* src = &pixels_[4 * std::size_t(h - 1 - y) * std::size_t(w)];
        std::uint8_t* dst = &frame->rgb[3 * std::size_t(y) * std::size_t(w)];
        for (int x = 0; x < w; ++x) {
          dst[3 * x] = src[4 * x];
          dst[3 * x + 1] = src[4 * x + 1];
          dst[3 * x + 2] = src[4 * x + 2];
        }
      }
    } else {
      frame->rgb.clear();
    }
  }

  void SetTerrain(std::shared_ptr<const scene::TileList> tiles) override {
    terrain_ = std::move(tiles);
  }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  std::string description() const override { return description_; }

 private:
  // This renderer's context, current on the calling thread (another
  // renderer made on the thread since, or destroyed, leaves it not current).
  void MakeCurrent() {
    if (OSMesaGetCurrentContext() == context_) return;
    if (!OSMesaMakeCurrent(context_, backing_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      throw std::runtime_error("Renderer: cannot make the OSMesa context current");
    }
  }

  // The scene program for a surface (0 plain, 1 terrain, 2 water), a mesh's
  // features (kTexture ...) and the pass's look (look_): made at its first
  // use, in use, with this frame's uniforms. Fixed sampler units: 0 base
  // colour, 1 lightmap, 2 normal map, 3 detail, 4 shadow map, 5 triangle segments.
  void UseProgram(int surface, int features) {
    int key = look_ | features;
    if (look_ & kDataOnly) {
      // Segment and normal only: what decides which fragments exist, and the ids.
      key = kDataOnly | (features & (kAlphaMask | kTriangleSegments));
      if (features & kAlphaMask) key |= features & (kTexture | kVertexColors);
    } else {
      key |= std::clamp(surface, 0, 2);
      if (!(look_ & kData)) key &= ~kTriangleSegments;
      if (!(look_ & kMaterials)) key &= ~kNormalMap;
    }
    if (key == program_key_) return;
    program_key_ = key;
    auto found = programs_.find(key);
    const bool made = found == programs_.end();
    if (made) {
      std::string fragment = "#version 450 core\n";
      const std::pair<const char*, int> defines[] = {
          {"SURFACE", key & 3},
          {"GAMMA", (key & kGamma) != 0},
          {"MATERIALS", (key & kMaterials) != 0},
          {"SHADOWS", (key & kShadows) != 0},
          {"DATA", (key & kData) != 0},
          {"DATA_ONLY", (key & kDataOnly) != 0},
          {"TEXTURE", (key & kTexture) != 0},
          {"LIGHTMAP", (key & kLightmap) != 0},
          {"NORMAL_MAP", (key & kNormalMap) != 0},
          {"ALPHA_MASK", (key & kAlphaMask) != 0},
          {"VERTEX_COLORS", (key & kVertexColors) != 0},
          {"TRIANGLE_SEGMENTS", (key & kTriangleSegments) != 0},
          {"GBUFFER", (key & kGBuffer) != 0},
          {"TRANSLUCENT", (key & kTranslucent) != 0}};
      for (const auto& [name, value] : defines) {
        fragment += "#define " + std::string(name) + " " + std::to_string(value) + "\n";
      }
      fragment += shaders::kShading;
      fragment += shaders::kSceneFragment;
      found =
          programs_.emplace(key, SceneProgram{Link(shaders::kSceneVertex, fragment.c_str()), {}})
              .first;
    }
    program_ = &found->second;
    glUseProgram(program_->id);
    if (made) {
      const std::pair<const char*, int> units[] = {{"base_texture", 0},   {"lightmap", 1},
                                                   {"normal_texture", 2}, {"detail", 3},
                                                   {"shadow_map", 4},     {"segments", 5}};
      for (const auto& [name, unit] : units) glUniform1i(U(name), unit);
    }
    if (program_->frame != frame_number_) {
      program_->frame = frame_number_;
      ApplyFrameUniforms();
    }
  }
  // A uniform of the scene program in use.
  GLint U(const char* name) {
    auto found = program_->uniforms.find(name);
    if (found != program_->uniforms.end()) return found->second;
    return program_->uniforms[name] = glGetUniformLocation(program_->id, name);
  }

  void ClearTargets(bool data_targets, const Eigen::Vector3f& sky, bool keep_color = false) {
    glDepthMask(GL_TRUE);
    glClearDepth(0.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    if (!keep_color) {
      const float color[] = {sky.x(), sky.y(), sky.z(), 1.f};
      glClearBufferfv(GL_COLOR, 0, color);
    }
    if (data_targets) {
      const GLuint zero_id[] = {0, 0, 0, 0};
      const float zero[] = {0.f, 0.f, 0.f, 0.f};
      const GLenum all[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
      glDrawBuffers(3, all);
      glClearBufferuiv(GL_COLOR, 1, zero_id);
      glClearBufferfv(GL_COLOR, 2, zero);
    }
  }

  // This frame's uniforms, for every scene program used in it. Colours in
  // the shading space (linear light with gamma-correct shading).
  void SetFrameUniforms(const CameraView& view, const Eigen::Matrix4f& view_proj,
                        const RenderSettings& settings, const Eigen::Vector3f& sun,
                        const std::vector<ShadowCascade>& cascades) {
    FrameUniforms& u = frame_uniforms_;
    u.view_proj = view_proj;
    u.sun = sun;
    u.horizon = Shading(settings.sky_rgb, false);
    u.zenith = Shading(Zenith(settings.sky_rgb), false);
    // The haze: the level's visibility when it gives one.
    const bool default_fog = settings.fog_end_m == RenderSettings{}.fog_end_m;
    const double visibility = level_->horizon ? level_->horizon->visibility_m : 0.0;
    if (!settings.haze) {
      u.fog = Eigen::Vector2f::Zero();
    } else if (default_fog && visibility > 0.0) {
      u.fog = Eigen::Vector2f(float(0.1 * visibility), float(visibility));
    } else {
      u.fog = Eigen::Vector2f(settings.fog_start_m, settings.fog_end_m);
    }
    u.camera_z = float(camera_.z());
    u.camera_xy = Eigen::Vector2f(float(std::fmod(camera_.x(), kPatternPeriod_m)),
                                  float(std::fmod(camera_.y(), kPatternPeriod_m)));
    const Eigen::Vector3f grass =
        level_->horizon ? level_->horizon->rgb : Eigen::Vector3f(0.36f, 0.45f, 0.24f);
    const Eigen::Vector3f layers[4] = {
        grass, {0.45f, 0.42f, 0.38f}, {0.93f, 0.94f, 0.96f}, {0.74f, 0.67f, 0.48f}};
    for (int i = 0; i < 4; ++i) u.ground[i] = Shading(layers[i], false);
    u.view_axis = view.X_WC.linear().col(0).cast<float>();
    u.R_CW = view.X_WC.linear().transpose().cast<float>();
    u.cascades = cascades;
    // Anisotropic filtering of material textures (the sampler repeats at the edges).
    const float anisotropy = float(settings.anisotropy);
    if (anisotropy > max_anisotropy_) {
      throw std::invalid_argument("Renderer: anisotropy " + std::to_string(settings.anisotropy) +
                                  " is beyond this GL's " + std::to_string(int(max_anisotropy_)));
    }
    if (anisotropy > 1.f) {
      glSamplerParameterf(anisotropic_, GL_TEXTURE_MAX_ANISOTROPY, anisotropy);
      glBindSampler(0, anisotropic_);
      glBindSampler(2, anisotropic_);
    } else {
      glBindSampler(0, 0);
      glBindSampler(2, 0);
    }
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D_ARRAY, detail_);
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_2D_ARRAY, shadow_map_);
    glActiveTexture(GL_TEXTURE0);
  }

  void ApplyFrameUniforms() {
    const FrameUniforms& u = frame_uniforms_;
    glUniformMatrix4fv(U("view_proj"), 1, GL_FALSE, u.view_proj.data());
    glUniform3fv(U("sun"), 1, u.sun.data());
    glUniform3fv(U("horizon"), 1, u.horizon.data());
    glUniform3fv(U("zenith"), 1, u.zenith.data());
    glUniform2fv(U("fog"), 1, u.fog.data());
    glUniform1f(U("camera_z"), u.camera_z);
    glUniform2fv(U("camera_xy"), 1, u.camera_xy.data());
    glUniform1f(U("water_level"), water_level_);
    glUniform1f(U("snow_line"), kSnowLine_m);
    glUniform3fv(U("ground_rgb"), 4, u.ground[0].data());
    glUniform3fv(U("view_axis"), 1, u.view_axis.data());
    glUniformMatrix3fv(U("world_to_camera"), 1, GL_FALSE, u.R_CW.data());
    glUniform1i(U("cascades"), int(u.cascades.size()));
    for (std::size_t c = 0; c < u.cascades.size(); ++c) {
      const std::string i = "[" + std::to_string(c) + "]";
      const Eigen::Matrix4f M = u.cascades[c].light_clip.cast<float>();
      glUniformMatrix4fv(U(("shadow_clip" + i).c_str()), 1, GL_FALSE, M.data());
      glUniform1f(U(("cascade_far" + i).c_str()), float(u.cascades[c].far_m));
      glUniform1f(U(("shadow_texel" + i).c_str()), float(u.cascades[c].texel_m));
    }
  }

  // A colour to the shading space: linear light with gamma-correct shading,
  // else display (sRGB) values. `linear`: the colour is given linear (glTF).
  Eigen::Vector3f Shading(const Eigen::Vector3f& rgb, bool linear) const {
    Eigen::Vector3f out;
    for (int i = 0; i < 3; ++i) {
      const float c = std::clamp(rgb[i], 0.f, 1.f);
      if (gamma_ && !linear) {
        out[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
      } else if (!gamma_ && linear) {
        out[i] = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
      } else {
        out[i] = c;
      }
    }
    return out;
  }

  static Eigen::Vector3f Zenith(const Eigen::Vector3f& horizon) {
    return 0.55f * horizon + Eigen::Vector3f(0.02f, 0.08f, 0.25f);
  }

  // Everything in the world, in one pass. Opaque first, then the translucent
  // (water) on top; whatever lies outside the view is skipped.
  // Opaque surfaces nearest first (robots, movable actors, level chunks by
  // distance, terrain, the ground beyond), so that llvmpipe's early depth
  // test skips the shading of what is hidden; then `between` (the sky, into
  // what no surface covered); then translucent surfaces far to near.
  void DrawScene(Pass pass, const Eigen::Matrix4f& view_proj,
                 const std::function<void()>& between = {}) {
    pass_ = pass;
    view_proj_ = view_proj;
    const Eigen::Matrix4f static_model =
        Relative(Eigen::Affine3d(Eigen::Translation3d(origin_)), camera_);
    const Eigen::Matrix4f static_clip = view_proj * static_model;
    const Eigen::Vector3f eye_S = (camera_ - origin_).cast<float>();  // in the chunks' frame
    auto actor_model = [&](int actor) {
      return Relative(Eigen::Affine3d(ActorPose(actor).matrix()), camera_);
    };
    const Eigen::Vector3f static_to_camera = (origin_ - camera_).cast<float>();
    auto chunk_error = [&](std::size_t i) {
      const Eigen::AlignedBox3f& bounds = static_meshes_[i].first;
      return LodError(
          Eigen::AlignedBox3f(bounds.min() + static_to_camera, bounds.max() + static_to_camera));
    };
    // The level's chunks in view, nearest first.
    static_order_.clear();
    for (std::size_t i = 0; i < static_meshes_.size(); ++i) {
      const auto& [bounds, mesh] = static_meshes_[i];
      if (!InFrustum(static_clip, bounds)) continue;
      static_order_.push_back({bounds.exteriorDistance(eye_S), i});
    }
    std::sort(static_order_.begin(), static_order_.end());

    // (Shadow maps draw what moves and what stays apart.)
    const bool moving = pass != Pass::kShadow || shadow_casters_ != Casters::kStill;
    const bool still = pass != Pass::kShadow || shadow_casters_ != Casters::kMoving;
    if (moving) {
      for (std::size_t r = 0; r < posed_robots_.size(); ++r) {
        const auto& [pose, meshes] = posed_robots_[r];
        // Its closed meshes as posed: the eye outside the robot's box.
        const bool outside = robot_bounds_W_[r].exteriorDistance(camera_) > near_reach_m_;
        for (const GpuMesh* mesh : meshes) {
          CullBackFacesIf(outside && mesh->hidden.shape() == HiddenBackFaces::Shape::kSolid);
          Draw(*mesh, Relative(Eigen::Affine3d(pose.matrix()), camera_));
        }
      }
      for (const auto& [actor, mesh] : actor_meshes_) {
        if (IsTranslucent(mesh)) continue;
        CullHiddenBackFaces(mesh, (ActorPose(actor).inverse() * camera_).cast<float>());
        Draw(mesh, actor_model(actor));
      }
    }
    if (still) {
      for (const auto& [distance, i] : static_order_) {
        const GpuMesh& mesh = static_meshes_[i].second;
        lod_error_m_ = chunk_error(i);
        if (IsTranslucent(mesh)) continue;
        CullHiddenBackFaces(mesh, eye_S);
        Draw(mesh, static_model);
      }
      glDisable(GL_CULL_FACE);
      DrawTerrain();
    }
    if (horizon_.index_count > 0 && pass != Pass::kShadow) {
      const Eigen::Vector3f& rgb = level_->horizon->rgb;
      DrawMesh(horizon_, static_model, Eigen::Vector4f(rgb.x(), rgb.y(), rgb.z(), 1.f), 0);
    }
    if (between) between();
    if (pass == Pass::kShadow) return;

    if (pass == Pass::kColor && !(look_ & kGBuffer)) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    }
    for (auto it = static_order_.rbegin(); it != static_order_.rend(); ++it) {
      const GpuMesh& mesh = static_meshes_[it->second].second;
      lod_error_m_ = chunk_error(it->second);
      if (IsTranslucent(mesh)) Draw(mesh, static_model);
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (IsTranslucent(mesh)) Draw(mesh, actor_model(actor));
    }
    glDisable(GL_BLEND);
  }

  // A movable actor's pose this frame, and its bounds (camera-centred).
  const Eigen::Isometry3d& ActorPose(int actor) const {
    return actor_poses_->size() == level_->actors.size() ? (*actor_poses_)[std::size_t(actor)]
                                                         : level_->actors[std::size_t(actor)].X_WA;
  }
  Eigen::AlignedBox3f ActorBoundsC(int actor) const {
    const Eigen::AlignedBox3d& box_A = actor_bounds_A_.at(actor);
    Eigen::AlignedBox3f box_C;
    for (int k = 0; k < 8 && !box_A.isEmpty(); ++k) {
      box_C.extend((ActorPose(actor) * box_A.corner(Eigen::AlignedBox3d::CornerType(k)) - camera_)
                       .cast<float>());
    }
    return box_C;
  }

  // What `lod_px` pixels span at the nearest point of `box_C` (camera-centred).
  float PixelError(const Eigen::AlignedBox3f& box_C) const {
    if (lod_px_ <= 0.f || box_C.isEmpty()) return 0.f;
    return lod_px_ * pixel_angle_ * box_C.exteriorDistance(Eigen::Vector3f::Zero());
  }

  // The error a draw of what stays, within `box_C`, may have: PixelError, and
  // with shadows no more than a fifth of the shadow-map texel there (the shadow
  // maps hold another level: the two stay under the shadows' bias of 0.4
  // texel, no acne). Shadow passes set their own.
  float LodError(const Eigen::AlignedBox3f& box_C) const {
    if (pass_ == Pass::kShadow) return lod_error_m_;
    float error = PixelError(box_C);
    const std::vector<ShadowCascade>& cascades = frame_uniforms_.cascades;
    // (Deferred shading moves its shadow lookups off the surface by this
    // draw's allowance instead: LightingFrame::lod_offset_per_m.)
    if (!cascades.empty() && look_ & kShadows && !(look_ & kGBuffer)) {
      const Eigen::Vector3f& axis = frame_uniforms_.view_axis;
      const float depth = axis.dot(box_C.center()) - 0.5f * box_C.sizes().dot(axis.cwiseAbs());
      std::size_t c = 0;
      while (c + 1 < cascades.size() && depth > cascades[c].far_m) ++c;
      if (depth <= cascades.back().far_m) error = std::min(error, float(cascades[c].texel_m) / 5.f);
    }
    return error;
  }

  // Whether meshes of this material and surface are drawn opaque and whole
  // (not water, not cut out, not see-through): their back faces hide behind
  // their front faces.
  bool DrawnWhole(int material, int surface) const {
    if (surface == int(scene::Surface::kWater)) return false;
    if (material < 0 || material >= int(level_->materials.size())) return true;
    const scene::Material& m = level_->materials[std::size_t(material)];
    return m.surface != scene::Surface::kWater && m.alpha_mode != scene::AlphaMode::kMask &&
           m.base_color.w() >= 0.999f;
  }

  // Back faces culled in a mesh's next draw where they cannot be seen from
  // `eye` (in the mesh's frame; its axes keep their handedness). Not in
  // shadow maps: the sun's view is not the eye's.
  void CullHiddenBackFaces(const GpuMesh& mesh, const Eigen::Vector3f& eye) {
    CullBackFacesIf(mesh.hidden.HiddenFrom(eye, float(near_reach_m_)));
  }
  void CullBackFacesIf(bool hidden) {
    if (cull_hidden_back_faces_ && pass_ != Pass::kShadow && hidden) {
      glEnable(GL_CULL_FACE);
    } else {
      glDisable(GL_CULL_FACE);
    }
  }

  bool IsTranslucent(const GpuMesh& mesh) const {
    if (mesh.surface == int(scene::Surface::kWater)) return true;
    if (mesh.material < 0 || mesh.material >= int(level_->materials.size())) return false;
    const scene::Material& m = level_->materials[std::size_t(mesh.material)];
    return m.surface == scene::Surface::kWater ||
           (m.alpha_mode != scene::AlphaMode::kMask && m.base_color.w() < 0.999f);
  }

  // A mesh with its material.
  void Draw(const GpuMesh& mesh, const Eigen::Matrix4f& model) {
    const scene::Material* material =
        mesh.material >= 0 && mesh.material < int(level_->materials.size())
            ? &level_->materials[std::size_t(mesh.material)]
            : nullptr;
    static const scene::Material kDefault = [] {
      scene::Material m;
      m.base_color = {0.8f, 0.8f, 0.8f, 1.f};
      return m;
    }();
    const scene::Material& m = material != nullptr ? *material : kDefault;
    const auto texture = textures_.find(mesh.material);
    const GLuint texture_id = texture != textures_.end() ? texture->second : 0;
    const auto lightmap = lightmaps_.find(mesh.material);
    const auto normal_map = normal_maps_.find(mesh.material);
    const GLuint lightmap_id = lightmap != lightmaps_.end() ? lightmap->second : 0;
    const GLuint normal_map_id = normal_map != normal_maps_.end() ? normal_map->second : 0;
    const int features = (texture_id != 0 && mesh.uvs != 0 ? kTexture : 0) |
                         (lightmap_id != 0 && mesh.lightmap_uvs != 0 ? kLightmap : 0) |
                         (normal_map_id != 0 && mesh.uvs != 0 ? kNormalMap : 0) |
                         (m.alpha_mode == scene::AlphaMode::kMask ? kAlphaMask : 0) |
                         (mesh.colors != 0 ? kVertexColors : 0) |
                         (mesh.triangle_segments != 0 ? kTriangleSegments : 0);
    if (pass_ == Pass::kShadow) {
      const bool masked = (features & kAlphaMask) && (features & kTexture);
      UseShadowProgram(masked);
      glUniform1f(shadow_uniforms_[masked].alpha_cutoff, m.alpha_cutoff);
      glUniformMatrix4fv(shadow_uniforms_[masked].model, 1, GL_FALSE, model.data());
      glBindTexture(GL_TEXTURE_2D, masked ? texture_id : 0);
      glBindVertexArray(mesh.vao);
      DrawTriangles(mesh);
      return;
    }
    if (look_ & kTranslucent) translucent_drawn_ = true;
    UseProgram(mesh.surface >= 0 ? mesh.surface : int(m.surface), features);
    glUniformMatrix4fv(U("model"), 1, GL_FALSE, model.data());
    const Eigen::Vector3f base = Shading(m.base_color.head<3>(), m.linear_color);
    glUniform4f(U("base_color"), base.x(), base.y(), base.z(), m.base_color.w());
    glUniform1i(U("vertex_color_space"), gamma_ == m.linear_color ? 0 : gamma_ ? 1 : 2);
    glUniform1f(U("alpha_cutoff"), m.alpha_cutoff);
    glUniform2f(U("metal_rough"), m.metallic, m.roughness);
    BindTexture(GL_TEXTURE0, features & kTexture ? texture_id : 0, true);
    BindTexture(GL_TEXTURE1, features & kLightmap ? lightmap_id : 0, true);
    BindTexture(GL_TEXTURE2, features & kNormalMap ? normal_map_id : 0, false);
    DrawIds(mesh);
  }

  // The rest of a draw: segment ids, then the triangles.
  void DrawIds(const GpuMesh& mesh) {
    glUniform1ui(U("segment_base"), mesh.segment_base);
    if (mesh.triangle_segments != 0) {
      glActiveTexture(GL_TEXTURE5);
      glBindTexture(GL_TEXTURE_BUFFER, mesh.triangle_segments);
      glActiveTexture(GL_TEXTURE0);
    }
    glBindVertexArray(mesh.vao);
    DrawTriangles(mesh);
  }

  // The level of detail: what moves, this frame's (ChooseMovingLevels); what
  // stays, the coarsest within this draw's allowance (in colour, see NextLevel).
  void DrawTriangles(const GpuMesh& mesh) {
    MeshLods::Level level{0, std::uint32_t(mesh.index_count), 0.f};
    if (!mesh.lods.empty()) {
      if (mesh.moving && !(pass_ == Pass::kShadow && cpu_shadows_)) {
        level = mesh.lods[std::min(mesh.level, mesh.lods.size() - 1)];
      } else if (pass_ == Pass::kColor) {
        level = mesh.lods[mesh.level = NextLevel(mesh, lod_error_m_)];
      } else {
        level = LevelFor(mesh.lods, lod_error_m_);
      }
    }
    glDrawElements(GL_TRIANGLES, GLsizei(level.count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(std::uintptr_t(level.first) * 4));
  }

  // The coarsest level within `error_m`, but a coarser one than the mesh's
  // last only once well within it: a camera that keeps its distance does
  // not see a mesh flicker between two levels.
  static std::size_t NextLevel(const GpuMesh& mesh, float error_m) {
    auto index = [&](float e) { return std::size_t(&LevelFor(mesh.lods, e) - mesh.lods.data()); };
    const std::size_t k = index(error_m);
    return k > mesh.level ? std::max(index(error_m / 1.5f), mesh.level) : k;
  }

  // This frame's level of each robot's and movable actor's meshes (before
  // the shadow maps, which draw them at it too).
  void ChooseMovingLevels() {
    for (std::size_t r = 0; r < posed_robots_.size(); ++r) {
      const Eigen::AlignedBox3d& box_W = robot_bounds_W_[r];
      const float error =
          box_W.isEmpty() ? 0.f
                          : PixelError(Eigen::AlignedBox3f((box_W.min() - camera_).cast<float>(),
                                                           (box_W.max() - camera_).cast<float>()));
      for (const GpuMesh* mesh : posed_robots_[r].second) {
        if (!mesh->lods.empty()) mesh->level = NextLevel(*mesh, error);
      }
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (!mesh.lods.empty()) mesh.level = NextLevel(mesh, PixelError(ActorBoundsC(actor)));
    }
  }

  // Binds a texture; colour textures (sRGB) are decoded to linear light by
  // the sampler with gamma-correct shading and read as display values without.
  void BindTexture(GLenum unit, GLuint texture, bool srgb) {
    glActiveTexture(unit);
    glBindTexture(GL_TEXTURE_2D, texture);
    if (texture != 0 && srgb) {
      // A texture decodes until told otherwise.
      bool& decoding = srgb_decode_.emplace(texture, true).first->second;
      if (decoding != gamma_) {
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SRGB_DECODE_EXT,
                        gamma_ ? GL_DECODE_EXT : GL_SKIP_DECODE_EXT);
        decoding = gamma_;
      }
    }
    glActiveTexture(GL_TEXTURE0);
  }

  // The depth-only program for the sun's view; `masked`: cut-outs cut.
  void UseShadowProgram(bool masked) {
    const int key = masked ? -3 : -2;
    if (program_key_ == key) return;
    program_key_ = key;
    glUseProgram(shadow_programs_[masked]);
    glUniformMatrix4fv(shadow_uniforms_[masked].view_proj, 1, GL_FALSE, view_proj_.data());
  }

  // A mesh in one colour (and texture, 0: none), not a level material: the
  // horizon and terrain tiles. Draws all of it unless `ranges` are given.
  void DrawMesh(const GpuMesh& mesh, const Eigen::Matrix4f& model, const Eigen::Vector4f& color,
                GLuint texture,
                const std::vector<std::pair<std::uint32_t, std::uint32_t>>* ranges = nullptr) {
    if (pass_ == Pass::kShadow) {
      UseShadowProgram(false);
      glUniformMatrix4fv(shadow_uniforms_[0].model, 1, GL_FALSE, model.data());
    } else {
      const bool textured = texture != 0 && mesh.uvs != 0;
      UseProgram(mesh.surface >= 0 ? mesh.surface : 0, textured ? kTexture : 0);
      glUniformMatrix4fv(U("model"), 1, GL_FALSE, model.data());
      const Eigen::Vector3f base = Shading(color.head<3>(), false);
      glUniform4f(U("base_color"), base.x(), base.y(), base.z(), color.w());
      glUniform2f(U("metal_rough"), 0.f, 1.f);
      BindTexture(GL_TEXTURE0, textured ? texture : 0, true);
      glUniform1ui(U("segment_base"), mesh.segment_base);
    }
    glBindVertexArray(mesh.vao);
    if (ranges == nullptr) {
      glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
      return;
    }
    for (const auto& [a, b] : *ranges) {
      if (b <= a) continue;
      glDrawElements(GL_TRIANGLES, GLsizei(b - a), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(std::uintptr_t(a) * 4));
    }
  }

  // The sun's depth from each cascade's box.
  // The shadow maps: per cascade, what does not move (level chunks, terrain)
  // drawn into a map of its own only when the cascade's box, the sun or the
  // terrain's tiles change; each frame that map copied and what moves (robots,
  // movable actors) drawn over it.
  // With `cpu` (deferred shading), the maps as the CPU shades with them: the
  // still casters' maps read back when redrawn, the moving casters in a map
  // of their own each frame (DrawMovingShadowsForCpu).
  void DrawShadowMaps(const std::vector<ShadowCascade>& cascades, const Eigen::Vector3f& sun,
                      int px, bool cpu) {
    const int layers = int(cascades.size());
    if (shadow_map_ == 0 || shadow_px_ != px || shadow_layers_ < layers) {
      for (GLuint* map : {&shadow_map_, &shadow_static_}) {
        if (*map != 0) glDeleteTextures(1, map);
        glGenTextures(1, map);
        glBindTexture(GL_TEXTURE_2D_ARRAY, *map);
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, px, px, layers, 0,
                     GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
      }
      if (shadow_fbo_ == 0) glGenFramebuffers(1, &shadow_fbo_);
      shadow_px_ = px;
      shadow_layers_ = layers;
      static_shadow_keys_.clear();
    }
    static_shadow_keys_.resize(std::size_t(layers));
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo_);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glViewport(0, 0, px, px);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.f);
    glClearDepth(1.0);
    for (int c = 0; c < layers; ++c) {
      const ShadowCascade& cascade = cascades[std::size_t(c)];
      const StaticShadowKey key{cascade.cell, cascade.half_size_m, sun, terrain_.get()};
      if (!(static_shadow_keys_[std::size_t(c)] == key)) {
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadow_static_, 0, c);
        glClear(GL_DEPTH_BUFFER_BIT);
        program_key_ = -1;  // the shadow programs take this cascade's clip at first use
        shadow_casters_ = Casters::kStill;
        lod_error_m_ = ShadowLodError(cascade);
        DrawScene(Pass::kShadow, cascade.light_clip.cast<float>());
        static_shadow_keys_[std::size_t(c)] = key;
      }
      if (cpu) {
        ReadStillShadows(c, px);
        continue;
      }
      glCopyImageSubData(shadow_static_, GL_TEXTURE_2D_ARRAY, 0, 0, 0, c, shadow_map_,
                         GL_TEXTURE_2D_ARRAY, 0, 0, 0, c, px, px, 1);
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadow_map_, 0, c);
      program_key_ = -1;
      shadow_casters_ = Casters::kMoving;
      lod_error_m_ = ShadowLodError(cascade);
      DrawScene(Pass::kShadow, cascade.light_clip.cast<float>());
    }
    if (cpu) DrawMovingShadowsForCpu(sun);
    shadow_casters_ = Casters::kAll;
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  // Cascade c's still casters for the CPU (shadow_cpu_static_): read back
  // when its map was redrawn.
  void ReadStillShadows(int c, int px) {
    const std::size_t layer = std::size_t(px) * std::size_t(px);
    if (shadow_cpu_static_.size() != std::size_t(shadow_layers_) * layer) {
      shadow_cpu_static_.assign(std::size_t(shadow_layers_) * layer, 1.f);
      cpu_static_keys_.assign(std::size_t(shadow_layers_), StaticShadowKey{});
    }
    if (cpu_static_keys_[std::size_t(c)] == static_shadow_keys_[std::size_t(c)]) return;
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadow_static_, 0, c);
    glReadPixels(0, 0, px, px, GL_DEPTH_COMPONENT, GL_FLOAT,
                 &shadow_cpu_static_[std::size_t(c) * layer]);
    cpu_static_keys_[std::size_t(c)] = static_shadow_keys_[std::size_t(c)];
  }

  // The moving casters (robots, movable actors) for the CPU: drawn once into
  // a map of their own around them and read back (moving_casters_); where no
  // caster was drawn, infinitely deep.
  void DrawMovingShadowsForCpu(const Eigen::Vector3f& sun) {
    moving_casters_ = ShadowMapView{};
    Eigen::AlignedBox3f box_C;
    for (const Eigen::AlignedBox3d& box_W : robot_bounds_W_) {
      if (!box_W.isEmpty()) {
        box_C.extend(Eigen::AlignedBox3f((box_W.min() - camera_).cast<float>(),
                                         (box_W.max() - camera_).cast<float>()));
      }
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (!IsTranslucent(mesh)) box_C.extend(ActorBoundsC(actor));
    }
    if (box_C.isEmpty()) return;
    const ShadowCascade box =
        FitCasterShadow(box_C.center().cast<double>(), 0.5 * box_C.diagonal().norm() + 0.01,
                        sun.cast<double>(), kMovingShadowPx);
    if (moving_shadow_fbo_ == 0) {
      glGenFramebuffers(1, &moving_shadow_fbo_);
      glGenRenderbuffers(1, &moving_shadow_depth_);
      glBindRenderbuffer(GL_RENDERBUFFER, moving_shadow_depth_);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, kMovingShadowPx,
                            kMovingShadowPx);
      glBindFramebuffer(GL_FRAMEBUFFER, moving_shadow_fbo_);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                moving_shadow_depth_);
      glDrawBuffer(GL_NONE);
      glReadBuffer(GL_NONE);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, moving_shadow_fbo_);
    glViewport(0, 0, kMovingShadowPx, kMovingShadowPx);
    glClear(GL_DEPTH_BUFFER_BIT);
    program_key_ = -1;
    shadow_casters_ = Casters::kMoving;
    cpu_shadows_ = true;
    lod_error_m_ = ShadowLodError(box);
    DrawScene(Pass::kShadow, box.light_clip.cast<float>());
    cpu_shadows_ = false;
    moving_depth_.resize(std::size_t(kMovingShadowPx) * kMovingShadowPx);
    glReadPixels(0, 0, kMovingShadowPx, kMovingShadowPx, GL_DEPTH_COMPONENT, GL_FLOAT,
                 moving_depth_.data());
    for (float& d : moving_depth_) {
      if (d >= 1.f) d = std::numeric_limits<float>::infinity();
    }
    moving_casters_ = {box.light_clip.cast<float>(), 0.f, float(box.texel_m), kMovingShadowPx,
                       moving_depth_.data()};
  }

  // The G-buffer layer `layer` (opaque_ or translucent_) read back.
  void ReadLayer(int width, int height, SurfaceLayer* layer) {
    const bool opaque = layer == &opaque_;
    const std::size_t count = std::size_t(width) * std::size_t(height);
    layer->width = width;
    layer->height = height;
    layer->albedo.resize(count);
    layer->normal.resize(count);
    layer->depth.resize(count);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, opaque ? gbuffer_lean_fbo_ : translucent_lean_fbo_);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->albedo.data());
    glReadBuffer(GL_COLOR_ATTACHMENT3);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->normal.data());
    glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, layer->depth.data());
  }

  // This frame's lighting for the CPU (the scene programs' frame uniforms).
  LightingFrame LightingOf(const RenderSettings& settings,
                           const Eigen::Matrix4f& clip_to_world) const {
    const FrameUniforms& u = frame_uniforms_;
    LightingFrame f;
    f.clip_to_world = clip_to_world;
    f.sun = u.sun;
    f.horizon = u.horizon;
    f.zenith = u.zenith;
    f.sky_horizon_display = settings.sky_rgb;
    f.sky_zenith_display = Zenith(settings.sky_rgb);
    f.fog = u.fog;
    f.camera_z = u.camera_z;
    f.camera_xy = u.camera_xy;
    f.water_level = water_level_;
    f.snow_line = kSnowLine_m;
    for (int i = 0; i < 4; ++i) f.ground[std::size_t(i)] = u.ground[i];
    f.view_axis = u.view_axis;
    f.materials = settings.materials;
    f.lod_offset_per_m = lod_px_ * pixel_angle_;
    const std::size_t layer = std::size_t(shadow_px_) * std::size_t(shadow_px_);
    for (std::size_t c = 0; c < u.cascades.size(); ++c) {
      f.cascades.push_back({u.cascades[c].light_clip.cast<float>(), float(u.cascades[c].far_m),
                            float(u.cascades[c].texel_m), shadow_px_,
                            &shadow_cpu_static_[c * layer]});
    }
    if (!u.cascades.empty()) f.moving_casters = moving_casters_;
    return f;
  }

  // A fifth of a texel: with a surface's own error (LodError), under the
  // shadows' bias of 0.4 texel and more.
  float ShadowLodError(const ShadowCascade& cascade) const {
    return lod_px_ > 0.f ? float(cascade.texel_m) / 5.f : 0.f;
  }

  // Robots: their posed meshes, uploaded once a frame for every pass.
  void UploadRobots(const std::vector<const scene::RobotState*>& robots) {
    posed_robots_.clear();
    robot_bounds_W_.clear();
    for (const scene::RobotState* state : robots) {
      const scene::RobotModel& model = state->model();
      std::vector<GpuMesh>& meshes = robot_meshes_[&model];
      std::vector<const GpuMesh*> drawn;
      Eigen::AlignedBox3f bounds_B;
      for (std::size_t m = 0; m < model.meshes.size(); ++m) {
        for (const Eigen::Vector3f& p : state->positions_B(int(m))) bounds_B.extend(p);
        const scene::Mesh& bind = model.meshes[m].bind;
        if (meshes.size() <= m) {
          // Levels of detail within the sets of vertices that follow the same
          // bones by the same weights (errors in this pose hold in every pose).
          const std::vector<std::uint32_t> skin_groups = SkinGroups(model.meshes[m]);
          const MeshLods lods = MakeMeshLods(
              state->positions_B(int(m)),
              WeldedIndices(state->positions_B(int(m)), state->normals_B(int(m)), bind.uvs,
                            bind.lightmap_uvs, bind.colors, &skin_groups, bind.indices),
              &skin_groups);
          meshes.push_back(
              Upload({&state->positions_B(int(m)), &state->normals_B(int(m)), &bind.uvs,
                      &bind.lightmap_uvs, &bind.colors, nullptr, nullptr, &lods},
                     bind.material, GL_DYNAMIC_DRAW));
          const int r = RobotIndex(model);
          meshes.back().moving = true;
          // (Closed as made; its volume as first posed.)
          if (DrawnWhole(bind.material, -1)) {
            meshes.back().hidden = HiddenBackFaces::Of(state->positions_B(int(m)), bind.indices);
          }
          meshes.back().segment_base = r >= 0 ? legend_->bone(r, 0) : 0xffffu;
          const auto groups = robot_groups_.find(&model);
          if (r >= 0 && groups != robot_groups_.end())
            SetTriangleSegments(&meshes.back(), groups->second[m]);
        } else {
          glBindBuffer(GL_ARRAY_BUFFER, meshes[m].positions);
          glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(state->positions_B(int(m)).size() * 12),
                          state->positions_B(int(m)).data());
          glBindBuffer(GL_ARRAY_BUFFER, meshes[m].normals);
          glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(state->normals_B(int(m)).size() * 12),
                          state->normals_B(int(m)).data());
        }
        drawn.push_back(&meshes[m]);
      }
      posed_robots_.emplace_back(state->pose(), std::move(drawn));
      Eigen::AlignedBox3d bounds_W;
      for (int k = 0; k < 8 && !bounds_B.isEmpty(); ++k) {
        bounds_W.extend(state->pose() *
                        bounds_B.corner(Eigen::AlignedBox3f::CornerType(k)).cast<double>());
      }
      robot_bounds_W_.push_back(bounds_W);
    }
  }

  // Per vertex, an id of the bones and weights it follows.
  static std::vector<std::uint32_t> SkinGroups(const scene::SkinnedMesh& mesh) {
    const std::size_t n = mesh.bind.positions_A.size();
    std::vector<std::uint32_t> group(n, 0);
    if (mesh.influence_begin.size() != n + 1) return group;
    std::map<std::vector<std::pair<std::uint16_t, float>>, std::uint32_t> ids;
    std::vector<std::pair<std::uint16_t, float>> influences;
    for (std::size_t v = 0; v < n; ++v) {
      influences.clear();
      for (std::uint32_t i = mesh.influence_begin[v]; i < mesh.influence_begin[v + 1]; ++i) {
        influences.emplace_back(mesh.influence_joint[i], mesh.influence_weight[i]);
      }
      std::sort(influences.begin(), influences.end());
      group[v] = ids.emplace(influences, std::uint32_t(ids.size())).first->second;
    }
    return group;
  }

  int RobotIndex(const scene::RobotModel& model) const {
    for (std::size_t r = 0; r < level_->robots.size(); ++r) {
      if (&level_->robots[r] == &model) return int(r);
    }
    return -1;
  }

  // Static actors' meshes in world coordinates, grouped by material, surface
  // and ground cell, uploaded once: few draws, and whole cells culled.
  void MergeStatic(const scene::Level& level) {
    origin_ = level.bounds_W().isEmpty() ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                         : Eigen::Vector3d(level.bounds_W().center());
    // By material, surface, ground cell and which back faces may go
    // (-1: none, 0: those of solids, k + 1: those of height field k).
    std::map<std::tuple<int, int, long, long, int>, StaticChunk> chunks;
    int height_fields = 0;
    for (std::size_t a = 0; a < level.actors.size(); ++a) {
      const scene::Actor& actor = level.actors[a];
      if (actor.movable) continue;
      const int surface = actor.surface ? int(*actor.surface) : -1;
      const Eigen::Matrix3d R = actor.X_WA.linear();
      for (const scene::Mesh& mesh : actor.meshes) {
        // This mesh's vertices already copied into each chunk.
        std::map<std::tuple<int, int, long, long, int>, std::vector<std::int64_t>> copied;
        // Its vertices in the chunks' frame, once each.
        std::vector<Eigen::Vector3d> p_S(mesh.positions_A.size());
        std::vector<Eigen::Vector3f> positions_S(p_S.size());
        for (std::size_t v = 0; v < p_S.size(); ++v) {
          p_S[v] = actor.X_WA * mesh.positions_A[v].cast<double>() - origin_;
          positions_S[v] = p_S[v].cast<float>();
        }
        const HiddenBackFaces hidden = DrawnWhole(mesh.material, surface)
                                           ? HiddenBackFaces::Of(positions_S, mesh.indices)
                                           : HiddenBackFaces();
        const int kind = hidden.shape() == HiddenBackFaces::Shape::kSolid         ? 0
                         : hidden.shape() == HiddenBackFaces::Shape::kHeightField ? ++height_fields
                                                                                  : -1;
        const bool has_uvs = mesh.uvs.size() == mesh.positions_A.size();
        const bool has_lightmap_uvs = mesh.lightmap_uvs.size() == mesh.positions_A.size();
        const bool has_colors = mesh.colors.size() == mesh.positions_A.size();
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
          const Eigen::Vector3d c =
              (p_S[mesh.indices[t]] + p_S[mesh.indices[t + 1]] + p_S[mesh.indices[t + 2]]) / 3.0;
          const std::tuple<int, int, long, long, int> key{
              mesh.material, surface, std::lround(std::floor(c.x() / kChunkCell_m)),
              std::lround(std::floor(c.y() / kChunkCell_m)), kind};
          StaticChunk& chunk = chunks[key];
          std::vector<std::int64_t>& map = copied[key];
          if (map.empty()) {
            map.assign(mesh.positions_A.size(), -1);
            // (A chunk of solids culls while the eye is outside all of their boxes.)
            chunk.hidden =
                chunk.indices.empty() ? hidden : HiddenBackFaces::Union(chunk.hidden, hidden);
          }
          chunk.any_uvs = chunk.any_uvs || has_uvs;
          chunk.any_lightmap_uvs = chunk.any_lightmap_uvs || has_lightmap_uvs;
          chunk.any_colors = chunk.any_colors || has_colors;
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = mesh.indices[t + std::size_t(k)];
            if (map[v] < 0) {
              map[v] = std::int64_t(chunk.positions.size());
              chunk.positions.push_back(positions_S[v]);
              chunk.normals.push_back((R * mesh.normals_A[v].cast<double>()).cast<float>());
              chunk.uvs.push_back(has_uvs ? mesh.uvs[v] : Eigen::Vector2f::Zero());
              chunk.lightmap_uvs.push_back(has_lightmap_uvs ? mesh.lightmap_uvs[v]
                                                            : Eigen::Vector2f::Zero());
              chunk.colors.push_back(has_colors ? mesh.colors[v] : Eigen::Vector4f::Ones());
              chunk.segments.push_back(legend_->actor(int(a)));
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
      if (!chunk.any_colors) chunk.colors.clear();
      const MeshLods lods =
          MakeMeshLods(chunk.positions,
                       WeldedIndices(chunk.positions, chunk.normals, chunk.uvs, chunk.lightmap_uvs,
                                     chunk.colors, &chunk.segments, chunk.indices));
      GpuMesh gpu = Upload({&chunk.positions, &chunk.normals, &chunk.uvs, &chunk.lightmap_uvs,
                            &chunk.colors, &chunk.segments, nullptr, &lods},
                           std::get<0>(key), GL_STATIC_DRAW);
      gpu.surface = std::get<1>(key);
      gpu.hidden = chunk.hidden;
      static_meshes_.push_back({chunk.bounds, gpu});
    }
  }

  // An RGBA8 texture (sRGB: colours; else data) with mipmaps.
  GLuint UploadTexture(const RgbaImage& image, GLint wrap, bool srgb) {
    GLuint id = 0;
    glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, image.width, image.height, 0,
                 GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
    return id;
  }

  void DrawSky(const Eigen::Matrix4f& clip_to_world, const Eigen::Vector3f& horizon,
               const Eigen::Vector3f& sun) {
    glUseProgram(sky_program_);
    program_key_ = -1;
    glUniformMatrix4fv(glGetUniformLocation(sky_program_, "clip_to_world"), 1, GL_FALSE,
                       clip_to_world.data());
    glUniform3f(glGetUniformLocation(sky_program_, "horizon"), horizon.x(), horizon.y(),
                horizon.z());
    const Eigen::Vector3f zenith = Zenith(horizon);
    glUniform3f(glGetUniformLocation(sky_program_, "zenith"), zenith.x(), zenith.y(), zenith.z());
    glUniform3f(glGetUniformLocation(sky_program_, "sun"), sun.x(), sun.y(), sun.z());
    // At the far plane (depth 0): only where no surface was drawn.
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GEQUAL);
    glBindVertexArray(overlay_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
  }

  // The edge filter: from a copy of the colour buffer back into it.
  void FilterEdges(int width, int height) {
    if (edge_source_ == 0) glGenTextures(1, &edge_source_);
    glBindTexture(GL_TEXTURE_2D, edge_source_);
    if (edge_source_size_ != Eigen::Vector2i(width, height)) {
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                   nullptr);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      edge_source_size_ = {width, height};
    }
    glCopyImageSubData(buffers_[0], GL_RENDERBUFFER, 0, 0, 0, 0, edge_source_, GL_TEXTURE_2D, 0, 0,
                       0, 0, width, height, 1);
    const GLenum color_only[] = {GL_COLOR_ATTACHMENT0};
    glDrawBuffers(1, color_only);
    glUseProgram(edge_filter_program_);
    program_key_ = -1;
    glUniform1i(glGetUniformLocation(edge_filter_program_, "image"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindSampler(0, 0);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindVertexArray(overlay_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEnable(GL_DEPTH_TEST);
  }

  struct TileGpu {
    GpuMesh mesh;
    GLuint texture{0};
  };

  // Terrain tiles: uploaded when first seen, freed when gone.
  void UploadTerrain() {
    std::map<const scene::TerrainTile*, TileGpu> kept;
    for (const auto& tile : terrain_ ? *terrain_ : scene::TileList{}) {
      auto found = tile_gpu_.find(tile.get());
      if (found != tile_gpu_.end()) {
        kept[tile.get()] = found->second;
        tile_gpu_.erase(found);
      } else {
        kept[tile.get()] = UploadTile(*tile);
      }
    }
    for (auto& [tile, gpu] : tile_gpu_) {
      Free(gpu.mesh);
      if (gpu.texture != 0) glDeleteTextures(1, &gpu.texture);
    }
    tile_gpu_.swap(kept);
  }

  // Terrain tiles in view; a coarse tile leaves out the blocks a fine tile covers.
  void DrawTerrain() {
    if (!terrain_) return;
    std::set<std::uint64_t> fine;
    for (const auto& tile : *terrain_) {
      if (tile->id.lod == 0) fine.insert(tile->id.key());
    }
    const int factor = level_->terrain ? level_->terrain->coarse_factor : 1;
    const Eigen::Vector4f plain(level_->horizon ? level_->horizon->rgb.x() : 0.45f,
                                level_->horizon ? level_->horizon->rgb.y() : 0.5f,
                                level_->horizon ? level_->horizon->rgb.z() : 0.35f, 1.f);
    // The tiles in view, nearest first.
    std::vector<std::pair<float, const scene::TerrainTile*>> order;
    for (const auto& tile : *terrain_) {
      if (tile->indices.empty() || tile->bounds_W.isEmpty()) continue;
      if (pass_ == Pass::kShadow && tile->id.lod != 0) continue;  // far tiles cast no shadow here
      const Eigen::AlignedBox3f box((tile->bounds_W.min() - camera_).cast<float>(),
                                    (tile->bounds_W.max() - camera_).cast<float>());
      if (!InFrustum(view_proj_, box)) continue;
      order.push_back({box.exteriorDistance(Eigen::Vector3f::Zero()), tile.get()});
    }
    std::sort(order.begin(), order.end());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
    for (const auto& [distance, tile] : order) {
      const TileGpu& gpu = tile_gpu_.at(tile);
      const Eigen::Matrix4f model =
          Relative(Eigen::Affine3d(Eigen::Translation3d(tile->origin_W)), camera_);
      // Index ranges: the surface (coarse: without the blocks fine tiles cover), the skirts.
      ranges.clear();
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
      DrawMesh(gpu.mesh, model, gpu.texture ? Eigen::Vector4f(1.f, 1.f, 1.f, 1.f) : plain,
               gpu.texture, &ranges);
    }
  }

  TileGpu UploadTile(const scene::TerrainTile& tile) {
    std::vector<std::uint32_t> indices = tile.indices;
    indices.insert(indices.end(), tile.skirt_indices.begin(), tile.skirt_indices.end());
    TileGpu gpu;
    gpu.mesh =
        Upload({&tile.positions, &tile.normals, &tile.uvs, nullptr, nullptr, nullptr, &indices}, -1,
               GL_STATIC_DRAW);
    gpu.mesh.surface = int(scene::Surface::kTerrain);
    gpu.mesh.segment_base = legend_->actor(level_->terrain_actor);
    if (!tile.texture_rgba.empty()) {
      gpu.texture = UploadTexture({tile.texture_width, tile.texture_height, tile.texture_rgba},
                                  GL_CLAMP_TO_EDGE, true);
    }
    return gpu;
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
    horizon_ = Upload({&positions, &normals, nullptr, nullptr, nullptr, nullptr, &indices}, -1,
                      GL_STATIC_DRAW);
    horizon_.segment_base = legend_->horizon();
  }

  // Points and lines with one colour each, relative to the camera.
  void DrawOverlay(const Overlay& overlay, const Eigen::Matrix4f& view_proj) {
    overlay_positions_.clear();
    overlay_colors_.clear();
    for (std::size_t i = 0; i < overlay.points_W.size(); ++i) {
      overlay_positions_.push_back((overlay.points_W[i] - camera_).cast<float>());
      overlay_colors_.push_back(overlay.point_rgb[i]);
    }
    for (std::size_t i = 0; i < overlay.lines_W.size(); ++i) {
      overlay_positions_.push_back((overlay.lines_W[i] - camera_).cast<float>());
      overlay_colors_.push_back(overlay.line_rgb[i / 2]);
    }
    glUseProgram(overlay_program_);
    program_key_ = -1;
    glUniformMatrix4fv(glGetUniformLocation(overlay_program_, "view_proj"), 1, GL_FALSE,
                       view_proj.data());
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

  // The data buffer (colour, segment, normal, depth at pixel centres) and,
  // with multisampling, the multisampled colour buffer.
  void Resize(int width, int height, int samples) {
    if (width == width_ && height == height_ && samples == samples_) return;
    if (fbo_ == 0) {
      glGenFramebuffers(1, &fbo_);
      glGenRenderbuffers(4, buffers_);
      glGenFramebuffers(1, &msaa_fbo_);
      glGenRenderbuffers(2, msaa_buffers_);
      glGenFramebuffers(1, &gbuffer_fbo_);
      glGenFramebuffers(1, &translucent_fbo_);
      glGenFramebuffers(1, &gbuffer_lean_fbo_);
      glGenFramebuffers(1, &translucent_lean_fbo_);
      glGenFramebuffers(1, &overlay_fbo_);
      glGenRenderbuffers(5, layer_buffers_);
    }
    auto attach = [&](GLuint fbo, GLuint buffer, GLenum format, GLenum attachment, int n) {
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      glBindRenderbuffer(GL_RENDERBUFFER, buffer);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, format, width, height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
    };
    auto check = [&](const char* what) {
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        throw std::runtime_error(std::string("Renderer: ") + what + " framebuffer of " +
                                 std::to_string(width) + " x " + std::to_string(height) +
                                 " is incomplete");
      }
    };
    attach(fbo_, buffers_[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
    attach(fbo_, buffers_[1], GL_R32UI, GL_COLOR_ATTACHMENT1, 0);
    attach(fbo_, buffers_[2], GL_RGBA32F, GL_COLOR_ATTACHMENT2, 0);
    attach(fbo_, buffers_[3], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, 0);
    check("the");
    // Deferred shading's layers (SurfaceLayer): the opaque surfaces' and the
    // translucent ones', each in a framebuffer with the segment, normal and
    // depth buffers and in a lean one with the depth alone; the overlay's target.
    auto share = [&](GLenum attachment, GLuint buffer) {
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
    };
    for (int layer = 0; layer < 2; ++layer) {
      const GLuint albedo = layer_buffers_[2 * layer], normal = layer_buffers_[2 * layer + 1];
      attach(layer == 0 ? gbuffer_fbo_ : translucent_fbo_, albedo, GL_RGBA8, GL_COLOR_ATTACHMENT0,
             0);
      attach(layer == 0 ? gbuffer_fbo_ : translucent_fbo_, normal, GL_RGBA8, GL_COLOR_ATTACHMENT3,
             0);
      share(GL_COLOR_ATTACHMENT1, buffers_[1]);
      share(GL_COLOR_ATTACHMENT2, buffers_[2]);
      share(GL_DEPTH_ATTACHMENT, buffers_[3]);
      check("a deferred shading layer's");
      glBindFramebuffer(GL_FRAMEBUFFER, layer == 0 ? gbuffer_lean_fbo_ : translucent_lean_fbo_);
      share(GL_COLOR_ATTACHMENT0, albedo);
      share(GL_COLOR_ATTACHMENT3, normal);
      share(GL_DEPTH_ATTACHMENT, buffers_[3]);
      check("a lean deferred shading layer's");
    }
    attach(overlay_fbo_, layer_buffers_[4], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
    share(GL_DEPTH_ATTACHMENT, buffers_[3]);
    check("the overlay's");
    if (samples > 0) {
      attach(msaa_fbo_, msaa_buffers_[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, samples);
      attach(msaa_fbo_, msaa_buffers_[1], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, samples);
      check("the multisampled");
    }
    width_ = width, height_ = height, samples_ = samples;
  }

  OSMesaContext context_{nullptr};
  std::vector<std::uint8_t> backing_;
  std::string description_;
  PFNGLCLIPCONTROLPROC clip_control_{nullptr};
  // The scene's programs by surface and look, the one in use and the pass's look.
  struct SceneProgram {
    GLuint id{0};
    std::map<std::string, GLint> uniforms;
    long frame{-1};  // the frame its frame uniforms are from
  };
  // Program keys: the surface (bits 0-1), the look, the mesh's features.
  static constexpr int kGamma = 4, kMaterials = 8, kShadows = 16, kData = 32, kDataOnly = 64;
  static constexpr int kTexture = 128, kLightmap = 256, kNormalMap = 512, kAlphaMask = 1024,
                       kVertexColors = 2048, kTriangleSegments = 4096;
  // Deferred shading: the G-buffer pass's programs, for opaque and for translucent surfaces.
  static constexpr int kGBuffer = 8192, kTranslucent = 16384;
  std::map<int, SceneProgram> programs_;
  SceneProgram* program_{nullptr};
  int program_key_{-1};
  int look_{0};
  GLuint shadow_programs_[2]{0, 0}, overlay_program_{0}, sky_program_{0};  // [masked]
  GLuint edge_filter_program_{0}, edge_source_{0};  // the filter reads a copy of the colour
  struct ShadowUniforms {
    GLint model{-1}, view_proj{-1}, alpha_cutoff{-1};
  } shadow_uniforms_[2];
  // This frame's uniforms for the scene programs.
  struct FrameUniforms {
    Eigen::Matrix4f view_proj;
    Eigen::Vector3f sun, horizon, zenith, ground[4], view_axis;
    Eigen::Vector2f fog, camera_xy;
    float camera_z{0.f};
    Eigen::Matrix3f R_CW;
    std::vector<ShadowCascade> cascades;
  } frame_uniforms_;
  long frame_number_{0};
  bool gamma_{true};                    // this frame's shading is in linear light
  std::map<GLuint, bool> srgb_decode_;  // by colour texture: decoding to linear now
  GLuint fbo_{0}, buffers_[4]{0, 0, 0, 0}, msaa_fbo_{0}, msaa_buffers_[2]{0, 0};
  GLuint shadow_fbo_{0}, shadow_map_{0}, shadow_static_{0}, detail_{0};
  // What a shadow pass draws: all, what never moves, or what may.
  enum class Casters { kAll, kStill, kMoving } shadow_casters_{Casters::kAll};
  // What each cascade's map of still casters was drawn for.
  struct StaticShadowKey {
    std::array<std::int64_t, 3> cell{0, 0, 0};
    double half_size_m{-1.0};
    Eigen::Vector3f sun{Eigen::Vector3f::Zero()};
    const scene::TileList* terrain{nullptr};
    bool operator==(const StaticShadowKey& o) const {
      return cell == o.cell && half_size_m == o.half_size_m && sun == o.sun && terrain == o.terrain;
    }
  };
  std::vector<StaticShadowKey> static_shadow_keys_;
  int shadow_px_{0}, shadow_layers_{0};
  // Deferred shading: its layers' framebuffers and buffers (opaque albedo and
  // normal, translucent albedo, normal and depth with code, overlay), what
  // was read back of them, the CPU's shader and image, and its copies of the
  // detail textures and the shadow maps.
  GLuint gbuffer_fbo_{0}, translucent_fbo_{0}, overlay_fbo_{0}, layer_buffers_[5]{0, 0, 0, 0, 0};
  GLuint gbuffer_lean_fbo_{0}, translucent_lean_fbo_{0};  // the same without segment and normal
  SurfaceLayer opaque_, translucent_;
  bool translucent_drawn_{false};
  bool cpu_shadows_{false};  // drawing the moving casters' map for the CPU
  std::unique_ptr<DeferredShader> deferred_;
  DetailTextures detail_cpu_;
  std::vector<std::uint8_t> lit_, filtered_;
  std::vector<std::uint32_t> overlay_rgba_;
  std::vector<float> shadow_cpu_static_;          // the still casters' maps
  std::vector<StaticShadowKey> cpu_static_keys_;  // what shadow_cpu_static_ holds
  GLuint moving_shadow_fbo_{0}, moving_shadow_depth_{0};
  std::vector<float> moving_depth_;  // the moving casters' map
  ShadowMapView moving_casters_;
  GLuint overlay_vao_{0}, overlay_buffers_[2]{0, 0};
  GLfloat max_anisotropy_{1.f};
  GLuint anisotropic_{0};  // a sampler
  std::vector<Eigen::Vector3f> overlay_positions_, overlay_colors_;
  int width_{0}, height_{0}, samples_{-1};
  Eigen::Vector2i edge_source_size_{0, 0};
  const scene::Level* level_{nullptr};
  std::unique_ptr<SegmentationLegend> legend_;
  float water_level_{-1e9f};
  Eigen::Vector3d origin_{Eigen::Vector3d::Zero()};  // of the static chunks
  std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> static_meshes_;
  std::vector<std::pair<int, GpuMesh>> actor_meshes_;        // movable actors'
  std::vector<std::pair<float, std::size_t>> static_order_;  // this pass's chunks in view
  std::map<const scene::RobotModel*, std::vector<GpuMesh>> robot_meshes_;
  std::map<const scene::RobotModel*, std::vector<std::vector<std::uint32_t>>> robot_groups_;
  std::shared_ptr<const scene::TileList> terrain_;
  std::map<const scene::TerrainTile*, TileGpu> tile_gpu_;
  GpuMesh horizon_;
  std::map<int, GLuint> textures_;     // by material
  std::map<int, GLuint> normal_maps_;  // by material
  std::map<int, GLuint> lightmaps_;    // by material
  std::vector<std::string> warnings_;
  // The frame being drawn.
  Pass pass_{Pass::kColor};
  bool cull_hidden_back_faces_{true};
  double near_reach_m_{0.0};  // from the eye to the near plane's corners
  Eigen::Matrix4f view_proj_{Eigen::Matrix4f::Identity()};
  Eigen::Vector3d camera_{Eigen::Vector3d::Zero()};
  const std::vector<Eigen::Isometry3d>* actor_poses_{nullptr};
  std::vector<std::pair<Eigen::Isometry3d, std::vector<const GpuMesh*>>> posed_robots_;
  std::vector<Eigen::AlignedBox3d> robot_bounds_W_;    // as posed this frame
  std::map<int, Eigen::AlignedBox3d> actor_bounds_A_;  // movable actors', by actor
  // Levels of detail: this frame's allowance in pixels, a pixel's angle, and
  // the error the draw being made may have.
  float lod_px_{0.f}, pixel_angle_{0.f}, lod_error_m_{0.f};
  std::vector<std::uint8_t> pixels_;
  std::vector<float> depth_, normal_;
  std::vector<std::uint32_t> segment_;
};

// llvmpipe allocates a frame's bins and staging images anew each frame and
// frees them after; glibc would hand that memory back to the kernel at once
// (heap trim, or munmap above 128 KiB), so that every frame faulted it in again
// (about 7 MB and 6 ms a 640 x 480 frame here). The process keeps it instead.
void KeepFreedMemory() {
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
  });
}

}  // namespace

std::unique_ptr<Renderer> MakeRenderer(RendererBackend backend) {
  KeepFreedMemory();
  switch (backend) {
    case RendererBackend::kOsMesa:
      return std::make_unique<OsMesaRenderer>();
  }
  return nullptr;
}

}  // namespace sandbox::render
