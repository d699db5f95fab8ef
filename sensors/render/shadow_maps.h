#pragma once
// The sun's shadow maps: per cascade, what does not move (level chunks,
// terrain) drawn into a map of its own only when the cascade's box, the sun
// or the terrain's tiles change; each frame that map copied and what moves
// (robots, movable actors) drawn over it. For deferred shading (the CPU
// lights the pixels), the still casters' maps are read back when redrawn,
// and the moving casters drawn each frame into one map around them.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "scene/terrain_streamer.h"
#include "sensors/render/deferred_shading.h"
#include "sensors/render/gl.h"
#include "sensors/render/shadow_cascades.h"

namespace sandbox::render {

class ShadowMaps {
 public:
  // What a shadow pass draws: all, what never moves, or what may.
  enum class Casters { kAll, kStill, kMoving };
  // Draws `casters` as the sun sees them through `light_clip` (camera-
  // centred world to the map's clip), at `lod_error_m`; `for_cpu`: the
  // moving casters at their level of this frame's colour, for the CPU.
  using DrawCasters = std::function<void(Casters casters, const Eigen::Matrix4f& light_clip,
                                         float lod_error_m, bool for_cpu)>;

  // This frame's maps, `px` texels a side. `terrain`: the tiles drawn (a
  // new list redraws the still casters). `lod_px` > 0: casters drawn at a
  // fifth of a texel's error. With `cpu`, `moving_box_C` bounds the moving
  // casters (camera-centred; empty: none).
  void Draw(const std::vector<ShadowCascade>& cascades, const Eigen::Vector3f& sun, int px,
            bool cpu, const scene::TileList* terrain, float lod_px,
            const Eigen::AlignedBox3f& moving_box_C, const DrawCasters& draw);
  // After a new level: every still map is drawn anew.
  void Forget() { static_keys_.clear(); }

  GLuint map() const { return map_; }  // a depth texture array, one layer a cascade
  // The maps as the CPU shades with them (after Draw with `cpu`).
  std::vector<ShadowMapView> CpuCascades(const std::vector<ShadowCascade>& cascades) const;
  const ShadowMapView& moving_casters() const { return moving_casters_; }

 private:
  // What each cascade's map of still casters was drawn for.
  struct StaticKey {
    std::array<std::int64_t, 3> cell{0, 0, 0};
    double half_size_m{-1.0};
    Eigen::Vector3f sun{Eigen::Vector3f::Zero()};
    const scene::TileList* terrain{nullptr};
    bool operator==(const StaticKey& o) const {
      return cell == o.cell && half_size_m == o.half_size_m && sun == o.sun && terrain == o.terrain;
    }
  };
  void Allocate(int px, int layers);
  void ReadStill(int c, int px);
  void DrawMovingForCpu(const Eigen::Vector3f& sun, float lod_px, const Eigen::AlignedBox3f& box_C,
                        const DrawCasters& draw);

  GLuint fbo_{0}, map_{0}, static_{0};
  int px_{0}, layers_{0};
  std::vector<StaticKey> static_keys_;
  std::vector<float> cpu_static_;           // the still casters' maps
  std::vector<StaticKey> cpu_static_keys_;  // what cpu_static_ holds
  GLuint moving_fbo_{0}, moving_depth_buffer_{0};
  std::vector<float> moving_depth_;  // the moving casters' map
  ShadowMapView moving_casters_;
};

}  // namespace sandbox::render
