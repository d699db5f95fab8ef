#pragma once
// The robots as posed each frame: their skinned meshes uploaded at first
// sight (with levels of detail within the vertices that follow the same
// bones alike, and a per-triangle table of bone groups for segmentation),
// then only their positions and normals rewritten each frame.

#include <Eigen/Geometry>
#include <map>
#include <utility>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/surface_ids.h"
#include "sensors/render/gpu_mesh.h"

namespace sandbox::render {

class RobotMeshes {
 public:
  // `level` and `legend` outlive this.
  RobotMeshes(const scene::Level& level, const scene::SurfaceIds& legend);

  // This frame's robots, uploaded (first sight) or updated.
  void Pose(const std::vector<const scene::RobotState*>& robots);

  struct Posed {
    Eigen::Isometry3d pose;
    std::vector<const GpuMesh*> meshes;
    Eigen::AlignedBox3d bounds_W;  // as posed (empty when it has no vertices)
  };
  const std::vector<Posed>& posed() const { return posed_; }

 private:
  int RobotIndex(const scene::RobotModel& model) const;

  const scene::Level& level_;
  const scene::SurfaceIds& legend_;
  std::map<const scene::RobotModel*, std::vector<GpuMesh>> meshes_;
  std::map<const scene::RobotModel*, std::vector<std::vector<std::uint32_t>>> groups_;
  std::vector<Posed> posed_;
};

// Per vertex of a skinned mesh, an id of the bones and weights it follows.
std::vector<std::uint32_t> SkinGroups(const scene::SkinnedMesh& mesh);

}  // namespace sandbox::render
