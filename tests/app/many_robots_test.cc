// Two robots in one level, on a collision course, through `sandbox run
// --replay` (the loop, lock-step): each robot's face scanner sees the other
// in its current, bent shape and never itself. The reference for every
// published face is a one-shot scan of a world holding only the other robot's
// skinned mesh, posed from the same inputs (not the loop's collision pieces).
// A third robot far away keeps more sensors due than the loop has threads.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>
#include <vector>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/face_scanner.h"
#include "sensors/ray_caster.h"
#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using namespace sandbox;
namespace fs = std::filesystem;

constexpr int kSteps = 4;
constexpr int kBoneValues = 45;  // the wing: root, R1-R10, L1-L10 two angles each; E1-E3 one

std::string WingTable(const std::string& name, const std::string& position = "[0, 0, 0]") {
  const std::string file =
      (fs::path(SANDBOX_SOURCE_DIR) / "assets/robots/generated/flying_wing.gltf").string();
  return "[[robot]]\nname = \"" + name + "\"\nfile = \"" + file + "\"\nposition = " + position +
         "\n"
         "bones = [\"root\", \"R1\", \"R2\", \"R3\", \"R4\", \"R5\", \"R6\", \"R7\", \"R8\", "
         "\"R9\", \"R10\", \"L1\", \"L2\", \"L3\", \"L4\", \"L5\", \"L6\", \"L7\", \"L8\", "
         "\"L9\", \"L10\", \"E1\", \"E2\", \"E3\"]\n"
         "rotation = \"angles\"\nangle_axes = [\"x\", \"y\"]\n"
         "[robot.bone_axes]\nE1 = [\"y\"]\nE2 = [\"y\"]\nE3 = [\"y\"]\n"
         "[[robot.sensor]]\nname = \"scanner\"\ntype = \"face\"\nresolution_m = 0.5\n"
         "half_extent_m = 20.0\nrefresh = \"full\"\n";
}

// Step k of the course: A flies +x, B comes the other way 3 m higher and 2 m
// aside, turned 10 degrees off the line and rolled; both wings bent (B twice
// as much, upwards; A downwards), more at each step.
Eigen::Isometry3d Pose(int robot, int k) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (robot == 0) {
    X.translation() = Eigen::Vector3d(2.0 * k, 0, 60);
  } else {
    X.translation() = Eigen::Vector3d(24.0 - 3.0 * k, 2, 63);
    X.linear() = (Eigen::AngleAxisd(M_PI - 0.17, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return X;
}

std::vector<double> Bones(int robot, int k) {
  std::vector<double> values(kBoneValues, 0.0);
  const double bend = (robot == 0 ? -0.03 : 0.06) * (1 + k);  // radians a joint
  for (int b = 1; b <= 20; ++b) values[std::size_t(2 * b)] = b <= 10 ? bend : -bend;
  return values;
}

template <typename Message>
void Write(lcm::LogFile* log, const std::string& channel, const Message& message,
           std::int64_t* utime) {
  std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  lcm::LogEvent event{};
  event.timestamp = (*utime += 10'000);
  event.channel = channel;
  event.datalen = std::int32_t(bytes.size());
  event.data = bytes.data();
  ASSERT_EQ(log->writeEvent(&event), 0);
}

// Per step: both robots' bones, then A's pose (a tick), then B's (a tick:
// tick 2k + 1 sees both at step k).
void WriteCourse(const std::string& path) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  std::int64_t utime = 1'000'000;
  const char* names[] = {"A", "B"};
  for (int k = 0; k < kSteps; ++k) {
    for (int r = 0; r < 2; ++r) {
      sandbox_msgs::bone_values_t bones{};
      bones.seq = k;
      bones.utime = utime;
      bones.values = Bones(r, k);
      bones.num_values = kBoneValues;
      Write(&log, std::string(names[r]) + "/BONES", bones, &utime);
    }
    for (int r = 0; r < 2; ++r) {
      const Eigen::Isometry3d X = Pose(r, k);
      const Eigen::Quaterniond q(X.linear());
      sandbox_msgs::robot_pose_t pose{};
      pose.seq = k;
      pose.utime = utime;
      for (int i = 0; i < 3; ++i) pose.position[i] = X.translation()[i];
      pose.orientation[0] = q.w(), pose.orientation[1] = q.x();
      pose.orientation[2] = q.y(), pose.orientation[3] = q.z();
      Write(&log, std::string(names[r]) + "/POSE", pose, &utime);
    }
  }
}

// A level holding one actor: robot `model`'s skinned mesh posed by the
// inputs of step k (bend 0: the wing straight, for the control).
scene::Level PosedMeshLevel(const scene::RobotModel& model, int robot, int k, bool bent) {
  scene::RobotState state(model);
  EXPECT_TRUE(state.SetPose(Pose(robot, k)));
  EXPECT_TRUE(state.SetBones(bent ? Bones(robot, k) : std::vector<double>(kBoneValues, 0.0)));
  state.Update();
  scene::Level level;
  level.name = "posed";
  scene::Actor actor;
  actor.name = model.name;
  actor.X_WA = state.pose();
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    scene::Mesh mesh = model.meshes[m].bind;
    mesh.positions_A = state.positions_B(int(m));
    mesh.normals_A = state.normals_B(int(m));
    for (const Eigen::Vector3f& p : mesh.positions_A) {
      actor.bounds_W.extend(actor.X_WA * p.cast<double>());
    }
    actor.meshes.push_back(std::move(mesh));
  }
  level.actors.push_back(std::move(actor));
  return level;
}

struct Comparison {
  int faces{0}, occupied{0}, occupancy_differs{0};
  std::vector<double> errors_m;  // of the points occupied in both

  double Quantile(double q) {
    if (errors_m.empty()) return 0.0;
    std::sort(errors_m.begin(), errors_m.end());
    return errors_m[std::size_t(q * double(errors_m.size() - 1))];
  }
};

// Compares a published face with the same face scanned in `world`.
void Compare(const sandbox_msgs::scan_face_t& message, const scene::CollisionWorld& world,
             const sensors::FaceScanner& scanner, Comparison* result) {
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();
  X_WS.translation() = Eigen::Vector3d(message.sensor_position[0], message.sensor_position[1],
                                       message.sensor_position[2]);
  X_WS.linear() = Eigen::Quaterniond(message.sensor_orientation[0], message.sensor_orientation[1],
                                     message.sensor_orientation[2], message.sensor_orientation[3])
                      .toRotationMatrix();
  sensors::RayCaster caster(1);
  sensors::FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, sensors::RayFilter{}, X_WS, message.tick, &scan);
  const sensors::ScanFace& face = scan.faces[std::size_t(message.face)];
  const Eigen::Vector3d origin(message.origin[0], message.origin[1], message.origin[2]);
  ++result->faces;
  for (int k = 0; k < message.num_points; ++k) {
    const int published = message.occupancy[std::size_t(k)];
    const int expected = face.occupancy[std::size_t(k)];
    result->occupied += published == sensors::kOccupied;
    if (published != expected) {
      ++result->occupancy_differs;
      continue;
    }
    if (published != sensors::kOccupied) continue;
    const Eigen::Vector3d p = origin + Eigen::Vector3f(message.xyz[std::size_t(3 * k)],
                                                       message.xyz[std::size_t(3 * k + 1)],
                                                       message.xyz[std::size_t(3 * k + 2)])
                                           .cast<double>();
    result->errors_m.push_back((p - scan.PointW(message.face, std::size_t(k))).norm());
  }
}

TEST(ManyRobotsTest, EachRobotsScannerSeesTheOtherBentAndNeverItself) {
  sandbox::testing::TempDir dir;
  const fs::path manifest =
      dir.Write("course.toml", "[level]\nname = \"course\"\n" + WingTable("A") + WingTable("B") +
                                   WingTable("C", "[500, 500, 60]"));
  const std::string course = (dir.path() / "course.lcmlog").string();
  const std::string record = (dir.path() / "out.lcmlog").string();
  WriteCourse(course);
  const auto run = sandbox::testing::RunSandbox("run " + manifest.string() + " --replay " + course +
                                                " --record " + record);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  ASSERT_NE(run.out.find("sandbox run: " + std::to_string(2 * kSteps) + " ticks"),
            std::string::npos)
      << run.out;

  const scene::Level level = scene::LoadLevel(manifest);
  // C, far away and never moved, makes three sensors due each tick: the loop
  // runs them at once on its two threads (sandbox_loop.cc).
  ASSERT_EQ(level.robots.size(), 3u);
  sensors::FaceScannerConfig config;
  config.resolution_m = 0.5;
  config.half_extent_m = 20.0;
  config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner scanner(config);
  // Per robot (the scanning one) and step: the other robot's posed mesh, bent
  // as its inputs say, and straight (the control: the bend must show).
  std::map<std::pair<int, int>, std::unique_ptr<scene::Level>> bent, straight;
  std::map<std::pair<int, int>, std::unique_ptr<scene::CollisionWorld>> bent_world, straight_world;
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < kSteps; ++k) {
      const int other = 1 - r;
      bent[{r, k}] = std::make_unique<scene::Level>(
          PosedMeshLevel(level.robots[std::size_t(other)], other, k, true));
      straight[{r, k}] = std::make_unique<scene::Level>(
          PosedMeshLevel(level.robots[std::size_t(other)], other, k, false));
      bent_world[{r, k}] = std::make_unique<scene::CollisionWorld>(*bent[{r, k}]);
      straight_world[{r, k}] = std::make_unique<scene::CollisionWorld>(*straight[{r, k}]);
    }
  }

  Comparison against_bent[2], against_straight[2];
  lcm::LogFile log(record, "r");
  ASSERT_TRUE(log.good());
  int c_faces = 0;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    c_faces += event->channel == "C/SCAN_FACE";
    const int r = event->channel == "A/SCAN_FACE" ? 0 : event->channel == "B/SCAN_FACE" ? 1 : -1;
    if (r < 0) continue;
    sandbox_msgs::scan_face_t face;
    ASSERT_GE(face.decode(event->data, 0, event->datalen), 0);
    if (face.tick % 2 == 0) continue;  // only one robot moved yet at even ticks
    const int k = int(face.tick / 2);
    Compare(face, *bent_world[{r, k}], scanner, &against_bent[r]);
    Compare(face, *straight_world[{r, k}], scanner, &against_straight[r]);
  }
  EXPECT_EQ(c_faces, 6 * 2 * kSteps);  // a full scan each tick
  for (int r = 0; r < 2; ++r) {
    SCOPED_TRACE(r == 0 ? "A's scanner" : "B's scanner");
    EXPECT_EQ(against_bent[r].faces, 6 * kSteps);
    // The other robot is seen, at hundreds of points.
    EXPECT_GT(against_bent[r].occupied, 300);
    // Where it is bent: the loop's rigid collision pieces are off the skin
    // only in the joints' blend zones (docs/reference/robots.md), so a few grazing
    // rays may differ.
    EXPECT_LT(against_bent[r].occupancy_differs, against_bent[r].occupied / 50)
        << against_bent[r].occupied << " occupied";
    // Hits agree to the millimetre mostly; a ray grazing the surface turns
    // millimetres off it into decimetres along the ray.
    EXPECT_LT(against_bent[r].Quantile(0.5), 0.001);
    EXPECT_LT(against_bent[r].Quantile(0.95), 0.01);
    EXPECT_LT(against_bent[r].Quantile(1.0), 0.25);
    // Had the loop missed the bend (or scanned the robot itself), the
    // published faces would not match the straight wing's either way.
    EXPECT_GT(against_straight[r].occupancy_differs, 10 * against_bent[r].occupancy_differs + 100)
        << against_straight[r].occupancy_differs << " vs " << against_bent[r].occupancy_differs;
  }
}

}  // namespace
