#pragma once
// The sun's shadow maps fitted to a camera's view: the view's frustum up to a
// distance cut into slices (near ones short, far ones long), each covered by an
// orthographic box along the sun. The box's size depends on the slice's size
// only, and its centre moves in steps of an eighth of the map (whole texels),
// so shadows do not shimmer as the camera moves, and a map of what does not
// move stays valid until the box steps (`cell` tells when).

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "sensors/render/view.h"

namespace sandbox::render {

struct ShadowCascade {
  // Camera-centred world (world axes, origin at the camera) to the map's clip
  // space: x, y in [-1, 1] across the box, depth 0 on the sun's side to 1.
  Eigen::Matrix4d light_clip;
  double far_m{0.0};    // the slice ends this far along the optical axis
  double texel_m{0.0};  // one shadow-map texel on the ground
  // The box in absolute light coordinates: its centre in steps, and its half
  // size; equal cells of equal sun and size: the same box.
  std::array<std::int64_t, 3> cell{0, 0, 0};
  double half_size_m{0.0};
};

// `sun_W`: towards the sun (any length). `caster_reach_m`: how far towards the
// sun beyond a slice a caster may stand and still shade it.
std::vector<ShadowCascade> FitShadowCascades(const CameraView& view, const Eigen::Vector3d& sun_W,
                                             double distance_m, int count, int map_px,
                                             double caster_reach_m);

// A map of `map_px` texels a side, seen from the sun, around casters within
// `radius_m` of `centre_C` (camera-centred): its box is the sphere's, depth 0
// at its top towards the sun and 1 at its bottom (receivers further down lie
// beyond 1). far_m and cell are not set.
ShadowCascade FitCasterShadow(const Eigen::Vector3d& centre_C, double radius_m,
                              const Eigen::Vector3d& sun_W, int map_px);

}  // namespace sandbox::render
