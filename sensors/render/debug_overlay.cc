#include "sensors/render/debug_overlay.h"

#include <cmath>

namespace sandbox::render {

Eigen::Vector3f SurfaceColour(std::int32_t id) {
  if (id == 0) return {0.5f, 0.5f, 0.5f};
  const double hue = 6.0 * std::fmod(double(id) * 0.6180339887498949, 1.0);
  const float value = 0.95f, low = value * (1.f - 0.8f);
  const int sector = int(hue) % 6;
  const float f = float(hue - std::floor(hue));
  const float falling = value - (value - low) * f, rising = low + (value - low) * f;
  switch (sector) {
    case 0:
      return {value, rising, low};
    case 1:
      return {falling, value, low};
    case 2:
      return {low, value, rising};
    case 3:
      return {low, falling, value};
    case 4:
      return {rising, low, value};
    default:
      return {value, low, falling};
  }
}

void AddFaceScan(const sensors::FaceScan& scan, double stub_m, Overlay* overlay,
                 SampleColour colour) {
  const Eigen::Vector3f red(1.f, 0.1f, 0.1f), green(0.1f, 0.9f, 0.1f);
  const bool by_surface = colour == SampleColour::kSurface;
  for (int f = 0; f < 6; ++f) {
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    if (face.tick < 0) continue;
    const Eigen::Vector3d origin_W = face.X_WS.translation();
    for (std::size_t i = 0; i < face.distance_m.size() && i < face.occupancy.size(); ++i) {
      if (face.occupancy[i] == sensors::kUnvisited) continue;
      const bool occupied = face.occupancy[i] == sensors::kOccupied;
      const Eigen::Vector3f rgb =
          by_surface ? SurfaceColour(occupied && i < face.surface.size() ? face.surface[i] : 0)
          : occupied ? red
                     : green;
      const Eigen::Vector3d p_W = scan.PointW(f, i);
      if (stub_m <= 0.0) {
        overlay->AddPoint(p_W, rgb);
        continue;
      }
      const Eigen::Vector3d back = origin_W - p_W;
      const double length = back.norm();
      overlay->AddLine(
          p_W, length > 1e-9 ? Eigen::Vector3d(p_W + back * std::min(1.0, stub_m / length)) : p_W,
          rgb);
    }
  }
}

void AddBoneFrames(const scene::RobotState& state, double axis_m, Overlay* overlay) {
  const Eigen::Vector3f axis_rgb[3] = {{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.3f, 1.f}};
  for (const scene::Bone& bone : state.model().bones) {
    const Eigen::Isometry3d X_WN =
        state.pose() * scene::RigidPart(state.node_poses_B()[std::size_t(bone.node)]);
    for (int k = 0; k < 3; ++k) {
      overlay->AddLine(X_WN.translation(),
                       X_WN * Eigen::Vector3d(axis_m * Eigen::Vector3d::Unit(k)), axis_rgb[k]);
    }
  }
}

void AddActorBounds(const scene::Level& level, const std::vector<Eigen::Isometry3d>& actor_poses,
                    bool static_too, Overlay* overlay) {
  const Eigen::Vector3f movable_rgb(1.f, 0.85f, 0.1f), static_rgb(0.6f, 0.6f, 0.6f);
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    const scene::Actor& actor = level.actors[a];
    if (actor.bounds_W.isEmpty() || (!actor.movable && !static_too)) continue;
    // The box was taken at the load pose; carry it to the current one.
    const Eigen::Isometry3d move = actor_poses.size() == level.actors.size()
                                       ? actor_poses[a] * actor.X_WA.inverse()
                                       : Eigen::Isometry3d::Identity();
    Eigen::Vector3d corner[8];
    for (int c = 0; c < 8; ++c) {
      corner[c] = move * actor.bounds_W.corner(Eigen::AlignedBox3d::CornerType(c));
    }
    // Corner bits: 1 = x max, 2 = y max, 4 = z max; edges join corners one bit apart.
    for (int c = 0; c < 8; ++c) {
      for (int bit = 1; bit < 8; bit <<= 1) {
        if ((c & bit) == 0) {
          overlay->AddLine(corner[c], corner[c | bit], actor.movable ? movable_rgb : static_rgb);
        }
      }
    }
  }
}

}  // namespace sandbox::render
