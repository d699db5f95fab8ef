#pragma once
// A robot description file (URDF read with urdfdom, SDF with sdformat) as
// links and joints: what the robot model is built from (robot_model.h).
// Scene-internal.
//
// Read: links with their visual and collision geometry (meshes by URI, boxes,
// cylinders, spheres) and material colours; joints (revolute, continuous,
// prismatic, fixed) with origins, axes and limits; SDF <include>d models.
// Ignored, with one warning per kind of element found: inertia, dynamics,
// transmissions, Gazebo extensions and plugins, SDF sensors, ...

#include <Eigen/Geometry>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sandbox::scene {

// Whether `file` is a robot description by its extension (.urdf, .sdf).
bool IsRobotDescription(const std::filesystem::path& file);

// One visual or collision shape of a link, in the link's frame.
struct LinkGeometry {
  enum class Kind { kMesh, kBox, kCylinder, kSphere };
  Kind kind{Kind::kBox};
  Eigen::Isometry3d X_LG{Eigen::Isometry3d::Identity()};  // the shape in the link frame
  std::filesystem::path mesh;                             // kMesh: the resolved file
  Eigen::Vector3d scale{1.0, 1.0, 1.0};                   // kMesh
  Eigen::Vector3d size{0.0, 0.0, 0.0};                    // kBox: edge lengths
  double radius{0.0};                                     // kCylinder (along z), kSphere
  double length{0.0};                                     // kCylinder
  std::optional<Eigen::Vector4f> rgba;                    // a material colour, when given
  std::string material;                                   // its name, when given
};

struct DescribedLink {
  std::string name;
  std::vector<LinkGeometry> visuals, collisions;
};

struct DescribedJoint {
  enum class Type { kFixed, kRevolute, kContinuous, kPrismatic };
  std::string name;
  Type type{Type::kFixed};
  int parent{-1}, child{-1};  // indices into RobotDescription::links
  // The child link's frame in the parent's at joint value 0; the joint moves
  // the child about (revolute) or along (prismatic) `axis`, a unit vector in
  // the child's frame, through the child's point `pivot` (URDF: its origin;
  // SDF: the joint frame's).
  Eigen::Isometry3d X_PC{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d axis{1.0, 0.0, 0.0};
  Eigen::Vector3d pivot{0.0, 0.0, 0.0};
  double lower{-std::numeric_limits<double>::infinity()};  // radians or metres
  double upper{std::numeric_limits<double>::infinity()};
  bool moves() const { return type != Type::kFixed; }
};

struct RobotDescription {
  std::filesystem::path file;
  std::string name;
  std::vector<DescribedLink> links;    // the root first, parents before children
  std::vector<DescribedJoint> joints;  // depth first from the root (siblings by name)
  std::vector<std::string> warnings;   // elements read past, one line per kind
};

// Reads a URDF or SDF file (by its extension). Mesh URIs (and SDF includes)
// are resolved by ResolveResourceUri. Throws LevelError naming the file (and
// the element) for malformed XML, a duplicate link, a joint loop or a second
// root, an unresolved URI (listing the paths searched), limits lower > upper.
RobotDescription ReadRobotDescription(const std::filesystem::path& file);
RobotDescription ReadUrdf(const std::filesystem::path& file);
RobotDescription ReadSdf(const std::filesystem::path& file);  // sdf_description.cc

// One warning per kind of `ignored` element (name: why) found in `xml`.
void WarnIgnoredElements(const std::filesystem::path& file, const std::string& xml,
                         const std::vector<std::pair<std::string, std::string>>& ignored,
                         std::vector<std::string>* warnings);

// Where `uri` (package://NAME/..., model://NAME/..., file://..., or a path
// relative to the describing file) is, given the file that names it. A
// package or model NAME is looked for in order: the file's folder and each of
// its parents (a folder called NAME, or one holding a package.xml whose
// <name> is NAME), then each folder of SANDBOX_RESOURCE_PATH, then of
// ROS_PACKAGE_PATH (package://) or GZ_SIM_RESOURCE_PATH (model://).
// Throws LevelError naming the URI and every place searched when not found.
std::filesystem::path ResolveResourceUri(const std::string& uri,
                                         const std::filesystem::path& describing_file);

}  // namespace sandbox::scene
