#include "scene/robot_description.h"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "scene/files.h"
#include "scene/placement.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// urdfdom reports through console_bridge's global handler: while a file is
// parsed, its errors and warnings are collected here instead of printed.
class Collect : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) lines.push_back(text);
  }
  std::vector<std::string> lines;
};

std::mutex urdfdom_mutex;  // the handler is global

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += (out.empty() ? "" : "; ") + line;
  return out;
}

Eigen::Isometry3d ToEigen(const urdf::Pose& pose) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  X.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  return X;
}

// The <name> a package.xml in `folder` gives its package ("" when none).
std::string PackageName(const fs::path& folder) {
  const fs::path manifest = folder / "package.xml";
  std::error_code error;
  if (!fs::is_regular_file(manifest, error)) return "";
  TiXmlDocument document;
  if (!document.LoadFile(manifest.string())) return "";
  const TiXmlElement* root = document.RootElement();
  const TiXmlElement* name = root != nullptr ? root->FirstChildElement("name") : nullptr;
  return name != nullptr && name->GetText() != nullptr ? name->GetText() : "";
}

std::vector<fs::path> PathList(const char* variable) {
  std::vector<fs::path> out;
  const char* value = std::getenv(variable);
  if (value == nullptr) return out;
  std::stringstream in(value);
  for (std::string item; std::getline(in, item, ':');) {
    if (!item.empty()) out.emplace_back(item);
  }
  return out;
}

// Refuses a link that is the child of two joints, and joints that form a
// loop, before urdfdom sees them (it reports them less clearly, and leaks the
// links of a loop).
void CheckJointTree(const fs::path& file, const TiXmlDocument& document) {
  const TiXmlElement* robot = document.RootElement();
  if (robot == nullptr) return;
  std::map<std::string, std::pair<std::string, std::string>> parent_of;  // child: parent, joint
  for (const TiXmlElement* joint = robot->FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    const char* name = joint->Attribute("name");
    if (parent == nullptr || child == nullptr || parent->Attribute("link") == nullptr ||
        child->Attribute("link") == nullptr || name == nullptr) {
      continue;  // urdfdom names what is missing
    }
    const auto [at, is_new] =
        parent_of.try_emplace(child->Attribute("link"), parent->Attribute("link"), name);
    if (!is_new) {
      throw LevelError(file.string() + ":" + std::to_string(joint->Row()) + ": link '" + at->first +
                       "' is the child of two joints ('" + at->second.second + "', '" + name +
                       "')");
    }
  }
  for (const auto& [start, unused] : parent_of) {
    std::set<std::string> seen{start};
    for (auto up = parent_of.find(start); up != parent_of.end();
         up = parent_of.find(up->second.first)) {
      if (!seen.insert(up->second.first).second) {
        throw LevelError(file.string() + ": the joints form a loop through link '" +
                         up->second.first + "' (joint '" + up->second.second + "')");
      }
    }
  }
}

LinkGeometry ConvertGeometry(const urdf::Geometry& geometry, const urdf::Pose& origin,
                             const fs::path& file, const std::string& where) {
  LinkGeometry out;
  out.X_LG = ToEigen(origin);
  auto positive = [&](double value, const char* what) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      throw LevelError(file.string() + ": " + where + ": " + what + " must be positive, got " +
                       std::to_string(value));
    }
    return value;
  };
  switch (geometry.type) {
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(geometry);
      out.kind = LinkGeometry::Kind::kMesh;
      try {
        out.mesh = ResolveResourceUri(mesh.filename, file);
      } catch (const LevelError& error) {
        throw LevelError(file.string() + ": " + where + ": " + error.what());
      }
      out.scale = {mesh.scale.x, mesh.scale.y, mesh.scale.z};
      if (!out.scale.allFinite() || (out.scale.array() == 0.0).any()) {
        throw LevelError(file.string() + ": " + where + ": mesh scale must be finite and nonzero");
      }
      break;
    }
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(geometry);
      out.kind = LinkGeometry::Kind::kBox;
      out.size = {positive(box.dim.x, "box size"), positive(box.dim.y, "box size"),
                  positive(box.dim.z, "box size")};
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      out.kind = LinkGeometry::Kind::kCylinder;
      out.radius = positive(cylinder.radius, "cylinder radius");
      out.length = positive(cylinder.length, "cylinder length");
      break;
    }
    case urdf::Geometry::SPHERE:
      out.kind = LinkGeometry::Kind::kSphere;
      out.radius = positive(static_cast<const urdf::Sphere&>(geometry).radius, "sphere radius");
      break;
  }
  return out;
}

}  // namespace

bool IsRobotDescription(const fs::path& file) {
  const std::string extension = LowerExtension(file);
  return extension == ".urdf" || extension == ".sdf";
}

RobotDescription ReadRobotDescription(const fs::path& file) {
  if (const std::string problem = RegularFileProblem(file); !problem.empty()) {
    throw LevelError(file.string() + ": " + problem);
  }
  return LowerExtension(file) == ".sdf" ? ReadSdf(file) : ReadUrdf(file);
}

void WarnIgnoredElements(const fs::path& file, const std::string& xml,
                         const std::vector<std::pair<std::string, std::string>>& ignored,
                         std::vector<std::string>* out) {
  TiXmlDocument document;
  document.Parse(xml.c_str());
  std::map<std::string, int> found;
  std::vector<const TiXmlElement*> stack;
  if (document.RootElement() != nullptr) stack.push_back(document.RootElement());
  while (!stack.empty()) {
    const TiXmlElement* element = stack.back();
    stack.pop_back();
    ++found[element->Value()];
    for (const TiXmlElement* child = element->FirstChildElement(); child != nullptr;
         child = child->NextSiblingElement()) {
      stack.push_back(child);
    }
  }
  for (const auto& [name, why] : ignored) {
    const auto count = found.find(name);
    if (count == found.end()) continue;
    out->push_back(file.string() + ": ignored " + std::to_string(count->second) + " <" + name +
                   "> element" + (count->second > 1 ? "s" : "") + " (" + why + ")");
  }
}

fs::path ResolveResourceUri(const std::string& uri, const fs::path& describing_file) {
  const fs::path folder = describing_file.parent_path();
  for (const char* scheme : {"package://", "model://"}) {
    const std::string prefix = scheme;
    if (uri.rfind(prefix, 0) != 0) continue;
    const std::string rest = uri.substr(prefix.size());
    const std::size_t slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    const fs::path inside =
        slash == std::string::npos ? fs::path() : fs::path(rest.substr(slash + 1));
    if (name.empty())
      throw LevelError("'" + uri + "' names no " + prefix.substr(0, prefix.size() - 3));
    std::vector<fs::path> searched;
    // A package or model folder under (or being) `dir`.
    auto look = [&](const fs::path& dir) -> std::optional<fs::path> {
      std::error_code error;
      for (const fs::path& candidate : {dir / name, dir}) {
        if (!fs::is_directory(candidate, error)) continue;
        if (candidate.filename() != name && PackageName(candidate) != name) continue;
        searched.push_back(candidate / inside);
        if (fs::exists(candidate / inside, error)) return candidate / inside;
      }
      if (searched.empty() || searched.back().parent_path() != dir) searched.push_back(dir / name);
      return std::nullopt;
    };
    std::vector<fs::path> places;
    for (fs::path dir = fs::absolute(folder); !dir.empty(); dir = dir.parent_path()) {
      places.push_back(dir);
      if (dir == dir.parent_path()) break;
    }
    for (const char* variable :
         {"SANDBOX_RESOURCE_PATH",
          prefix == "package://" ? "ROS_PACKAGE_PATH" : "GZ_SIM_RESOURCE_PATH"}) {
      for (const fs::path& dir : PathList(variable)) places.push_back(dir);
    }
    for (const fs::path& dir : places) {
      if (const auto found = look(dir)) return *found;
    }
    std::string list;
    for (const fs::path& path : searched) list += "\n  " + path.string();
    throw LevelError("'" + uri + "' not found; searched:" + list +
                     "\n(the describing file's folder and its parents, then SANDBOX_RESOURCE_PATH, "
                     "then " +
                     (prefix == "package://" ? "ROS_PACKAGE_PATH" : "GZ_SIM_RESOURCE_PATH") + ")");
  }
  fs::path path = uri.rfind("file://", 0) == 0 ? fs::path(uri.substr(7)) : fs::path(uri);
  if (path.is_relative()) path = folder / path;
  std::error_code error;
  if (!fs::exists(path, error)) throw LevelError("'" + uri + "' not found (" + path.string() + ")");
  return path;
}

RobotDescription ReadUrdf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw LevelError(file.string() + ": cannot read it");
  const std::string xml = text.str();
  {
    TiXmlDocument document;
    document.Parse(xml.c_str());
    if (document.Error()) {
      throw LevelError(file.string() + ":" + std::to_string(document.ErrorRow()) +
                       ": malformed XML: " + document.ErrorDesc());
    }
    CheckJointTree(file, document);
  }
  urdf::ModelInterfaceSharedPtr model;
  Collect messages;
  {
    const std::lock_guard<std::mutex> lock(urdfdom_mutex);
    console_bridge::useOutputHandler(&messages);
    try {
      model = urdf::parseURDF(xml);
    } catch (const std::exception& error) {  // urdfdom reports by value, but to be sure
      messages.lines.push_back(error.what());
    }
    console_bridge::restorePreviousOutputHandler();
  }
  if (model == nullptr) {
    throw LevelError(file.string() + ": not a valid URDF: " +
                     (messages.lines.empty() ? "urdfdom refused it" : Joined(messages.lines)));
  }
  RobotDescription out;
  out.file = file;
  out.name = model->getName();
  for (const std::string& line : messages.lines)
    out.warnings.push_back(file.string() + ": " + line);
  WarnIgnoredElements(file, xml,
                      {{"inertial", "the sandbox does not simulate dynamics"},
                       {"dynamics", "the sandbox does not simulate dynamics"},
                       {"transmission", "actuators are the publisher's business"},
                       {"gazebo", "Gazebo extensions"},
                       {"safety_controller", "joint values are only checked against <limit>"},
                       {"calibration", "joint values are taken as given"},
                       {"mimic", "every joint takes its own value"}},
                      &out.warnings);

  // Depth first from the root: parents before children.
  std::map<std::string, int> index_of;
  std::vector<urdf::LinkConstSharedPtr> stack{model->getRoot()};
  std::vector<urdf::JointConstSharedPtr> via{nullptr};
  while (!stack.empty()) {
    const urdf::LinkConstSharedPtr link = stack.back();
    const urdf::JointConstSharedPtr joint = via.back();
    stack.pop_back(), via.pop_back();
    if (!index_of.emplace(link->name, int(out.links.size())).second) {
      throw LevelError(file.string() + ": link '" + link->name +
                       "' is reached twice (a joint loop)");
    }
    DescribedLink described;
    described.name = link->name;
    const std::string where = "link '" + link->name + "'";
    for (const urdf::VisualSharedPtr& visual : link->visual_array) {
      if (visual == nullptr || visual->geometry == nullptr) continue;
      LinkGeometry geometry =
          ConvertGeometry(*visual->geometry, visual->origin, file, where + " visual");
      if (visual->material != nullptr) {
        const urdf::Color& c = visual->material->color;
        geometry.rgba = Eigen::Vector4f(c.r, c.g, c.b, c.a);
        geometry.material = visual->material_name;
      }
      described.visuals.push_back(std::move(geometry));
    }
    for (const urdf::CollisionSharedPtr& collision : link->collision_array) {
      if (collision == nullptr || collision->geometry == nullptr) continue;
      described.collisions.push_back(
          ConvertGeometry(*collision->geometry, collision->origin, file, where + " collision"));
    }
    out.links.push_back(std::move(described));
    if (joint != nullptr) {
      DescribedJoint j;
      j.name = joint->name;
      j.parent = index_of.at(joint->parent_link_name);
      j.child = index_of.at(link->name);
      j.X_PC = ToEigen(joint->parent_to_joint_origin_transform);
      const std::string at = file.string() + ": joint '" + joint->name + "': ";
      switch (joint->type) {
        case urdf::Joint::REVOLUTE:
          j.type = DescribedJoint::Type::kRevolute;
          break;
        case urdf::Joint::CONTINUOUS:
          j.type = DescribedJoint::Type::kContinuous;
          break;
        case urdf::Joint::PRISMATIC:
          j.type = DescribedJoint::Type::kPrismatic;
          break;
        case urdf::Joint::FIXED:
          j.type = DescribedJoint::Type::kFixed;
          break;
        default:
          out.warnings.push_back(at +
                                 "a floating or planar joint is held fixed (its value is the "
                                 "robot's pose, or not supported)");
          j.type = DescribedJoint::Type::kFixed;
      }
      if (j.moves()) {
        j.axis = Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
        if (!j.axis.allFinite() || j.axis.norm() < 1e-9) throw LevelError(at + "zero <axis>");
        j.axis.normalize();
      }
      if (j.type == DescribedJoint::Type::kRevolute || j.type == DescribedJoint::Type::kPrismatic) {
        if (joint->limits == nullptr) throw LevelError(at + "<limit> is required");
        j.lower = joint->limits->lower, j.upper = joint->limits->upper;
        if (!(j.lower <= j.upper)) {
          throw LevelError(at + "<limit> lower " + std::to_string(j.lower) + " is above upper " +
                           std::to_string(j.upper));
        }
      }
      out.joints.push_back(std::move(j));
    }
    // Children pushed in reverse, so that they come out by name.
    std::vector<urdf::JointSharedPtr> children = link->child_joints;
    std::sort(children.begin(), children.end(),
              [](const auto& a, const auto& b) { return a->name > b->name; });
    for (const urdf::JointSharedPtr& child : children) {
      stack.push_back(model->getLink(child->child_link_name));
      via.push_back(child);
    }
  }
  if (out.links.size() != model->links_.size()) {
    throw LevelError(file.string() + ": " +
                     std::to_string(model->links_.size() - out.links.size()) +
                     " links are not connected to the root link '" + out.links[0].name + "'");
  }
  return out;
}

}  // namespace sandbox::scene
