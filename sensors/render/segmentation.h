#pragma once
// Segmentation ids: one per actor, one for the ground beyond the level, and
// one per bone group of each robot (a bone of its bone map with the nodes
// below it that are not bones themselves). 0 is the sky. The legend names
// each id; it depends on the level alone, so every camera of a run agrees.

#include <cstdint>
#include <string>
#include <vector>

#include "scene/level.h"

namespace sandbox::render {

struct SegmentEntry {
  std::uint32_t id{0};
  std::string kind;  // "actor", "horizon", "robot" (its root bone group) or "bone"
  std::string name;  // the actor's, "horizon", or "robot/bone"
};

class SegmentationLegend {
 public:
  explicit SegmentationLegend(const scene::Level& level);

  static constexpr std::uint32_t kSky = 0;
  std::uint32_t actor(int actor_index) const { return std::uint32_t(1 + actor_index); }
  std::uint32_t horizon() const { return horizon_; }
  // The id of bone `bone` (an index into the bone map) of level robot `robot`.
  std::uint32_t bone(int robot, int bone) const {
    return robot_base_[std::size_t(robot)] + std::uint32_t(bone);
  }
  // The robot that owns `id`, or -1 (actors, horizon, sky).
  int RobotOf(std::uint32_t id) const;
  const std::vector<SegmentEntry>& entries() const { return entries_; }
  // "id,kind,name" lines with a header, as written beside the frames.
  std::string Csv() const;

 private:
  std::uint32_t horizon_{0};
  std::vector<std::uint32_t> robot_base_;
  std::vector<SegmentEntry> entries_;
};

// For each triangle of mesh `mesh` of `model`, the bone map entry of its bone
// group: the nearest bone at or above the node that carries most of the
// triangle's weight (scene::DominantNodePerTriangle); 0 (the root) when none.
std::vector<std::uint32_t> BoneGroupPerTriangle(const scene::RobotModel& model, int mesh);

}  // namespace sandbox::render
