#include "sensors/render/shadow_maps.h"

#include <limits>

namespace sandbox::render {
namespace {

constexpr int kMovingShadowPx = 512;  // the moving casters' map (deferred shading)

// A fifth of a texel: with a surface's own error (mesh_lods.h), under the
// shadows' bias of 0.4 texel and more.
float ShadowLodError(const ShadowCascade& cascade, float lod_px) {
  return lod_px > 0.f ? float(cascade.texel_m) / 5.f : 0.f;
}

}  // namespace

void ShadowMaps::Allocate(int px, int layers) {
  for (GLuint* map : {&map_, &static_}) {
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
  if (fbo_ == 0) glGenFramebuffers(1, &fbo_);
  px_ = px;
  layers_ = layers;
  static_keys_.clear();
}

void ShadowMaps::Draw(const std::vector<ShadowCascade>& cascades, const Eigen::Vector3f& sun,
                      int px, bool cpu, const scene::TileList* terrain, float lod_px,
                      const Eigen::AlignedBox3f& moving_box_C, const DrawCasters& draw) {
  const int layers = int(cascades.size());
  if (map_ == 0 || px_ != px || layers_ < layers) Allocate(px, layers);
  static_keys_.resize(std::size_t(layers));
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
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
    const StaticKey key{cascade.cell, cascade.half_size_m, sun, terrain};
    if (!(static_keys_[std::size_t(c)] == key)) {
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, static_, 0, c);
      glClear(GL_DEPTH_BUFFER_BIT);
      draw(Casters::kStill, cascade.light_clip.cast<float>(), ShadowLodError(cascade, lod_px),
           false);
      static_keys_[std::size_t(c)] = key;
    }
    if (cpu) {
      ReadStill(c, px);
      continue;
    }
    glCopyImageSubData(static_, GL_TEXTURE_2D_ARRAY, 0, 0, 0, c, map_, GL_TEXTURE_2D_ARRAY, 0, 0, 0,
                       c, px, px, 1);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, map_, 0, c);
    draw(Casters::kMoving, cascade.light_clip.cast<float>(), ShadowLodError(cascade, lod_px),
         false);
  }
  if (cpu) DrawMovingForCpu(sun, lod_px, moving_box_C, draw);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

// Cascade c's still casters for the CPU: read back when its map was redrawn.
void ShadowMaps::ReadStill(int c, int px) {
  const std::size_t layer = std::size_t(px) * std::size_t(px);
  if (cpu_static_.size() != std::size_t(layers_) * layer) {
    cpu_static_.assign(std::size_t(layers_) * layer, 1.f);
    cpu_static_keys_.assign(std::size_t(layers_), StaticKey{});
  }
  if (cpu_static_keys_[std::size_t(c)] == static_keys_[std::size_t(c)]) return;
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, static_, 0, c);
  glReadPixels(0, 0, px, px, GL_DEPTH_COMPONENT, GL_FLOAT, &cpu_static_[std::size_t(c) * layer]);
  cpu_static_keys_[std::size_t(c)] = static_keys_[std::size_t(c)];
}

// The moving casters for the CPU: drawn once into a map of their own
// around them and read back; where no caster was drawn, infinitely deep.
void ShadowMaps::DrawMovingForCpu(const Eigen::Vector3f& sun, float lod_px,
                                  const Eigen::AlignedBox3f& box_C, const DrawCasters& draw) {
  moving_casters_ = ShadowMapView{};
  if (box_C.isEmpty()) return;
  const ShadowCascade box =
      FitCasterShadow(box_C.center().cast<double>(), 0.5 * box_C.diagonal().norm() + 0.01,
                      sun.cast<double>(), kMovingShadowPx);
  if (moving_fbo_ == 0) {
    glGenFramebuffers(1, &moving_fbo_);
    glGenRenderbuffers(1, &moving_depth_buffer_);
    glBindRenderbuffer(GL_RENDERBUFFER, moving_depth_buffer_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, kMovingShadowPx, kMovingShadowPx);
    glBindFramebuffer(GL_FRAMEBUFFER, moving_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              moving_depth_buffer_);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, moving_fbo_);
  glViewport(0, 0, kMovingShadowPx, kMovingShadowPx);
  glClear(GL_DEPTH_BUFFER_BIT);
  draw(Casters::kMoving, box.light_clip.cast<float>(), ShadowLodError(box, lod_px), true);
  moving_depth_.resize(std::size_t(kMovingShadowPx) * kMovingShadowPx);
  glReadPixels(0, 0, kMovingShadowPx, kMovingShadowPx, GL_DEPTH_COMPONENT, GL_FLOAT,
               moving_depth_.data());
  for (float& d : moving_depth_) {
    if (d >= 1.f) d = std::numeric_limits<float>::infinity();
  }
  moving_casters_ = {box.light_clip.cast<float>(), 0.f, float(box.texel_m), kMovingShadowPx,
                     moving_depth_.data()};
}

std::vector<ShadowMapView> ShadowMaps::CpuCascades(
    const std::vector<ShadowCascade>& cascades) const {
  std::vector<ShadowMapView> views;
  const std::size_t layer = std::size_t(px_) * std::size_t(px_);
  for (std::size_t c = 0; c < cascades.size(); ++c) {
    views.push_back({cascades[c].light_clip.cast<float>(), float(cascades[c].far_m),
                     float(cascades[c].texel_m), px_, &cpu_static_[c * layer]});
  }
  return views;
}

}  // namespace sandbox::render
