#include "scene/surface_ids.h"

#include <algorithm>
#include <sstream>

namespace sandbox::scene {

SurfaceIds::SurfaceIds(const Level& level) {
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    SurfaceEntry entry;
    entry.id = actor(int(a)), entry.kind = "actor", entry.name = level.actors[a].name;
    entry.actor = int(a);
    entries_.push_back(std::move(entry));
  }
  horizon_ = std::int32_t(level.actors.size() + 1);
  SurfaceEntry horizon;
  horizon.id = horizon_, horizon.kind = "horizon", horizon.name = "horizon";
  entries_.push_back(std::move(horizon));
  std::int32_t next = horizon_ + 1;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    const RobotModel& robot = level.robots[r];
    robot_base_.push_back(next);
    for (std::size_t b = 0; b < robot.bones.size(); ++b) {
      SurfaceEntry entry;
      entry.id = next + std::int32_t(b), entry.kind = b == 0 ? "robot" : "bone";
      entry.name = robot.name + "/" + robot.bones[b].name;
      entry.robot = int(r);
      entry.robot_name = robot.name;
      entry.bone = int(b);
      entry.bone_name = robot.bones[b].name;
      entries_.push_back(std::move(entry));
    }
    next += std::int32_t(std::max<std::size_t>(robot.bones.size(), 1));
  }
  end_ = next;
}

const SurfaceEntry* SurfaceIds::Find(std::int32_t id) const {
  if (id < 1 || std::size_t(id) > entries_.size()) return nullptr;
  return &entries_[std::size_t(id - 1)];
}

std::string SurfaceIds::Csv() const {
  std::ostringstream out;
  out << "id,kind,name\n";
  for (const SurfaceEntry& entry : entries_) {
    out << entry.id << "," << entry.kind << "," << entry.name << "\n";
  }
  return out.str();
}

std::vector<int> BoneGroupOfNodes(const RobotModel& model) {
  // Each node's bone group: its own bone, else its parent's (parents first).
  std::vector<int> group(model.nodes.size(), -1);
  for (std::size_t b = 0; b < model.bones.size(); ++b) {
    if (model.bones[b].node >= 0) group[std::size_t(model.bones[b].node)] = int(b);
  }
  for (std::size_t n = 0; n < model.nodes.size(); ++n) {
    if (group[n] < 0) {
      const int parent = model.nodes[n].parent;
      group[n] = parent >= 0 ? group[std::size_t(parent)] : 0;
    }
  }
  return group;
}

std::vector<std::uint32_t> BoneGroupPerTriangle(const RobotModel& model, int mesh) {
  const std::vector<int> group = BoneGroupOfNodes(model);
  std::vector<std::uint32_t> out;
  for (const int node : DominantNodePerTriangle(model, mesh)) {
    out.push_back(node >= 0 && std::size_t(node) < group.size()
                      ? std::uint32_t(group[std::size_t(node)])
                      : 0u);
  }
  return out;
}

}  // namespace sandbox::scene
