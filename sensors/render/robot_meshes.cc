#include "sensors/render/robot_meshes.h"

#include <algorithm>

#include "sensors/render/level_meshes.h"
#include "sensors/render/mesh_lods.h"

namespace sandbox::render {

RobotMeshes::RobotMeshes(const scene::Level& level, const scene::SurfaceIds& legend)
    : level_(level), legend_(legend) {
  // The robots' bone groups, per triangle, for segmentation.
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    std::vector<std::vector<std::uint32_t>>& groups = groups_[&level.robots[r]];
    for (std::size_t m = 0; m < level.robots[r].meshes.size(); ++m) {
      groups.push_back(scene::BoneGroupPerTriangle(level.robots[r], int(m)));
    }
  }
}

void RobotMeshes::Pose(const std::vector<const scene::RobotState*>& robots) {
  posed_.clear();
  for (const scene::RobotState* state : robots) {
    const scene::RobotModel& model = state->model();
    std::vector<GpuMesh>& meshes = meshes_[&model];
    // (Room for all first: pointers into `meshes` are kept below.)
    meshes.reserve(model.meshes.size());
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
        meshes.push_back(Upload({&state->positions_B(int(m)), &state->normals_B(int(m)), &bind.uvs,
                                 &bind.lightmap_uvs, &bind.colors, nullptr, nullptr, &lods},
                                bind.material, GL_DYNAMIC_DRAW));
        const int r = RobotIndex(model);
        meshes.back().moving = true;
        // (Closed as made; its volume as first posed.)
        if (DrawnWhole(level_, bind.material, std::nullopt)) {
          meshes.back().hidden = HiddenBackFaces::Of(state->positions_B(int(m)), bind.indices);
        }
        meshes.back().segment_base = r >= 0 ? legend_.bone(r, 0) : 0xffffu;
        const auto groups = groups_.find(&model);
        if (r >= 0 && groups != groups_.end()) {
          SetTriangleSegments(&meshes.back(), groups->second[m]);
        }
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
    Eigen::AlignedBox3d bounds_W;
    for (int k = 0; k < 8 && !bounds_B.isEmpty(); ++k) {
      bounds_W.extend(state->pose() *
                      bounds_B.corner(Eigen::AlignedBox3f::CornerType(k)).cast<double>());
    }
    posed_.push_back({state->pose(), std::move(drawn), bounds_W});
  }
}

int RobotMeshes::RobotIndex(const scene::RobotModel& model) const {
  for (std::size_t r = 0; r < level_.robots.size(); ++r) {
    if (&level_.robots[r] == &model) return int(r);
  }
  return -1;
}

std::vector<std::uint32_t> SkinGroups(const scene::SkinnedMesh& mesh) {
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

}  // namespace sandbox::render
