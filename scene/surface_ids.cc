#include "scene/surface_ids.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace sandbox::scene {

namespace {

float Linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

const Material& MaterialOf(const Mesh& mesh, const std::vector<Material>& materials) {
  static const Material plain;
  return mesh.material >= 0 && std::size_t(mesh.material) < materials.size()
             ? materials[std::size_t(mesh.material)]
             : plain;
}

// The triangle-weighted mean of `of(mesh)` over `meshes`; 0.5 without triangles.
template <typename Of>
float TriangleMean(const std::vector<const Mesh*>& meshes, Of of) {
  double sum = 0.0, triangles = 0.0;
  for (const Mesh* mesh : meshes) {
    const double n = double(mesh->num_triangles());
    sum += double(of(*mesh)) * n, triangles += n;
  }
  return triangles > 0.0 ? float(sum / triangles) : SurfaceEntry::kDefaultReflectivity;
}

}  // namespace

float MaterialReflectivity(const Material& m) {
  Eigen::Vector3f rgb = m.base_color.head<3>().cwiseMax(0.f).cwiseMin(1.f);
  if (!m.linear_color) rgb = {Linear(rgb.x()), Linear(rgb.y()), Linear(rgb.z())};
  double y = 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
  if (!m.base_color_texture_path.empty() || m.base_color_texture_embedded >= 0) y *= 0.5;
  return float(y);
}

float MeshReflectivity(const Actor& actor, const Mesh& mesh,
                       const std::vector<Material>& materials) {
  const Material& material = MaterialOf(mesh, materials);
  if (mesh.material >= 0) {
    const auto entry = actor.material_reflectivity.find(material.name);
    if (entry != actor.material_reflectivity.end()) return float(entry->second);
  }
  if (actor.reflectivity) return float(*actor.reflectivity);
  return MaterialReflectivity(material);
}

float DerivedReflectivity(const std::vector<const Mesh*>& meshes,
                          const std::vector<Material>& materials) {
  return TriangleMean(
      meshes, [&](const Mesh& mesh) { return MaterialReflectivity(MaterialOf(mesh, materials)); });
}

SurfaceIds::SurfaceIds(const Level& level) {
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    const Actor& source = level.actors[a];
    SurfaceEntry entry;
    entry.id = actor(int(a)), entry.kind = "actor", entry.name = source.name;
    entry.actor = int(a);
    std::vector<const Mesh*> meshes;
    for (const Mesh& mesh : source.meshes) meshes.push_back(&mesh);
    entry.reflectivity = meshes.empty() && source.reflectivity
                             ? float(*source.reflectivity)
                             : TriangleMean(meshes, [&](const Mesh& mesh) {
                                 return MeshReflectivity(source, mesh, level.materials);
                               });
    entries_.push_back(std::move(entry));
  }
  horizon_ = std::int32_t(level.actors.size() + 1);
  SurfaceEntry horizon;
  horizon.id = horizon_, horizon.kind = "horizon", horizon.name = "horizon";
  horizon.reflectivity = 0.f;
  entries_.push_back(std::move(horizon));
  std::int32_t next = horizon_ + 1;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    const RobotModel& robot = level.robots[r];
    robot_base_.push_back(next);
    std::vector<const Mesh*> meshes;
    for (const auto& mesh : robot.meshes) meshes.push_back(&mesh.bind);
    const float robot_reflectivity = DerivedReflectivity(meshes, level.materials);
    for (std::size_t b = 0; b < robot.bones.size(); ++b) {
      SurfaceEntry entry;
      entry.id = next + std::int32_t(b), entry.kind = b == 0 ? "robot" : "bone";
      entry.name = robot.name + "/" + robot.bones[b].name;
      entry.robot = int(r);
      entry.robot_name = robot.name;
      entry.bone = int(b);
      entry.bone_name = robot.bones[b].name;
      entry.reflectivity = robot_reflectivity;
      entries_.push_back(std::move(entry));
    }
    next += std::int32_t(std::max<std::size_t>(robot.bones.size(), 1));
  }
  end_ = next;
  reflectivity_.assign(std::size_t(end_), 0.f);
  for (const SurfaceEntry& entry : entries_) {
    if (entry.kind != "horizon") reflectivity_[std::size_t(entry.id)] = entry.reflectivity;
  }
  if (level.terrain_actor >= 0)
    tile_reflectivity_ = reflectivity_[std::size_t(actor(level.terrain_actor))];
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
  for (const int node : DominantNodePerTriangle(model, model.meshes.at(std::size_t(mesh)))) {
    out.push_back(node >= 0 && std::size_t(node) < group.size()
                      ? std::uint32_t(group[std::size_t(node)])
                      : 0u);
  }
  return out;
}

}  // namespace sandbox::scene
