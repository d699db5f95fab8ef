#include "sensors/render/segmentation.h"

#include <sstream>

namespace sandbox::render {

SegmentationLegend::SegmentationLegend(const scene::Level& level) {
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    entries_.push_back({actor(int(a)), "actor", level.actors[a].name});
  }
  horizon_ = std::uint32_t(level.actors.size() + 1);
  entries_.push_back({horizon_, "horizon", "horizon"});
  std::uint32_t next = horizon_ + 1;
  for (const scene::RobotModel& robot : level.robots) {
    robot_base_.push_back(next);
    for (std::size_t b = 0; b < robot.bones.size(); ++b) {
      entries_.push_back({next + std::uint32_t(b), b == 0 ? "robot" : "bone",
                          robot.name + "/" + robot.bones[b].name});
    }
    next += std::uint32_t(std::max<std::size_t>(robot.bones.size(), 1));
  }
}

int SegmentationLegend::RobotOf(std::uint32_t id) const {
  for (std::size_t r = robot_base_.size(); r-- > 0;) {
    if (id >= robot_base_[r]) return int(r);
  }
  return -1;
}

std::string SegmentationLegend::Csv() const {
  std::ostringstream out;
  out << "id,kind,name\n";
  for (const SegmentEntry& entry : entries_) {
    out << entry.id << "," << entry.kind << "," << entry.name << "\n";
  }
  return out.str();
}

std::vector<std::uint32_t> BoneGroupPerTriangle(const scene::RobotModel& model, int mesh) {
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
  std::vector<std::uint32_t> out;
  for (const int node : scene::DominantNodePerTriangle(model, mesh)) {
    out.push_back(node >= 0 && std::size_t(node) < group.size()
                      ? std::uint32_t(group[std::size_t(node)])
                      : 0u);
  }
  return out;
}

}  // namespace sandbox::render
