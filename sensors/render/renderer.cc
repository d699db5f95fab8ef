// Over 600 lines: the engine that draws a frame as its passes, with the state those
// passes share; everything it draws with is a part of its own beside it.
// The OSMesa renderer: the level's meshes, robots, terrain and horizon drawn
// by the parts beside this file, in a frame's passes (Render). Its parts:
// gl_context (the context), gl_program and scene_programs (shaders),
// gpu_mesh, level_meshes, robot_meshes, terrain_meshes (geometry),
// material_textures, shadow_maps, frame_targets (framebuffers and the
// G-buffer), screen_passes (sky, edge filter, overlay), read_back; and,
// without GL, projection and mesh_lods (levels of detail).
#include "sensors/render/renderer.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <stdexcept>

#include "scene/surface_ids.h"
#include "sensors/render/deferred_shading.h"
#include "sensors/render/detail_textures.h"
#include "sensors/render/frame_targets.h"
#include "sensors/render/gl_context.h"
#include "sensors/render/lens.h"
#include "sensors/render/level_meshes.h"
#include "sensors/render/material_textures.h"
#include "sensors/render/mesh_drawer.h"
#include "sensors/render/mesh_lods.h"
#include "sensors/render/projection.h"
#include "sensors/render/read_back.h"
#include "sensors/render/robot_meshes.h"
#include "sensors/render/scene_programs.h"
#include "sensors/render/screen_passes.h"
#include "sensors/render/shadow_cascades.h"
#include "sensors/render/shadow_maps.h"
#include "sensors/render/terrain_meshes.h"

namespace sandbox::render {

namespace {

constexpr int kDetailPx = 256;

// What a frame draws, decided once from its settings.
struct FramePlan {
  ImageKinds kinds{0};
  int samples{0};          // multisampled colour; 0: none
  bool shadows{false};     // the sun casts shadows in colour
  bool deferred{false};    // colour lit on the CPU from the G-buffer
  bool want_data{false};   // segmentation or normals
  bool want_depth{false};  // depth
  bool marks{false};       // an overlay over colour
  // Depth, segment and normal in a pass of their own (colour did not give them).
  bool data_pass() const {
    return (want_data || want_depth || marks) && (samples > 0 || !(kinds & kColorImage));
  }
};

FramePlan Plan(const RenderSettings& settings, const Overlay* overlay) {
  FramePlan plan;
  plan.kinds = settings.images;
  plan.samples = settings.msaa_samples > 1 ? settings.msaa_samples : 0;
  const bool color = (plan.kinds & kColorImage) != 0;
  plan.shadows = settings.shadows && color && settings.sun_direction_W.normalized().z() > 0.02f;
  // Deferred shading (on the CPU) for the gamma-correct looks without multisampling.
  plan.deferred = color && settings.deferred && settings.gamma_correct && plan.samples == 0;
  plan.want_data = (plan.kinds & (kSegmentationImage | kNormalsImage)) != 0;
  plan.want_depth = (plan.kinds & kDepthImage) != 0;
  plan.marks = overlay != nullptr && !overlay->empty() && color;
  return plan;
}

const GLenum kColorOnly[] = {GL_COLOR_ATTACHMENT0};
const GLenum kAllTargets[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
const GLenum kDataTargets[] = {GL_NONE, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};

class OsMesaRenderer : public Renderer {
 public:
  OsMesaRenderer() {
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &max_anisotropy_);
    if (glGetError() != GL_NO_ERROR) max_anisotropy_ = 1.f;
    glGenSamplers(1, &anisotropic_);
    glSamplerParameteri(anisotropic_, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glSamplerParameteri(anisotropic_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    // The ground's detail textures, for GL and for the CPU.
    const std::vector<std::uint8_t> detail = MakeDetailTextures(kDetailPx);
    detail_cpu_ = DetailTextures(detail, kDetailPx, kNumDetailLayers);
    glGenTextures(1, &detail_);
    glBindTexture(GL_TEXTURE_2D_ARRAY, detail_);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA8, kDetailPx, kDetailPx, kNumDetailLayers, 0,
                 GL_RGBA, GL_UNSIGNED_BYTE, detail.data());
    glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }

  void SetLevel(const scene::Level& level, const TextureDecoder& decoder) override {
    context_.MakeCurrent();
    level_ = &level;
    drawer_.SetLevel(level);
    shadow_maps_.Forget();
    legend_ = std::make_unique<scene::SurfaceIds>(level);
    water_level_ = -1e9f;
    for (const scene::Actor& actor : level.actors) {
      if (actor.surface == scene::Surface::kWater && !actor.bounds_W.isEmpty()) {
        water_level_ = std::max(water_level_, float(actor.bounds_W.max().z()));
      }
    }
    origin_ = ChunkOrigin(level);
    static_meshes_ = UploadChunks(MergeStaticActors(level, origin_, *legend_));
    if (level.horizon && !level.horizon->hole_W.isEmpty()) {
      const PlainMesh grid = HorizonGrid(*level.horizon, origin_);
      horizon_ = Upload(
          {&grid.positions, &grid.normals, nullptr, nullptr, nullptr, nullptr, &grid.indices}, -1,
          GL_STATIC_DRAW);
      horizon_.segment_base = legend_->horizon();
    }
    MovableMeshes movable = UploadMovableActors(level, *legend_);
    actor_meshes_ = std::move(movable.meshes);
    actor_bounds_A_ = std::move(movable.bounds_A);
    textures_.Load(level, decoder, &warnings_);
    robots_ = std::make_unique<RobotMeshes>(level, *legend_);
  }

  // The frame's passes: the shadow maps, colour (deferred or forward), the
  // data pass, then read-back.
  void Render(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
              const std::vector<const scene::RobotState*>& robots, const RenderSettings& settings,
              Frame* frame, const Overlay* overlay) override {
    if (view.lens) return RenderThroughLens(view, actor_poses, robots, settings, frame, overlay);
    const FramePlan plan = Draw(view, actor_poses, robots, settings, overlay);
    ReadBack(view, settings, plan, overlay, frame);
  }

  void SetTerrain(std::shared_ptr<const scene::TileList> tiles) override {
    terrain_ = std::move(tiles);
  }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  std::string description() const override { return context_.description(); }

 private:
  // Every pass of a frame before read-back; the plan it followed.
  FramePlan Draw(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
                 const std::vector<const scene::RobotState*>& robots,
                 const RenderSettings& settings, const Overlay* overlay) {
    context_.MakeCurrent();
    view.ValidateOrThrow();
    if (overlay != nullptr && (overlay->point_rgb.size() != overlay->points_W.size() ||
                               overlay->line_rgb.size() * 2 != overlay->lines_W.size())) {
      throw std::invalid_argument(
          "Renderer::Render(): an overlay needs one colour per point and per line");
    }
    settings.ValidateOrThrow();
    if (settings.anisotropy > max_anisotropy_) {
      throw std::invalid_argument("Renderer::Render(): anisotropy " +
                                  std::to_string(settings.anisotropy) + " is beyond this GL's " +
                                  std::to_string(int(max_anisotropy_)));
    }
    const FramePlan plan = Plan(settings, overlay);
    targets_.Resize(view.width, view.height, plan.samples);
    context_.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    actor_poses_ = &actor_poses;
    robots_->Pose(robots);
    tiles_.Update(terrain_ ? *terrain_ : scene::TileList{}, legend_->actor(level_->terrain_actor));
    SetCamera(view, settings, plan);
    std::vector<ShadowCascade> cascades;
    if (plan.shadows) cascades = DrawShadowMaps(view, settings, plan);
    SetLook(view, settings, plan, cascades);
    if (plan.deferred) {
      DrawDeferredColor(view, settings, plan);
    } else if (plan.kinds & kColorImage) {
      DrawForwardColor(view, settings, plan);
    }
    if (plan.data_pass()) DrawDataPass(view, settings);
    return plan;
  }

  struct LensCache;  // below

  // A view with a lens: drawn as its pinhole source (lens.h), then gathered
  // through the lens straight from the source's read-back, on the shading
  // threads (the source's own images are never converted).
  void RenderThroughLens(const CameraView& view, const std::vector<Eigen::Isometry3d>& actor_poses,
                         const std::vector<const scene::RobotState*>& robots,
                         const RenderSettings& settings, Frame* frame, const Overlay* overlay) {
    const LensCache& lens = LensOf(view);
    CameraView source = view;
    source.lens.reset();
    source.width = lens.source.width, source.height = lens.source.height;
    source.fov_y_rad = lens.source.fov_y_rad;
    const FramePlan plan = Draw(source, actor_poses, robots, settings, overlay);
    const std::vector<std::uint32_t>* marks = nullptr;
    RawImages raw = ReadRaw(source, settings, plan, overlay, &marks);
    if (marks != nullptr) {  // deferred colour's overlay, over a copy
      marked_.assign(raw.rgba, raw.rgba + 4 * std::size_t(source.width) * source.height);
      MarkImage(*marks, &marked_);
      raw.rgba = marked_.data();
    }
    lens.remap.Apply(raw, frame, &deferred_.pool());
    frame->kinds = plan.kinds;
  }

  // The source view and map of `view`'s lens, built at its first frame (a
  // tenth of a second) and kept: a level's lens cameras take turns.
  const LensCache& LensOf(const CameraView& view) {
    for (const std::unique_ptr<LensCache>& cached : lenses_) {
      if (cached->lens == *view.lens && cached->width == view.width &&
          cached->height == view.height) {
        return *cached;
      }
    }
    view.lens->ValidateOrThrow(view.width, view.height);
    const CameraView source = SourceView(view, *view.lens);
    if (lenses_.size() == kLensesKept) lenses_.erase(lenses_.begin());
    lenses_.push_back(std::make_unique<LensCache>(
        LensCache{*view.lens, view.width, view.height, source,
                  LensRemap(*view.lens, view.width, view.height, source)}));
    return *lenses_.back();
  }

  // The camera-centred world: rotation only in the view; positions relative
  // to the camera. Levels of detail in colour-only frames; depth,
  // segmentation and normals are measurements.
  void SetCamera(const CameraView& view, const RenderSettings& settings, const FramePlan& plan) {
    camera_ = view.X_WC.translation();
    pass_.cull_hidden_back_faces = settings.cull_hidden_back_faces;
    pass_.near_reach_m = NearReach(view);
    view_proj_d_ = ReversedDepthProjection(view) * ViewRotation(view.X_WC);
    lod_px_ = plan.kinds == kColorImage ? settings.lod_px : 0.f;
    pixel_angle_ = PixelAngle(view);
    ChooseMovingLevels();
  }

  // The shadow maps, before the look (they need the scene's upload).
  std::vector<ShadowCascade> DrawShadowMaps(const CameraView& view, const RenderSettings& settings,
                                            const FramePlan& plan) {
    const Eigen::Vector3f sun = settings.sun_direction_W.normalized();
    std::vector<ShadowCascade> cascades =
        FitShadowCascades(view, sun.cast<double>(), settings.shadow_distance_m,
                          settings.shadow_cascades, settings.shadow_map_px, 1500.0);
    shadow_maps_.Draw(cascades, sun, settings.shadow_map_px, plan.deferred, terrain_.get(), lod_px_,
                      plan.deferred ? MovingCastersBoxC() : Eigen::AlignedBox3f(),
                      [&](ShadowMaps::Casters casters, const Eigen::Matrix4f& light_clip,
                          float lod_error_m, bool for_cpu) {
                        programs_.Forget();  // the shadow programs take this map's clip
                        shadow_casters_ = casters;
                        pass_.cpu_shadows = for_cpu;
                        pass_.lod_error_m = lod_error_m;
                        DrawScene(Pass::kShadow, light_clip);
                        pass_.cpu_shadows = false;
                      });
    shadow_casters_ = ShadowMaps::Casters::kAll;
    return cascades;
  }

  // This frame's uniforms for every scene program used in it, its samplers
  // and shared textures; each program gets them at its first use in the frame.
  void SetLook(const CameraView& view, const RenderSettings& settings, const FramePlan& plan,
               const std::vector<ShadowCascade>& cascades) {
    ++pass_.frame;
    pass_.gamma = settings.gamma_correct;
    look_base_ = (settings.gamma_correct ? kGamma : 0) | (settings.materials ? kMaterials : 0) |
                 (plan.shadows ? kShadows : 0);
    pass_.uniforms = &uniforms_;
    uniforms_ = MakeFrameUniforms(view, view_proj_d_.cast<float>(), settings, *level_, camera_,
                                  water_level_, cascades);
    // Anisotropic filtering of material textures (the sampler repeats at the edges).
    const float anisotropy = float(settings.anisotropy);
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
    glBindTexture(GL_TEXTURE_2D_ARRAY, shadow_maps_.map());
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDisable(GL_CULL_FACE);
  }

  // Deferred colour: the opaque surfaces into the G-buffer, read back; the
  // nearest translucent surfaces into a layer of their own over that depth;
  // each pixel lit once on the CPU. (Without segment and normal images, into
  // framebuffers without them: llvmpipe pays for every target attached.)
  void DrawDeferredColor(const CameraView& view, const RenderSettings& settings,
                         const FramePlan& plan) {
    const bool full = plan.want_data;
    glBindFramebuffer(GL_FRAMEBUFFER, targets_.opaque(full));
    glViewport(0, 0, view.width, view.height);
    ClearTargets(full, settings.sky_rgb, /*keep_color=*/true);
    const GLenum data = full ? GL_COLOR_ATTACHMENT1 : GL_NONE;
    const GLenum normals = full ? GL_COLOR_ATTACHMENT2 : GL_NONE;
    const GLenum layer[] = {GL_COLOR_ATTACHMENT0, data, normals, GL_COLOR_ATTACHMENT3};
    glDrawBuffers(4, layer);
    pass_.look = look_base_ | kGBuffer | (full ? kData : 0);
    pass_.translucent_drawn = false;
    DrawScene(Pass::kColor, uniforms_.view_proj, [&] {
      targets_.ReadLayer(true, view.width, view.height, &opaque_);
      glBindFramebuffer(GL_FRAMEBUFFER, targets_.translucent(full));
      glDrawBuffers(4, layer);
      pass_.look = look_base_ | kGBuffer | kTranslucent | (full ? kData : 0);
    });
    if (pass_.translucent_drawn) targets_.ReadLayer(false, view.width, view.height, &translucent_);
    LightingFrame lighting = LightingOf(uniforms_, settings, view_proj_d_.inverse().cast<float>(),
                                        lod_px_ * pixel_angle_);
    lighting.cascades = shadow_maps_.CpuCascades(uniforms_.cascades);
    if (!uniforms_.cascades.empty()) lighting.moving_casters = shadow_maps_.moving_casters();
    deferred_.Shade(lighting, detail_cpu_, opaque_,
                    pass_.translucent_drawn ? &translucent_ : nullptr, &lit_);
  }

  // Forward colour: into the multisampled buffer (resolved into the data
  // buffer), or straight into the data buffer with segment and normal in
  // the same pass; the sky where no surface was drawn; then the edge filter.
  void DrawForwardColor(const CameraView& view, const RenderSettings& settings,
                        const FramePlan& plan) {
    glBindFramebuffer(GL_FRAMEBUFFER, plan.samples > 0 ? targets_.multisampled() : targets_.data());
    glViewport(0, 0, view.width, view.height);
    const bool data_too = plan.samples == 0 && plan.want_data;
    ClearTargets(data_too, settings.sky_rgb);
    glDrawBuffers(data_too ? 3 : 1, data_too ? kAllTargets : kColorOnly);
    pass_.look = look_base_ | (data_too ? kData : 0);
    DrawScene(Pass::kColor, uniforms_.view_proj, [&] {
      glDrawBuffers(1, kColorOnly);
      screen_.DrawSky(view_proj_d_.inverse().cast<float>(), settings.sky_rgb,
                      Zenith(settings.sky_rgb), uniforms_.sun);
      programs_.Forget();
      glDrawBuffers(data_too ? 3 : 1, data_too ? kAllTargets : kColorOnly);
    });
    if (plan.samples > 0) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, targets_.multisampled());
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, targets_.data());
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      glDrawBuffers(1, kColorOnly);
      glBlitFramebuffer(0, 0, view.width, view.height, 0, 0, view.width, view.height,
                        GL_COLOR_BUFFER_BIT, GL_NEAREST);
      glBindFramebuffer(GL_FRAMEBUFFER, targets_.data());
    }
    if (settings.fxaa) {
      screen_.FilterEdges(targets_.color_buffer(), view.width, view.height);
      programs_.Forget();
    }
  }

  // Depth, segment and normal at pixel centres, when colour did not give
  // them (the overlay is hidden by this depth too).
  void DrawDataPass(const CameraView& view, const RenderSettings& settings) {
    glBindFramebuffer(GL_FRAMEBUFFER, targets_.data());
    glViewport(0, 0, view.width, view.height);
    ClearTargets(true, settings.sky_rgb, /*keep_color=*/true);
    glDrawBuffers(3, kDataTargets);
    pass_.look = kDataOnly;
    DrawScene(Pass::kData, uniforms_.view_proj);
  }

  // The images as GL holds them (rows bottom first), read back without
  // conversion; depth before the overlay, which is drawn over colour (on
  // the CPU's image after deferred shading: its marks then in overlay_rgba_,
  // returned as `marks`).
  RawImages ReadRaw(const CameraView& view, const RenderSettings& settings, const FramePlan& plan,
                    const Overlay* overlay, const std::vector<std::uint32_t>** marks) {
    const int w = view.width, h = view.height;
    const std::size_t count = std::size_t(w) * std::size_t(h);
    RawImages raw;
    raw.width = w, raw.height = h, raw.near_m = view.near_m, raw.far_m = view.far_m;
    *marks = nullptr;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, targets_.data());
    if (plan.want_depth) {
      depth_.resize(count);
      glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth_.data());
      raw.depth = depth_.data();
    }
    if (plan.kinds & kSegmentationImage) {
      segment_.resize(count);
      glReadBuffer(GL_COLOR_ATTACHMENT1);
      glReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, segment_.data());
      raw.segment = segment_.data();
    }
    if (plan.kinds & kNormalsImage) {
      normal_.resize(3 * count);
      glReadBuffer(GL_COLOR_ATTACHMENT2);
      glReadPixels(0, 0, w, h, GL_RGB, GL_FLOAT, normal_.data());
      raw.normal = normal_.data();
    }
    if (plan.deferred) {
      const std::vector<std::uint8_t>* image = &lit_;
      if (settings.fxaa) {
        deferred_.FilterEdges(lit_, w, h, &filtered_);
        image = &filtered_;
      }
      if (plan.marks) {
        glBindFramebuffer(GL_FRAMEBUFFER, targets_.overlay());
        const float clear[] = {0.f, 0.f, 0.f, 0.f};
        glDrawBuffers(1, kColorOnly);
        glClearBufferfv(GL_COLOR, 0, clear);
        DrawOverlay(*overlay);
        overlay_rgba_.resize(count);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, targets_.overlay());
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, overlay_rgba_.data());
        *marks = &overlay_rgba_;
      }
      raw.rgba = image->data();
    } else if (plan.kinds & kColorImage) {
      glBindFramebuffer(GL_FRAMEBUFFER, targets_.data());
      if (plan.marks) {
        glDrawBuffers(1, kColorOnly);
        DrawOverlay(*overlay);
      }
      pixels_.resize(4 * count);
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels_.data());
      raw.rgba = pixels_.data();
    }
    return raw;
  }

  // The images, rows flipped to top first, depth in metres.
  void ReadBack(const CameraView& view, const RenderSettings& settings, const FramePlan& plan,
                const Overlay* overlay, Frame* frame) {
    const std::vector<std::uint32_t>* marks = nullptr;
    const RawImages raw = ReadRaw(view, settings, plan, overlay, &marks);
    const int w = view.width, h = view.height;
    frame->width = w;
    frame->height = h;
    frame->kinds = plan.kinds;
    frame->depth_m.clear();
    frame->segment.clear();
    frame->normal_C.clear();
    frame->rgb.clear();
    if (raw.depth) DepthImage(depth_, w, h, view.near_m, view.far_m, &frame->depth_m);
    if (raw.segment) FlippedImage(segment_, w, h, &frame->segment);
    if (raw.normal) FlippedImage(normal_, w, h, 3, &frame->normal_C);
    if (raw.rgba) RgbImage(raw.rgba, w, h, marks, &frame->rgb);
  }

  void DrawOverlay(const Overlay& overlay) {
    screen_.DrawOverlay(overlay, camera_, uniforms_.view_proj);
    programs_.Forget();
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
      glDrawBuffers(3, kAllTargets);
      glClearBufferuiv(GL_COLOR, 1, zero_id);
      glClearBufferfv(GL_COLOR, 2, zero);
    }
  }

  // Everything in the world, in one pass. Opaque first, then the translucent
  // (water) on top; whatever lies outside the view is skipped.
  // Opaque surfaces nearest first (robots, movable actors, level chunks by
  // distance, terrain, the ground beyond), so that llvmpipe's early depth
  // test skips the shading of what is hidden; then `between` (the sky, into
  // what no surface covered); then translucent surfaces far to near.
  void DrawScene(Pass pass, const Eigen::Matrix4f& view_proj,
                 const std::function<void()>& between = {}) {
    pass_.pass = pass;
    pass_.view_proj = view_proj;
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
    const bool moving = pass != Pass::kShadow || shadow_casters_ != ShadowMaps::Casters::kStill;
    const bool still = pass != Pass::kShadow || shadow_casters_ != ShadowMaps::Casters::kMoving;
    if (moving) {
      for (const RobotMeshes::Posed& robot : robots_->posed()) {
        // Its closed meshes as posed: the eye outside the robot's box.
        const bool outside = robot.bounds_W.exteriorDistance(camera_) > pass_.near_reach_m;
        for (const GpuMesh* mesh : robot.meshes) {
          drawer_.CullBackFacesIf(outside &&
                                  mesh->hidden.shape() == HiddenBackFaces::Shape::kSolid);
          drawer_.Draw(*mesh, Relative(Eigen::Affine3d(robot.pose.matrix()), camera_));
        }
      }
      for (const auto& [actor, mesh] : actor_meshes_) {
        if (Translucent(mesh)) continue;
        drawer_.CullHiddenBackFaces(mesh, (ActorPose(actor).inverse() * camera_).cast<float>());
        drawer_.Draw(mesh, actor_model(actor));
      }
    }
    if (still) {
      for (const auto& [distance, i] : static_order_) {
        const GpuMesh& mesh = static_meshes_[i].second;
        pass_.lod_error_m = chunk_error(i);
        if (Translucent(mesh)) continue;
        drawer_.CullHiddenBackFaces(mesh, eye_S);
        drawer_.Draw(mesh, static_model);
      }
      glDisable(GL_CULL_FACE);
      DrawTerrain();
    }
    if (horizon_.index_count > 0 && pass != Pass::kShadow) {
      const Eigen::Vector3f& rgb = level_->horizon->rgb;
      drawer_.DrawPlain(horizon_, static_model, Eigen::Vector4f(rgb.x(), rgb.y(), rgb.z(), 1.f), 0);
    }
    if (between) between();
    if (pass == Pass::kShadow) return;

    if (pass == Pass::kColor && !(pass_.look & kGBuffer)) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    }
    for (auto it = static_order_.rbegin(); it != static_order_.rend(); ++it) {
      const GpuMesh& mesh = static_meshes_[it->second].second;
      pass_.lod_error_m = chunk_error(it->second);
      if (Translucent(mesh)) drawer_.Draw(mesh, static_model);
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (Translucent(mesh)) drawer_.Draw(mesh, actor_model(actor));
    }
    glDisable(GL_BLEND);
  }

  // Terrain tiles in view, nearest first (terrain_meshes.h).
  void DrawTerrain() {
    if (!terrain_) return;
    const Eigen::Vector4f plain(level_->horizon ? level_->horizon->rgb.x() : 0.45f,
                                level_->horizon ? level_->horizon->rgb.y() : 0.5f,
                                level_->horizon ? level_->horizon->rgb.z() : 0.35f, 1.f);
    for (const TileDraw& draw :
         TileDraws(*terrain_, level_->terrain ? level_->terrain->coarse_factor : 1, camera_,
                   pass_.view_proj, /*casting_shadows=*/pass_.pass == Pass::kShadow)) {
      const TerrainTiles::Gpu& gpu = tiles_.at(draw.tile);
      drawer_.DrawPlain(
          gpu.mesh, Relative(Eigen::Affine3d(Eigen::Translation3d(draw.tile->origin_W)), camera_),
          gpu.texture ? Eigen::Vector4f(1.f, 1.f, 1.f, 1.f) : plain, gpu.texture, &draw.ranges);
    }
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
  Eigen::AlignedBox3f CameraCentred(const Eigen::AlignedBox3d& box_W) const {
    return box_W.isEmpty() ? Eigen::AlignedBox3f()
                           : Eigen::AlignedBox3f((box_W.min() - camera_).cast<float>(),
                                                 (box_W.max() - camera_).cast<float>());
  }
  // The robots' and opaque movable actors' bounds (camera-centred).
  Eigen::AlignedBox3f MovingCastersBoxC() const {
    Eigen::AlignedBox3f box_C;
    for (const RobotMeshes::Posed& robot : robots_->posed()) {
      if (!robot.bounds_W.isEmpty()) box_C.extend(CameraCentred(robot.bounds_W));
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (!Translucent(mesh)) box_C.extend(ActorBoundsC(actor));
    }
    return box_C;
  }

  // The error a draw of what stays, within `box_C`, may have: what lod_px
  // pixels span there and, with shadows, a fifth of a shadow-map texel
  // (deferred shading moves its shadow lookups off the surface by this
  // draw's allowance instead: LightingFrame::lod_offset_per_m). Shadow
  // passes set their own.
  float LodError(const Eigen::AlignedBox3f& box_C) const {
    if (pass_.pass == Pass::kShadow) return pass_.lod_error_m;
    const float error = PixelError(lod_px_, pixel_angle_, box_C);
    if (!(pass_.look & kShadows) || (pass_.look & kGBuffer)) return error;
    return UnderShadowTexel(error, uniforms_.cascades, uniforms_.view_axis, box_C);
  }

  // This frame's level of each robot's and movable actor's meshes (before
  // the shadow maps, which draw them at it too).
  void ChooseMovingLevels() {
    for (const RobotMeshes::Posed& robot : robots_->posed()) {
      const float error = PixelError(lod_px_, pixel_angle_, CameraCentred(robot.bounds_W));
      for (const GpuMesh* mesh : robot.meshes) {
        if (!mesh->lods.empty()) mesh->level = NextLevel(mesh->lods, mesh->level, error);
      }
    }
    for (const auto& [actor, mesh] : actor_meshes_) {
      if (!mesh.lods.empty()) {
        mesh.level = NextLevel(mesh.lods, mesh.level,
                               PixelError(lod_px_, pixel_angle_, ActorBoundsC(actor)));
      }
    }
  }

  bool Translucent(const GpuMesh& mesh) const {
    return IsTranslucent(*level_, mesh.material, mesh.surface);
  }

  // The parts, the context first (made current by its constructor).
  GlContext context_;
  ScenePrograms programs_;
  ScreenPasses screen_;
  FrameTargets targets_;
  ShadowMaps shadow_maps_;
  MaterialTextures textures_;
  TerrainTiles tiles_;
  MeshDrawer drawer_{programs_, textures_};
  PassState& pass_{drawer_.state()};  // the pass being drawn
  DeferredShader deferred_;
  DetailTextures detail_cpu_;
  GLuint detail_{0};
  GLfloat max_anisotropy_{1.f};
  GLuint anisotropic_{0};  // a sampler
  std::vector<std::string> warnings_;
  // A lens drawn through: its pinhole source view and remap.
  struct LensCache {
    Lens lens;
    int width, height;
    CameraView source;
    LensRemap remap;
  };
  static constexpr std::size_t kLensesKept = 8;  // the oldest goes first
  std::vector<std::unique_ptr<LensCache>> lenses_;

  // The level.
  const scene::Level* level_{nullptr};
  std::unique_ptr<scene::SurfaceIds> legend_;
  float water_level_{-1e9f};
  Eigen::Vector3d origin_{Eigen::Vector3d::Zero()};  // of the static chunks
  std::vector<std::pair<Eigen::AlignedBox3f, GpuMesh>> static_meshes_;
  std::vector<std::pair<int, GpuMesh>> actor_meshes_;  // movable actors'
  std::map<int, Eigen::AlignedBox3d> actor_bounds_A_;  // movable actors', by actor
  std::unique_ptr<RobotMeshes> robots_;
  GpuMesh horizon_;
  std::shared_ptr<const scene::TileList> terrain_;

  // The frame being drawn.
  FrameUniforms uniforms_;
  int look_base_{0};  // the frame's look: kGamma, kMaterials, kShadows
  ShadowMaps::Casters shadow_casters_{ShadowMaps::Casters::kAll};
  Eigen::Matrix4d view_proj_d_{Eigen::Matrix4d::Identity()};  // the camera's
  Eigen::Vector3d camera_{Eigen::Vector3d::Zero()};
  const std::vector<Eigen::Isometry3d>* actor_poses_{nullptr};
  std::vector<std::pair<float, std::size_t>> static_order_;  // this pass's chunks in view
  // Levels of detail: this frame's allowance in pixels and a pixel's angle.
  float lod_px_{0.f}, pixel_angle_{0.f};
  // What was read back.
  SurfaceLayer opaque_, translucent_;
  std::vector<std::uint8_t> lit_, filtered_, pixels_, marked_;
  std::vector<std::uint32_t> overlay_rgba_, segment_;
  std::vector<float> depth_, normal_;
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
