#pragma once
// The sun's shadow maps fitted to a camera's view: the view's frustum up to a
// distance cut into slices (near ones short, far ones long), each covered by an
// orthographic box along the sun, snapped to whole shadow-map texels in world
// coordinates so that shadows do not shimmer as the camera moves.

#include <Eigen/Geometry>
#include <vector>

#include "sensors/render/view.h"

namespace sandbox::render {

struct ShadowCascade {
  // Camera-centred world (world axes, origin at the camera) to the map's clip
  // space: x, y in [-1, 1] across the box, depth 0 on the sun's side to 1.
  Eigen::Matrix4d light_clip;
  double far_m{0.0};    // the slice ends this far along the optical axis
  double texel_m{0.0};  // one shadow-map texel on the ground
};

// `sun_W`: towards the sun (any length). `caster_reach_m`: how far towards the
// sun beyond a slice a caster may stand and still shade it.
std::vector<ShadowCascade> FitShadowCascades(const CameraView& view, const Eigen::Vector3d& sun_W,
                                             double distance_m, int count, int map_px,
                                             double caster_reach_m);

}  // namespace sandbox::render
