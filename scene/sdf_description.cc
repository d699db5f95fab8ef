// SDF robot descriptions, read with sdformat (the model of a model file, its
// <include>d models nested under their names: "gps::link").

#include <tinyxml.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sdf/sdf.hh>
#include <set>
#include <sstream>

#include "scene/files.h"
#include "scene/placement.h"
#include "scene/robot_description.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

Eigen::Isometry3d ToEigen(const ignition::math::Pose3d& pose) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z());
  const ignition::math::Quaterniond& q = pose.Rot();
  X.linear() = Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()).normalized().toRotationMatrix();
  return X;
}

std::string ErrorText(const sdf::Error& error) {
  std::string text = error.Message();
  if (error.FilePath())
    text = *error.FilePath() +
           (error.LineNumber() ? ":" + std::to_string(*error.LineNumber()) : "") + ": " + text;
  return text;
}

// sdformat's errors that do not stop a robot from being read: Gazebo-classic
// material scripts, deprecations, inertia (not used here).
bool Harmless(const sdf::Error& error) {
  switch (error.Code()) {
    case sdf::ErrorCode::ELEMENT_INVALID:
      return error.Message().find("<script>") != std::string::npos;
    case sdf::ErrorCode::ELEMENT_DEPRECATED:
    case sdf::ErrorCode::ATTRIBUTE_DEPRECATED:
    case sdf::ErrorCode::VERSION_DEPRECATED:
    case sdf::ErrorCode::LINK_INERTIA_INVALID:
      return true;
    default:
      return false;
  }
}

double Limit(double value) {
  // Gazebo models write +-1e16 for "no limit".
  return std::abs(value) >= 1e15 ? std::copysign(HUGE_VAL, value) : value;
}

// What sdformat 12 would crash on, refused before it reads the file: a URDF
// (it converts one itself), a version that is not digits.digits, and a <world> (its 1.7-to-1.8
// conversion of a world's flattened models throws an exception of its own type on a joint whose
// <parent> lies outside, and reads through a null pointer on an <axis> without <xyz>; found by the
// robot_description fuzz target). A robot description is a <model>; a world holds none the sandbox
// would take anyway.
void CheckSdfformatCanReadIt(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream xml;
  xml << in.rdbuf();
  TiXmlDocument document;
  document.Parse(xml.str().c_str());
  if (document.Error()) {
    throw LevelError(file.string() + ":" + std::to_string(document.ErrorRow()) +
                     ": malformed XML: " + document.ErrorDesc());
  }
  bool sdf = false;
  std::vector<const TiXmlElement*> stack;
  for (const TiXmlElement* top = document.FirstChildElement(); top != nullptr;
       top = top->NextSiblingElement()) {
    const std::string name = top->Value();
    if (name == "robot") {
      throw LevelError(file.string() + ":" + std::to_string(top->Row()) +
                       ": a URDF <robot>, not SDF: name the file .urdf");
    }
    if (name == "sdf") {
      // ignition's version parser throws std::invalid_argument on "1.(".
      const char* version = top->Attribute("version");
      const std::string text = version != nullptr ? version : "";
      const std::size_t dot = text.find('.');
      const auto digits = [](const std::string& part) {
        return !part.empty() && part.size() <= 3 &&
               part.find_first_not_of("0123456789") == std::string::npos;
      };
      if (dot == std::string::npos || !digits(text.substr(0, dot)) ||
          !digits(text.substr(dot + 1))) {
        throw LevelError(file.string() + ":" + std::to_string(top->Row()) + ": <sdf version=\"" +
                         text + "\"> is not a version like 1.9");
      }
      sdf = true;
    }
    stack.push_back(top);
  }
  if (!sdf) throw LevelError(file.string() + ": not a valid SDF model: it has no <sdf> element");
  while (!stack.empty()) {
    const TiXmlElement* element = stack.back();
    stack.pop_back();
    if (std::string(element->Value()) == "world") {
      throw LevelError(file.string() + ":" + std::to_string(element->Row()) +
                       ": an SDF <world>; a robot description is a <model> file (give the "
                       "model's own .sdf)");
    }
    for (const TiXmlElement* child = element->FirstChildElement(); child != nullptr;
         child = child->NextSiblingElement()) {
      stack.push_back(child);
    }
  }
}

class SdfReader {
 public:
  explicit SdfReader(const fs::path& file) : file_(file) {}

  RobotDescription Read() {
    CheckSdfformatCanReadIt(file_);
    // sdformat's assertions throw sdf::Exception, which is no std::exception;
    // the libraries under it may throw standard ones.
    try {
      return ReadChecked();
    } catch (const LevelError&) {
      throw;
    } catch (const sdf::Exception& error) {
      throw LevelError(file_.string() + ": sdformat failed on it: " + error.GetErrorStr());
    } catch (const std::exception& error) {
      throw LevelError(file_.string() + ": sdformat failed on it: " + error.what());
    }
  }

 private:
  RobotDescription ReadChecked() {
    sdf::ParserConfig config;
    std::string unresolved;
    config.SetFindCallback([&](const std::string& uri) -> std::string {
      try {
        const fs::path found = ResolveResourceUri(uri, file_);
        CheckIncluded(found);
        return found.string();
      } catch (const LevelError& error) {
        if (unresolved.empty()) unresolved = error.what();
        return "";
      }
    });
    sdf::Console::Instance()->SetQuiet(true);  // its errors come back as values
    sdf::Root root;
    const sdf::Errors errors = root.Load(file_.string(), config);
    std::vector<std::string> fatal;
    std::map<std::string, int> harmless;  // by text, counted
    for (const sdf::Error& error : errors) {
      if (Harmless(error)) {
        if (harmless[ErrorText(error)]++ == 0) out_.warnings.push_back(ErrorText(error));
      } else {
        fatal.push_back(ErrorText(error));
      }
    }
    for (std::string& warning : out_.warnings) {
      if (const int times = harmless[warning]; times > 1) {
        warning += " (" + std::to_string(times) + " times)";
      }
    }
    if (!unresolved.empty()) throw LevelError(file_.string() + ": " + unresolved);
    if (!fatal.empty() || root.Model() == nullptr) {
      std::string text;
      for (const std::string& line : fatal) text += (text.empty() ? "" : "; ") + line;
      throw LevelError(file_.string() +
                       ": not a valid SDF model: " + (text.empty() ? "it holds no <model>" : text));
    }
    for (std::string& warning : out_.warnings) warning = file_.string() + ": " + warning;
    std::ifstream in(file_, std::ios::binary);
    std::stringstream xml;
    xml << in.rdbuf();
    WarnIgnoredElements(file_, xml.str(),
                        {{"inertial", "the sandbox does not simulate dynamics"},
                         {"plugin", "Gazebo plugins"},
                         {"sensor", "declare sensors in the manifest: [[robot.sensor]]"},
                         {"physics", "the sandbox does not simulate dynamics"},
                         {"surface", "contact is the external module's"},
                         {"dynamics", "the sandbox does not simulate dynamics"}},
                        &out_.warnings);
    const sdf::Model& model = *root.Model();
    out_.file = file_;
    out_.name = model.Name();
    Collect(model, "", Eigen::Isometry3d::Identity());
    Order(model);
    return std::move(out_);
  }

  // An <include>d model folder's SDF files (or the file named) get the same
  // check as the describing file: sdformat converts them the same way.
  static void CheckIncluded(const fs::path& found) {
    std::error_code error;
    if (!fs::is_directory(found, error)) {
      if (LowerExtension(found) == ".sdf") CheckSdfformatCanReadIt(found);
      return;
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(found, error)) {
      if (entry.is_regular_file(error) && LowerExtension(entry.path()) == ".sdf")
        CheckSdfformatCanReadIt(entry.path());
    }
  }

  struct Link {
    DescribedLink link;
    Eigen::Isometry3d X_ML;  // in the top model's frame
  };

  // The links and joints of `model` (and of its nested models, their names
  // prefixed), its frame at X_MN in the top model's.
  void Collect(const sdf::Model& model, const std::string& prefix, const Eigen::Isometry3d& X_MN) {
    for (std::uint64_t i = 0; i < model.LinkCount(); ++i) {
      const sdf::Link& link = *model.LinkByIndex(i);
      ignition::math::Pose3d pose;
      link.SemanticPose().Resolve(pose);
      Link out{{prefix + link.Name(), {}, {}}, X_MN * ToEigen(pose)};
      for (std::uint64_t v = 0; v < link.VisualCount(); ++v) {
        const sdf::Visual& visual = *link.VisualByIndex(v);
        ignition::math::Pose3d at;
        visual.SemanticPose().Resolve(at);
        if (auto geometry = Geometry(*visual.Geom(), at, out.link.name, "visual")) {
          if (const sdf::Material* material = visual.Material()) {
            const ignition::math::Color c = material->Diffuse();
            // A colour given (not the black default of a script-only material).
            if (c.R() > 0.f || c.G() > 0.f || c.B() > 0.f) {
              geometry->rgba = Eigen::Vector4f(c.R(), c.G(), c.B(), c.A());
            }
            geometry->material = material->ScriptName();
          }
          out.link.visuals.push_back(std::move(*geometry));
        }
      }
      for (std::uint64_t c = 0; c < link.CollisionCount(); ++c) {
        const sdf::Collision& collision = *link.CollisionByIndex(c);
        ignition::math::Pose3d at;
        collision.SemanticPose().Resolve(at);
        if (auto geometry = Geometry(*collision.Geom(), at, out.link.name, "collision")) {
          out.link.collisions.push_back(std::move(*geometry));
        }
      }
      if (!links_.emplace(out.link.name, std::move(out)).second) {
        throw LevelError(file_.string() + ": link '" + prefix + link.Name() + "' twice");
      }
    }
    for (std::uint64_t j = 0; j < model.JointCount(); ++j) {
      joints_.push_back({model.JointByIndex(j), prefix});
    }
    for (std::uint64_t m = 0; m < model.ModelCount(); ++m) {
      const sdf::Model& nested = *model.ModelByIndex(m);
      ignition::math::Pose3d pose;
      nested.SemanticPose().Resolve(pose);
      Collect(nested, prefix + nested.Name() + "::", X_MN * ToEigen(pose));
    }
  }

  std::optional<LinkGeometry> Geometry(const sdf::Geometry& geometry,
                                       const ignition::math::Pose3d& pose, const std::string& link,
                                       const char* what) {
    LinkGeometry out;
    out.X_LG = ToEigen(pose);
    const std::string where = file_.string() + ": link '" + link + "' " + what + ": ";
    auto positive = [&](double value, const char* name) {
      if (!(value > 0.0) || !std::isfinite(value)) {
        throw LevelError(where + name + " must be positive, got " + std::to_string(value));
      }
      return value;
    };
    switch (geometry.Type()) {
      case sdf::GeometryType::BOX: {
        const ignition::math::Vector3d size = geometry.BoxShape()->Size();
        out.kind = LinkGeometry::Kind::kBox;
        out.size = {positive(size.X(), "box size"), positive(size.Y(), "box size"),
                    positive(size.Z(), "box size")};
        return out;
      }
      case sdf::GeometryType::CYLINDER:
        out.kind = LinkGeometry::Kind::kCylinder;
        out.radius = positive(geometry.CylinderShape()->Radius(), "cylinder radius");
        out.length = positive(geometry.CylinderShape()->Length(), "cylinder length");
        return out;
      case sdf::GeometryType::SPHERE:
        out.kind = LinkGeometry::Kind::kSphere;
        out.radius = positive(geometry.SphereShape()->Radius(), "sphere radius");
        return out;
      case sdf::GeometryType::MESH: {
        const sdf::Mesh& mesh = *geometry.MeshShape();
        out.kind = LinkGeometry::Kind::kMesh;
        const fs::path from = mesh.FilePath().empty() ? file_ : fs::path(mesh.FilePath());
        try {
          out.mesh = ResolveResourceUri(mesh.Uri(), from);
        } catch (const LevelError& error) {
          throw LevelError(where + error.what());
        }
        out.scale = {mesh.Scale().X(), mesh.Scale().Y(), mesh.Scale().Z()};
        if (!out.scale.allFinite() || (out.scale.array() == 0.0).any()) {
          throw LevelError(where + "mesh scale must be finite and nonzero");
        }
        return out;
      }
      default:
        skipped_shapes_.insert(link);
        return std::nullopt;
    }
  }

  // Links in tree order from the root, joints with them.
  void Order(const sdf::Model& model) {
    std::map<std::string, std::vector<std::size_t>> children;  // parent link: joints
    std::set<std::string> has_parent;
    for (std::size_t j = 0; j < joints_.size(); ++j) {
      const sdf::Joint& joint = *joints_[j].joint;
      const std::string parent = Scoped(joint.ParentLinkName(), joints_[j].prefix);
      const std::string child = Scoped(joint.ChildLinkName(), joints_[j].prefix);
      if (parent == "world" || links_.count(parent) == 0 || links_.count(child) == 0) {
        out_.warnings.push_back(file_.string() + ": joint '" + joint.Name() + "' between '" +
                                parent + "' and '" + child + "' is left out (not two links)");
        continue;
      }
      if (!has_parent.insert(child).second) {
        throw LevelError(file_.string() + ": link '" + child + "' is the child of two joints");
      }
      children[parent].push_back(j);
    }
    std::string root = model.CanonicalLinkName();
    if (root.empty() || links_.count(root) == 0 || has_parent.count(root) > 0) {
      root.clear();
      for (const auto& [name, link] : links_) {
        if (has_parent.count(name) == 0) {
          root = name;
          break;
        }
      }
    }
    if (root.empty()) throw LevelError(file_.string() + ": every link has a parent (a joint loop)");
    std::map<std::string, int> index_of;
    std::vector<std::pair<std::string, std::size_t>> stack{{root, SIZE_MAX}};
    while (!stack.empty()) {
      const auto [name, via] = stack.back();
      stack.pop_back();
      if (!index_of.emplace(name, int(out_.links.size())).second) {
        throw LevelError(file_.string() + ": link '" + name + "' is reached twice (a joint loop)");
      }
      out_.links.push_back(links_.at(name).link);
      if (via != SIZE_MAX)
        out_.joints.push_back(Joint(*joints_[via].joint, joints_[via].prefix, index_of));
      std::vector<std::size_t> next = children[name];
      std::sort(next.begin(), next.end(), [&](std::size_t a, std::size_t b) {
        return joints_[a].joint->Name() > joints_[b].joint->Name();
      });
      for (const std::size_t j : next)
        stack.emplace_back(Scoped(joints_[j].joint->ChildLinkName(), joints_[j].prefix), j);
    }
    // Links no joint reaches stay where the model puts them, fixed to the root.
    for (const auto& [name, link] : links_) {
      if (index_of.count(name) > 0) continue;
      out_.warnings.push_back(file_.string() + ": link '" + name +
                              "' has no joint to the others; it is fixed to '" + root + "'");
      index_of[name] = int(out_.links.size());
      out_.links.push_back(link.link);
      DescribedJoint fixed;
      fixed.name = name + "_fixed";
      fixed.parent = 0;
      fixed.child = index_of[name];
      fixed.X_PC = links_.at(root).X_ML.inverse() * link.X_ML;
      out_.joints.push_back(fixed);
    }
    for (const std::string& link : skipped_shapes_) {
      out_.warnings.push_back(file_.string() + ": link '" + link +
                              "': shapes other than box, cylinder, sphere and mesh are left out");
    }
  }

  static std::string Scoped(const std::string& name, const std::string& prefix) {
    return name == "world" ? name : prefix + name;
  }

  DescribedJoint Joint(const sdf::Joint& joint, const std::string& prefix,
                       const std::map<std::string, int>& index_of) {
    DescribedJoint out;
    out.name = prefix + joint.Name();
    const std::string parent = Scoped(joint.ParentLinkName(), prefix);
    const std::string child = Scoped(joint.ChildLinkName(), prefix);
    out.parent = index_of.at(parent);
    out.child = index_of.at(child);
    out.X_PC = links_.at(parent).X_ML.inverse() * links_.at(child).X_ML;
    const std::string at = file_.string() + ": joint '" + out.name + "': ";
    switch (joint.Type()) {
      case sdf::JointType::REVOLUTE:
        out.type = DescribedJoint::Type::kRevolute;
        break;
      case sdf::JointType::CONTINUOUS:
        out.type = DescribedJoint::Type::kContinuous;
        break;
      case sdf::JointType::PRISMATIC:
        out.type = DescribedJoint::Type::kPrismatic;
        break;
      case sdf::JointType::FIXED:
        out.type = DescribedJoint::Type::kFixed;
        break;
      default:
        out_.warnings.push_back(at + "a ball, universal, screw or gearbox joint is held fixed");
        out.type = DescribedJoint::Type::kFixed;
    }
    if (!out.moves()) return out;
    // The joint frame J in the child's: the axis passes through its origin.
    ignition::math::Pose3d pose;
    joint.SemanticPose().Resolve(pose, joint.ChildLinkName());
    const Eigen::Isometry3d X_CJ = ToEigen(pose);
    const sdf::JointAxis* axis = joint.Axis(0);
    if (axis == nullptr) throw LevelError(at + "no <axis>");
    ignition::math::Vector3d xyz = axis->Xyz();
    axis->ResolveXyz(xyz);  // in the joint frame (as given when it cannot resolve)
    out.axis = X_CJ.linear() * Eigen::Vector3d(xyz.X(), xyz.Y(), xyz.Z());
    if (!out.axis.allFinite() || out.axis.norm() < 1e-9) throw LevelError(at + "zero <axis>");
    out.axis.normalize();
    out.pivot = X_CJ.translation();
    if (out.type != DescribedJoint::Type::kContinuous) {
      out.lower = Limit(axis->Lower()), out.upper = Limit(axis->Upper());
      if (!(out.lower <= out.upper)) {
        throw LevelError(at + "<limit> lower " + std::to_string(out.lower) + " is above upper " +
                         std::to_string(out.upper));
      }
    }
    return out;
  }

  struct JointAt {
    const sdf::Joint* joint;
    std::string prefix;  // its model's, for its link names
  };

  const fs::path file_;
  RobotDescription out_;
  std::map<std::string, Link> links_;
  std::vector<JointAt> joints_;
  std::set<std::string> skipped_shapes_;
};

}  // namespace

RobotDescription ReadSdf(const fs::path& file) { return SdfReader(file).Read(); }

}  // namespace sandbox::scene
