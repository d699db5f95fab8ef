// Robots from URDF: links and joints as read, forward kinematics against
// kinematics computed here from the file's own XML (read with TinyXML, not
// urdfdom), limits, the collision body, and bad descriptions.

#include <gtest/gtest.h>
#include <tinyxml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

#ifdef SANDBOX_HAVE_KDL
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#endif

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;
using Eigen::Isometry3d;
using Eigen::Vector3d;

fs::path BundledArm() { return fs::path(SANDBOX_SOURCE_DIR) / "assets/arm/arm.urdf"; }
fs::path Kuka() { return fs::path(SANDBOX_SHARED_ASSETS) / "kuka-iiwa/lbr_iiwa_14_r820.urdf"; }

// A joint as the XML gives it.
struct XmlJoint {
  std::string name, type, parent, child;
  Isometry3d origin{Isometry3d::Identity()};
  Vector3d axis{1, 0, 0};
  double lower{-M_PI}, upper{M_PI};
};

Vector3d Triple(const TiXmlElement* element, const char* attribute, const Vector3d& otherwise) {
  const char* text = element != nullptr ? element->Attribute(attribute) : nullptr;
  if (text == nullptr) return otherwise;
  std::istringstream in(text);
  Vector3d v;
  in >> v.x() >> v.y() >> v.z();
  return v;
}

// URDF: origin = translation(xyz) * Rz(yaw) * Ry(pitch) * Rx(roll).
std::map<std::string, XmlJoint> ReadJoints(const fs::path& file) {
  TiXmlDocument document;
  EXPECT_TRUE(document.LoadFile(file.string()));
  std::map<std::string, XmlJoint> joints;  // by child link
  for (const TiXmlElement* j = document.RootElement()->FirstChildElement("joint"); j != nullptr;
       j = j->NextSiblingElement("joint")) {
    XmlJoint joint;
    joint.name = j->Attribute("name");
    joint.type = j->Attribute("type");
    joint.parent = j->FirstChildElement("parent")->Attribute("link");
    joint.child = j->FirstChildElement("child")->Attribute("link");
    const TiXmlElement* origin = j->FirstChildElement("origin");
    const Vector3d xyz = Triple(origin, "xyz", Vector3d::Zero());
    const Vector3d rpy = Triple(origin, "rpy", Vector3d::Zero());
    joint.origin = Eigen::Translation3d(xyz) * Eigen::AngleAxisd(rpy.z(), Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy.y(), Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy.x(), Vector3d::UnitX());
    joint.axis = Triple(j->FirstChildElement("axis"), "xyz", Vector3d::UnitX()).normalized();
    if (const TiXmlElement* limit = j->FirstChildElement("limit")) {
      limit->QueryDoubleAttribute("lower", &joint.lower);
      limit->QueryDoubleAttribute("upper", &joint.upper);
    }
    joints[joint.child] = joint;
  }
  return joints;
}

// The pose of `link` in the robot frame for joint values by joint name.
Isometry3d LinkPose(const std::map<std::string, XmlJoint>& joints, const std::string& link,
                    const std::map<std::string, double>& q) {
  const auto joint = joints.find(link);
  if (joint == joints.end()) return Isometry3d::Identity();  // the root
  const XmlJoint& j = joint->second;
  Isometry3d motion = Isometry3d::Identity();
  const double value = q.count(j.name) > 0 ? q.at(j.name) : 0.0;
  if (j.type == "prismatic") {
    motion = Eigen::Translation3d(value * j.axis);
  } else if (j.type != "fixed") {
    motion = Eigen::AngleAxisd(value, j.axis);
  }
  return LinkPose(joints, j.parent, q) * j.origin * motion;
}

// Sets ten random joint vectors within the limits and compares every link's
// pose with the independent kinematics.
void ExpectKinematicsAgree(const fs::path& file) {
  const Level level = LoadLevel(file);
  ASSERT_EQ(level.robots.size(), 1u);
  const RobotModel& model = level.robots[0];
  const std::map<std::string, XmlJoint> joints = ReadJoints(file);
  RobotState state(model);
  std::mt19937 random(7);
  for (int trial = 0; trial < 10; ++trial) {
    std::map<std::string, double> q;
    for (std::size_t b = 0; b < model.bones.size(); ++b) {
      const XmlJoint& j = joints.at(model.nodes[std::size_t(model.bones[b].node)].name);
      ASSERT_EQ(j.name, model.bones[b].name);
      const double lower = j.type == "continuous" ? -6.0 : j.lower;
      const double upper = j.type == "continuous" ? 6.0 : j.upper;
      q[j.name] = std::uniform_real_distribution<double>(lower, upper)(random);
      ASSERT_TRUE(state.SetBone(int(b), &q[j.name], 1)) << state.last_rejection();
    }
    state.Update();
    for (std::size_t n = 0; n < model.nodes.size(); ++n) {
      const Isometry3d expected = LinkPose(joints, model.nodes[n].name, q);
      const Eigen::Affine3d& got = state.node_poses_B()[n];
      EXPECT_LT((got.translation() - expected.translation()).norm(), 1e-9)
          << model.nodes[n].name << " trial " << trial;
      EXPECT_LT((got.linear() - expected.linear()).norm(), 1e-9) << model.nodes[n].name;
    }
  }
}

TEST(RobotDescriptionTest, BundledArmReadsLinksJointsLimitsAndIgnoredElements) {
  const Level level = LoadLevel(BundledArm());
  ASSERT_EQ(level.robots.size(), 1u);
  const RobotModel& arm = level.robots[0];
  EXPECT_TRUE(arm.described);
  EXPECT_EQ(arm.name, "arm");
  ASSERT_EQ(arm.nodes.size(), 7u);
  EXPECT_EQ(arm.nodes[0].name, "base");
  EXPECT_EQ(arm.nodes[0].parent, -1);
  const std::map<std::string, XmlJoint> joints = ReadJoints(BundledArm());
  ASSERT_EQ(arm.bones.size(), 5u);  // six joints, one fixed
  for (const Bone& bone : arm.bones) {
    const XmlJoint& j = joints.at(arm.nodes[std::size_t(bone.node)].name);
    EXPECT_EQ(bone.name, j.name);
    EXPECT_EQ(arm.nodes[std::size_t(arm.nodes[std::size_t(bone.node)].parent)].name, j.parent);
    EXPECT_LT((bone.axes[0] - j.axis).norm(), 1e-12);
    EXPECT_EQ(bone.rotation, j.type == "prismatic" ? BoneRotation::kSlide : BoneRotation::kAngles);
    if (j.type == "continuous") {
      EXPECT_TRUE(std::isinf(bone.lower) && std::isinf(bone.upper));
    } else {
      EXPECT_EQ(bone.lower, j.lower);
      EXPECT_EQ(bone.upper, j.upper);
    }
  }
  // Drawn: every link's visual; rays: the collision shapes (the flange has none).
  EXPECT_EQ(arm.meshes.size(), 7u);
  EXPECT_EQ(arm.collision_meshes.size(), 6u);
  int inertial = 0;
  for (const std::string& warning : level.warnings) {
    inertial += warning.find("ignored 1 <inertial> element") != std::string::npos;
  }
  EXPECT_EQ(inertial, 1);
}

TEST(RobotDescriptionTest, BundledArmKinematicsAgreeWithItsXml) {
  ExpectKinematicsAgree(BundledArm());
}

TEST(RobotDescriptionTest, KukaKinematicsAgreeWithItsXml) {
  if (!fs::exists(Kuka())) GTEST_SKIP() << "no " << Kuka();
  const Level level = LoadLevel(Kuka());
  EXPECT_EQ(level.robots.at(0).nodes.size(), 10u);  // urdfdom: 10 links, 9 joints
  EXPECT_EQ(level.robots.at(0).bones.size(), 7u);
  ExpectKinematicsAgree(Kuka());
}

#ifdef SANDBOX_HAVE_KDL
// Orocos KDL's forward kinematics of the chain from the root to `tip`, built
// from the XML as kdl_parser does: each joint about origin.R * axis through
// origin.p, the segment's tip at the origin.
Isometry3d KdlPose(const std::map<std::string, XmlJoint>& joints, const std::string& tip,
                   const std::map<std::string, double>& q) {
  std::vector<const XmlJoint*> path;  // tip to root, then reversed
  for (auto j = joints.find(tip); j != joints.end(); j = joints.find(j->second.parent)) {
    path.push_back(&j->second);
  }
  std::reverse(path.begin(), path.end());
  KDL::Chain chain;
  KDL::JntArray values(0);
  std::vector<double> moving;
  for (const XmlJoint* j : path) {
    const Eigen::Matrix3d R = j->origin.linear();
    const Vector3d p = j->origin.translation(), axis = R * j->axis;
    const KDL::Frame origin(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2),
                                          R(2, 0), R(2, 1), R(2, 2)),
                            KDL::Vector(p.x(), p.y(), p.z()));
    const KDL::Joint::JointType type = j->type == "fixed"       ? KDL::Joint::None
                                       : j->type == "prismatic" ? KDL::Joint::TransAxis
                                                                : KDL::Joint::RotAxis;
    const KDL::Joint joint =
        type == KDL::Joint::None
            ? KDL::Joint(j->name, KDL::Joint::None)
            : KDL::Joint(j->name, origin.p, KDL::Vector(axis.x(), axis.y(), axis.z()), type);
    chain.addSegment(KDL::Segment(j->child, joint, origin));
    if (type != KDL::Joint::None) moving.push_back(q.count(j->name) > 0 ? q.at(j->name) : 0.0);
  }
  values.resize(unsigned(moving.size()));
  for (std::size_t i = 0; i < moving.size(); ++i) values(unsigned(i)) = moving[i];
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::Frame out;
  EXPECT_GE(fk.JntToCart(values, out), 0);
  Isometry3d X = Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    X.translation()[r] = out.p[r];
    for (int c = 0; c < 3; ++c) X.linear()(r, c) = out.M(r, c);
  }
  return X;
}

TEST(RobotDescriptionTest, TipPosesAgreeWithOrocosKdl) {
  std::vector<std::pair<fs::path, std::string>> robots = {{BundledArm(), "flange"}};
  if (fs::exists(Kuka())) robots.emplace_back(Kuka(), "tool0");
  for (const auto& [file, tip] : robots) {
    const Level level = LoadLevel(file);
    const RobotModel& model = level.robots.at(0);
    const std::map<std::string, XmlJoint> joints = ReadJoints(file);
    RobotState state(model);
    std::mt19937 random(11);
    for (int trial = 0; trial < 10; ++trial) {
      std::map<std::string, double> q;
      for (std::size_t b = 0; b < model.bones.size(); ++b) {
        const XmlJoint& j = joints.at(model.nodes[std::size_t(model.bones[b].node)].name);
        const double lower = j.type == "continuous" ? -6.0 : j.lower;
        const double upper = j.type == "continuous" ? 6.0 : j.upper;
        q[j.name] = std::uniform_real_distribution<double>(lower, upper)(random);
        ASSERT_TRUE(state.SetBone(int(b), &q[j.name], 1));
      }
      state.UpdateKinematics();
      const Isometry3d kdl = KdlPose(joints, tip, q);
      const Eigen::Affine3d& ours = state.node_poses_B()[std::size_t(model.FindNode(tip))];
      EXPECT_LT((ours.translation() - kdl.translation()).norm(), 1e-9) << file << " " << trial;
      EXPECT_LT((ours.linear() - kdl.linear()).norm(), 1e-9) << file << " " << trial;
    }
  }
}
#endif

TEST(RobotDescriptionTest, ValuesBeyondLimitsAreRejectedAndCountedNeverClamped) {
  const Level level = LoadLevel(BundledArm());
  const RobotModel& arm = level.robots[0];
  RobotState state(arm);
  const int shoulder = arm.FindBone("shoulder"), extend = arm.FindBone("extend");
  const int yaw = arm.FindBone("base_yaw");
  const double good = 0.5, over = 1.5000001, nan = std::nan(""), slide = 0.2, turns = 20.0;
  EXPECT_TRUE(state.SetBone(shoulder, &good, 1));
  EXPECT_FALSE(state.SetBone(shoulder, &over, 1));
  EXPECT_FALSE(state.SetBone(shoulder, &nan, 1));
  EXPECT_FALSE(state.SetBone(extend, &slide, 1));
  EXPECT_TRUE(state.SetBone(yaw, &turns, 1));  // continuous: no limits
  EXPECT_EQ(state.rejected().at("joint value beyond its limits"), 2);
  EXPECT_EQ(state.rejected().at("non-finite bone value"), 1);
  EXPECT_EQ(state.bone_values()[std::size_t(arm.bones[std::size_t(shoulder)].first_value)], good);
}

TEST(RobotDescriptionTest, CollisionBodyFollowsTheLinksCollisionShapes) {
  const Level level = LoadLevel(BundledArm());
  const RobotModel& arm = level.robots[0];
  CollisionWorld world(level);
  RobotState state(arm);
  // The forearm level (0.4 - 0.3 - 0.1 about y), so that the wrist's sphere
  // is the highest thing over its centre.
  const std::map<std::string, double> q = {
      {"base_yaw", 0.7}, {"shoulder", 0.4}, {"elbow", -0.1}, {"extend", 0.1}, {"wrist_roll", 1.0}};
  for (const auto& [name, value] : q) ASSERT_TRUE(state.SetBone(arm.FindBone(name), &value, 1));
  state.Update();
  world.UpdateRobot(0, state);
  // Straight down onto the wrist's sphere (radius 0.04) from 1 m above its centre.
  const Vector3d centre = LinkPose(ReadJoints(BundledArm()), "wrist", q).translation();
  const auto hit = world.CastRay(centre + Vector3d(0, 0, 1), centre);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->robot, 0);
  // The sphere's polygon lies inside the radius by at most 1 - cos(pi / 16).
  EXPECT_NEAR(hit->distance_m, 1.0 - 0.04, 0.04 * (1.0 - std::cos(M_PI / 16)) + 1e-6);
  // The flange (a disc from x = 0 to 0.02 of its frame, where the wrist's
  // sphere ends) has no collision shape: a ray into it finds nothing.
  const Isometry3d flange = LinkPose(ReadJoints(BundledArm()), "flange", q);
  EXPECT_FALSE(world.CastRay(flange * Vector3d(0.5, 0, 0), flange * Vector3d(0.015, 0, 0)));
  EXPECT_TRUE(world.CastRay(flange * Vector3d(0.5, 0, 0), flange * Vector3d(-0.01, 0, 0)));
}

// A grid of rays from beside the posed arm sees the robot's collision body
// where it sees the same shapes placed as actors by the kinematics computed
// here from the XML.
TEST(RobotDescriptionTest, ScanOfThePosedArmMatchesItsShapesPlacedByIndependentKinematics) {
  const Level level = LoadLevel(BundledArm());
  const RobotModel& arm = level.robots[0];
  const std::map<std::string, XmlJoint> joints = ReadJoints(BundledArm());
  const std::map<std::string, double> q = {
      {"base_yaw", -0.6}, {"shoulder", 0.7}, {"elbow", 1.1}, {"extend", 0.12}, {"wrist_roll", -2}};
  const Isometry3d X_WB =
      Eigen::Translation3d(0.3, -0.2, 0.1) * Eigen::AngleAxisd(0.4, Vector3d::UnitZ());
  RobotState state(arm);
  ASSERT_TRUE(state.SetPose(X_WB));
  for (const auto& [name, value] : q) ASSERT_TRUE(state.SetBone(arm.FindBone(name), &value, 1));
  state.UpdateKinematics();
  CollisionWorld robot_world(level);
  robot_world.UpdateRobot(0, state);
  // The same shapes (the collision meshes, in their links' frames) as actors.
  Level placed;
  for (const SkinnedMesh& mesh : arm.collision_meshes) {
    const std::string& link = arm.nodes[std::size_t(arm.joints[mesh.influence_joint[0]].node)].name;
    Actor actor;
    actor.name = link + std::to_string(placed.actors.size());
    actor.X_WA = X_WB * LinkPose(joints, link, q);
    actor.meshes.push_back(mesh.bind);
    actor.bounds_W.setEmpty();
    for (const Eigen::Vector3f& p : mesh.bind.positions_A) {
      actor.bounds_W.extend(actor.X_WA * p.cast<double>());
    }
    placed.actors.push_back(std::move(actor));
  }
  CollisionWorld actor_world(placed);
  // 81 x 81 rays along -x from x = 2, over y, z in [-1, 1] x [0, 2] about the base.
  int hits = 0;
  for (int r = 0; r <= 80; ++r) {
    for (int c = 0; c <= 80; ++c) {
      const Vector3d from(2.0, -1.0 + c / 40.0, r / 40.0), to(-2.0, from.y(), from.z());
      const auto a = robot_world.CastRay(from, to), b = actor_world.CastRay(from, to);
      ASSERT_EQ(a.has_value(), b.has_value()) << r << " " << c;
      if (!a) continue;
      ++hits;
      EXPECT_NEAR(a->distance_m, b->distance_m, 1e-5) << r << " " << c;
    }
  }
  EXPECT_GT(hits, 100);  // the arm, 5 to 30 cm thick, crosses the 2.5 cm grid
}

// A bad description: the error names the file and what is wrong.
void ExpectRefused(const std::string& xml, const std::vector<std::string>& parts,
                   const std::string& name = "bad.urdf") {
  const testing::TempDir dir;
  const fs::path file = dir.Write(name, xml);
  try {
    LoadLevel(file);
    ADD_FAILURE() << "loaded: " << xml;
  } catch (const LevelError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

std::string Robot(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n" + body + "</robot>\n";
}
const std::string kBox = "<visual><geometry><box size=\"1 1 1\"/></geometry></visual>";

TEST(RobotDescriptionTest, BadDescriptionsAreRefusedNamingFileAndElement) {
  ExpectRefused("<robot name=\"r\">\n<link name=\"a\">\n</robot>", {":3: malformed XML"});
  ExpectRefused(Robot("<link name=\"a\">" + kBox + "</link><link name=\"a\">" + kBox + "</link>"),
                {"not a valid URDF", "a"});
  ExpectRefused(Robot("<link name=\"a\">" + kBox + "</link><link name=\"b\">" + kBox +
                      "</link><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child "
                      "link=\"b\"/></joint><joint name=\"k\" type=\"fixed\"><parent "
                      "link=\"b\"/><child link=\"a\"/></joint>"),
                {"the joints form a loop through link", "(joint '"});
  ExpectRefused(Robot("<link name=\"a\">" + kBox + "</link><link name=\"b\">" + kBox +
                      "</link><link name=\"c\">" + kBox +
                      "</link><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child "
                      "link=\"c\"/></joint><joint name=\"k\" type=\"fixed\"><parent "
                      "link=\"b\"/><child link=\"c\"/></joint>"),
                {"link 'c' is the child of two joints ('j', 'k')"});
  ExpectRefused(Robot("<link name=\"a\">" + kBox + "</link><link name=\"b\">" + kBox +
                      "</link><joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child "
                      "link=\"b\"/><limit lower=\"1\" upper=\"-1\" effort=\"1\" "
                      "velocity=\"1\"/></joint>"),
                {"joint 'j'", "lower 1", "above upper"});
  ExpectRefused(
      Robot("<link name=\"a\"><visual><geometry><mesh "
            "filename=\"package://no_such_package/m.stl\"/></geometry></visual></link>"),
      {"link 'a' visual", "package://no_such_package/m.stl", "searched", "no_such_package"});
  ExpectRefused(Robot("<link name=\"a\"><visual><geometry><mesh "
                      "filename=\"meshes/missing.stl\"/></geometry></visual></link>"),
                {"link 'a' visual", "meshes/missing.stl", "not found"});
  ExpectRefused(Robot("<link name=\"a\"><visual><geometry><box size=\"1 0 1\"/>"
                      "</geometry></visual></link>"),
                {"link 'a' visual", "box size must be positive"});
  ExpectRefused(Robot("<link name=\"a\"/>"), {"no link has geometry"});
}

TEST(RobotDescriptionTest, PackageUrisResolveByFolderNameOrPackageXml) {
  const testing::TempDir dir;
  // A package folder named otherwise, found by its package.xml beside the robot.
  dir.Write("ws/src/arm_pkg/package.xml", "<package><name>my_arm</name></package>");
  const std::string stl_text =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid t\n";
  dir.Write("ws/src/arm_pkg/meshes/part.stl", stl_text);
  const fs::path file = dir.Write(
      "ws/src/arm_pkg/urdf/r.urdf",
      Robot("<link name=\"a\"><visual><geometry><mesh "
            "filename=\"package://my_arm/meshes/part.stl\"/></geometry></visual></link>"));
  const Level level = LoadLevel(file);
  EXPECT_EQ(level.robots.at(0).num_triangles(), 1u);
  // Elsewhere, by SANDBOX_RESOURCE_PATH: a folder called after the package.
  dir.Write("elsewhere/other_pkg/m.stl", stl_text);
  const fs::path other = dir.Write(
      "r2.urdf", Robot("<link name=\"a\"><visual><geometry><mesh "
                       "filename=\"package://other_pkg/m.stl\"/></geometry></visual></link>"));
  EXPECT_THROW(LoadLevel(other), LevelError);
  ::setenv("SANDBOX_RESOURCE_PATH", (dir.path() / "elsewhere").c_str(), 1);
  EXPECT_EQ(LoadLevel(other).robots.at(0).num_triangles(), 1u);
  ::unsetenv("SANDBOX_RESOURCE_PATH");
}

TEST(RobotDescriptionTest, ManifestPlacesADescriptionAndMountsSensorsOnLinks) {
  const testing::TempDir dir;
  const std::string arm = BundledArm().string();
  const fs::path manifest =
      dir.Write("level.toml", "[[robot]]\nname = \"left\"\ndescription = \"" + arm +
                                  "\"\nposition = [1, 2, 0]\n"
                                  "[[robot.sensor]]\nname = \"probe\"\n"
                                  "type = \"ray\"\nmount = \"wrist\"\n");
  const Level level = LoadLevel(manifest);
  const RobotModel& left = level.robots.at(0);
  EXPECT_EQ(left.name, "left");
  EXPECT_EQ(left.X_WB_spawn.translation(), Vector3d(1, 2, 0));
  EXPECT_EQ(left.sensors.at(0).mount_node, left.FindNode("wrist"));
  // 'description' takes descriptions only; a mount must be a link.
  const fs::path gltf =
      dir.Write("bad.toml", "[[robot]]\nname = \"r\"\ndescription = \"x.gltf\"\n");
  EXPECT_THROW(LoadLevel(gltf), LevelError);
  const fs::path mount = dir.Write("mount.toml", "[[robot]]\nname = \"r\"\ndescription = \"" + arm +
                                                     "\"\n[[robot.sensor]]\nname = \"p\"\n"
                                                     "type = \"ray\"\nmount = \"elbow\"\n");
  try {
    LoadLevel(mount);
    ADD_FAILURE() << "mount on a joint's name loaded";
  } catch (const LevelError& error) {
    EXPECT_NE(std::string(error.what()).find("mount 'elbow' is not a node"), std::string::npos)
        << error.what();
  }
}

fs::path Px4(const std::string& model) {
  return fs::path(SANDBOX_SHARED_ASSETS) / "px4-sitl-models/models" / model / (model + ".sdf");
}

// The pose of node `name` at the model's bone values after `values` (by bone name).
Isometry3d NodePose(const RobotModel& model, const std::string& name,
                    const std::map<std::string, double>& values) {
  RobotState state(model);
  for (const auto& [bone, value] : values) {
    EXPECT_TRUE(state.SetBone(model.FindBone(bone), &value, 1)) << bone;
  }
  state.Update();
  const int node = model.FindNode(name);
  EXPECT_GE(node, 0) << name;
  return Isometry3d(state.node_poses_B()[std::size_t(node)].matrix());
}

TEST(RobotDescriptionTest, Px4PlaneControlSurfacesTurnAboutTheAxesTheSdfGives) {
  if (!fs::exists(Px4("plane"))) GTEST_SKIP() << "no " << Px4("plane");
  const Level level = LoadLevel(Px4("plane"));
  const RobotModel& plane = level.robots.at(0);
  EXPECT_EQ(plane.links.size(), 11u);  // 9 links and the included gps and airspeed
  EXPECT_EQ(plane.bones.size(), 8u);   // 10 joints, two of them fixed
  TiXmlDocument document;
  ASSERT_TRUE(document.LoadFile(Px4("plane").string()));
  int checked = 0;
  for (const TiXmlElement* j =
           document.RootElement()->FirstChildElement("model")->FirstChildElement("joint");
       j != nullptr; j = j->NextSiblingElement("joint")) {
    const std::string name = j->Attribute("name");
    if (name.find("elevon") == std::string::npos && name.find("flap") == std::string::npos &&
        name != "elevator_joint" && name != "rudder_joint") {
      continue;
    }
    // These children sit at the model origin with no rotation, and their joint
    // frames have none: the hinge is the joint's <pose> point along <axis><xyz>.
    std::istringstream pose(j->FirstChildElement("pose")->GetText());
    Vector3d pivot;
    pose >> pivot.x() >> pivot.y() >> pivot.z();
    std::istringstream xyz(j->FirstChildElement("axis")->FirstChildElement("xyz")->GetText());
    Vector3d axis;
    xyz >> axis.x() >> axis.y() >> axis.z();
    const std::string child = j->FirstChildElement("child")->GetText();
    const double q = 0.3;
    const Isometry3d expected(Eigen::Translation3d(pivot) *
                              Eigen::AngleAxisd(q, axis.normalized()) *
                              Eigen::Translation3d(-pivot));
    const Isometry3d got = NodePose(plane, child, {{name, q}});
    EXPECT_LT((got.matrix() - expected.matrix()).norm(), 1e-9) << name;
    ++checked;
  }
  EXPECT_EQ(checked, 6);  // two elevons, two flaps, the elevator and the rudder
}

TEST(RobotDescriptionTest, Px4IrisHasFourContinuousRotors) {
  if (!fs::exists(Px4("iris"))) GTEST_SKIP() << "no " << Px4("iris");
  const RobotModel iris = LoadLevel(Px4("iris")).robots.at(0);
  int rotors = 0;
  for (const Bone& bone : iris.bones) {
    if (bone.name.rfind("rotor_", 0) != 0) continue;
    ++rotors;
    EXPECT_TRUE(std::isinf(bone.lower) && std::isinf(bone.upper)) << bone.name;
    EXPECT_NEAR(std::abs(bone.axes[0].z()), 1.0, 1e-9) << bone.name;
  }
  EXPECT_EQ(rotors, 4);
}

// An SDF joint whose frame is rotated and off its child's origin, against
// the SDF rule computed here: X_PC(q) = X_PC(0) * X_CJ * R(axis_J, q) * X_CJ^-1.
TEST(RobotDescriptionTest, SdfJointFramesOffTheChildOriginTurnAboutTheirOwnAxis) {
  const testing::TempDir dir;
  const fs::path file = dir.Write("m.sdf", R"(<?xml version="1.0"?>
<sdf version="1.7">
  <model name="m">
    <link name="a"><visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link>
    <link name="b">
      <pose>1 2 3 0.1 0.2 0.3</pose>
      <visual name="v"><geometry><sphere><radius>0.5</radius></sphere></geometry></visual>
    </link>
    <joint name="j" type="revolute">
      <parent>a</parent><child>b</child>
      <pose>0.4 -0.2 0.1 0.5 0 -0.4</pose>
      <axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis>
    </joint>
  </model>
</sdf>
)");
  const RobotModel m = LoadLevel(file).robots.at(0);
  auto rpy = [](double r, double p, double y) {
    return Isometry3d(Eigen::AngleAxisd(y, Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(p, Vector3d::UnitY()) *
                      Eigen::AngleAxisd(r, Vector3d::UnitX()));
  };
  const Isometry3d X_AB = Eigen::Translation3d(1, 2, 3) * rpy(0.1, 0.2, 0.3);
  const Isometry3d X_BJ = Eigen::Translation3d(0.4, -0.2, 0.1) * rpy(0.5, 0, -0.4);
  for (const double q : {-0.9, 0.0, 0.35, 1.0}) {
    const Isometry3d expected =
        X_AB * X_BJ * Eigen::AngleAxisd(q, Vector3d::UnitZ()) * X_BJ.inverse();
    const Isometry3d got = NodePose(m, "b", {{"j", q}});
    EXPECT_LT((got.matrix() - expected.matrix()).norm(), 1e-9) << q;
  }
}

TEST(RobotDescriptionTest, BadSdfIsRefusedNamingFileAndWhat) {
  auto refused = [&](const std::string& body, const std::vector<std::string>& parts) {
    ExpectRefused("<?xml version=\"1.0\"?>\n<sdf version=\"1.7\">" + body + "</sdf>\n", parts,
                  "bad.sdf");
  };
  const std::string box =
      "<visual name=\"v\"><geometry><box><size>1 1 1</size></box></geometry></visual>";
  refused("<model name=\"m\"><link name=\"a\">" + box + "</link>", {"bad.sdf:2", "malformed XML"});
  refused("<model name=\"m\"><include><uri>model://no_such_model</uri></include><link name=\"a\">" +
              box + "</link></model>",
          {"model://no_such_model", "searched"});
  refused("<model name=\"m\"><link name=\"a\">" + box + "</link><link name=\"b\">" + box +
              "</link><joint name=\"j\" type=\"revolute\"><parent>a</parent><child>c</child>"
              "<axis><xyz>0 0 1</xyz></axis></joint></model>",
          {"not a valid SDF", "j"});
  refused(
      "<model name=\"m\"><link name=\"a\"><visual "
      "name=\"v\"><geometry><mesh><uri>meshes/none.stl</uri>"
      "</mesh></geometry></visual></link></model>",
      {"link 'a' visual", "meshes/none.stl", "not found"});
  // What sdformat 12 crashes on is refused before it reads the file: a
  // world's flattened model whose joint's parent lies outside (an uncaught
  // exception of sdformat's own) or whose <axis> has no <xyz> (a null
  // pointer), and a URDF under the .sdf name.
  refused(
      "<world name=\"w\"><model name=\"m\"><link name=\"a\"/><link name=\"b\"/>"
      "<joint name=\"x::j\" type=\"fixed\"><parent>a</parent><child>b</child></joint>"
      "</model></world>",
      {"bad.sdf:2", "<world>", "<model>"});
  refused(
      "<world name=\"w\"><model name=\"m\"><link name=\"x::a\"/><link name=\"x::b\"/>"
      "<joint name=\"x::j\" type=\"revolute\"><parent>x::a</parent><child>x::b</child>"
      "<axis><limit/></axis></joint></model></world>",
      {"bad.sdf:2", "<world>"});
  ExpectRefused("<?xml version=\"1.0\"?>\n<robot name=\"r\"><link name=\"a\"/></robot>\n",
                {"bad.sdf:2", "URDF", ".urdf"}, "bad.sdf");
  ExpectRefused("<?xml version=\"1.0\"?>\n<sdf version=\"1.(\"><model name=\"m\"/></sdf>\n",
                {"bad.sdf:2", "1.(", "version"}, "bad.sdf");
  ExpectRefused("<?xml version=\"1.0\"?>\n<model name=\"m\"/>\n", {"bad.sdf", "no <sdf>"},
                "bad.sdf");
}

}  // namespace
}  // namespace sandbox::scene
