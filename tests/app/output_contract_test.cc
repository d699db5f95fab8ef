// What `sandbox run` publishes holds to its documented contract, checked in
// lock-step replays of known flights against geometry computed here: lidar
// sweeps cast from the pose at each step's time, STATE's face frames as the
// faces were scanned, and scans far from the world origin as precise as near it.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/lidar.h"
#include "tests/app/run_sandbox.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox {
namespace {

namespace fs = std::filesystem;
using testing::RunSandbox;

constexpr std::int64_t kStartUtime = 1'000'000;

std::string Wing() {
  return (fs::path(SANDBOX_SOURCE_DIR) / "assets/robots/generated/flying_wing.gltf").string();
}

// A level: `actors` (TOML), then robot W (the flying wing, root bone only) with `sensors`.
fs::path WriteLevel(const testing::TempDir& dir, const std::string& actors,
                    const std::string& sensors) {
  return dir.Write("level.toml", actors + "\n[[robot]]\nname = \"W\"\nfile = \"" + Wing() +
                                     "\"\nbones = [\"root\"]\n\n" + sensors);
}

// W/POSE messages, pose i at kStartUtime + period_us i.
void WritePoses(const fs::path& file, const std::vector<Eigen::Isometry3d>& poses,
                std::int64_t period_us) {
  lcm::LogFile log(file.string(), "w");
  ASSERT_TRUE(log.good()) << file;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sandbox_msgs::robot_pose_t pose{};
    pose.utime = kStartUtime + period_us * std::int64_t(i);
    pose.seq = std::int64_t(i);
    const Eigen::Quaterniond q(poses[i].linear());
    for (int k = 0; k < 3; ++k) pose.position[k] = poses[i].translation()[k];
    pose.orientation[0] = q.w(), pose.orientation[1] = q.x();
    pose.orientation[2] = q.y(), pose.orientation[3] = q.z();
    std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
    pose.encode(bytes.data(), 0, int(bytes.size()));
    lcm::LogEvent event;
    event.eventnum = std::int64_t(i);
    event.timestamp = pose.utime;
    event.channel = "W/POSE";
    event.datalen = std::int32_t(bytes.size());
    event.data = bytes.data();
    ASSERT_EQ(log.writeEvent(&event), 0);
  }
}

// Every message of a recording on `channel`, decoded.
template <typename Message>
std::vector<Message> Recorded(const fs::path& file, const std::string& channel) {
  std::vector<Message> messages;
  lcm::LogFile log(file.string(), "r");
  EXPECT_TRUE(log.good()) << file;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != channel) continue;
    Message message;
    EXPECT_EQ(message.decode(event->data, 0, event->datalen), event->datalen);
    messages.push_back(message);
  }
  return messages;
}

// Replays `poses` (100 Hz) on the level in lock-step, recording what it publishes.
fs::path Replay(const testing::TempDir& dir, const fs::path& level,
                const std::vector<Eigen::Isometry3d>& poses, std::string* out = nullptr) {
  const fs::path log = dir.path() / "flight.lcmlog", recording = dir.path() / "out.lcmlog";
  WritePoses(log, poses, 10'000);
  const auto run = RunSandbox("run " + level.string() + " --replay " + log.string() + " --record " +
                              recording.string());
  EXPECT_EQ(run.exit_code, 0) << run.out;
  if (out != nullptr) *out = run.out;
  return recording;
}

Eigen::Isometry3d Pose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = p;
  return X;
}

Eigen::Quaterniond Rpy(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

// The fast pass: 50 m/s along +x and 90 deg/s of yaw, 20 m from the face of a wall.
Eigen::Isometry3d FastPass(double tau_s) {
  return Pose({50.0 * tau_s, 0.0, 0.0}, Rpy(0, 0, 0.5 * M_PI * tau_s));
}

// A noisy lidar with divergent beams in two lock-step replays of one flight:
// with one seed its sweeps are the same to the byte, with another they differ.
TEST(OutputContractTest, NoisyLidarSweepsRepeatInLockStepReplaysForOneSeed) {
  auto sweeps_with_seed = [](int seed) {
    testing::TempDir dir;
    dir.Write("wall.obj", testing::ObjBox("wall", 600, 1, 60, -200, 20, -30));
    dir.Write("pillar.obj", testing::ObjBox("pillar", 2, 2, 60, 30, 10, -30));
    const fs::path level =
        WriteLevel(dir,
                   "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n"
                   "[[actor]]\nname = \"pillar\"\nfile = \"pillar.obj\"\n",
                   "[[robot.sensor]]\nname = \"lidar\"\ntype = \"lidar\"\nchannels = 4\n"
                   "azimuth_steps = 720\nrate_hz = 10\nrange_noise_sigma_m = 0.05\n"
                   "dropout_probability = 0.1\ndivergence_rays = 4\ndivergence_deg = 1\nseed = " +
                       std::to_string(seed) + "\n");
    std::vector<Eigen::Isometry3d> poses;
    for (int i = 0; i < 50; ++i) poses.push_back(FastPass(0.01 * i));
    std::vector<std::vector<std::uint8_t>> bytes;
    for (const auto& sweep :
         Recorded<sandbox_msgs::lidar_scan_t>(Replay(dir, level, poses), "W/LIDAR")) {
      // Everything the sweep measured (its utime and seq stamp the run, not the sweep).
      sandbox_msgs::lidar_scan_t measured = sweep;
      measured.utime = measured.seq = 0;
      bytes.emplace_back(std::size_t(measured.getEncodedSize()));
      measured.encode(bytes.back().data(), 0, int(bytes.back().size()));
      EXPECT_EQ(sweep.num_last, sweep.num_beams);
    }
    return bytes;
  };
  const auto first = sweeps_with_seed(5), again = sweeps_with_seed(5), other = sweeps_with_seed(6);
  ASSERT_EQ(first.size(), 5u);  // at 0, 0.1, ..., 0.4 s of input time
  EXPECT_EQ(first, again);
  ASSERT_EQ(other.size(), first.size());
  for (std::size_t k = 0; k < first.size(); ++k) EXPECT_NE(first[k], other[k]) << k;
}

TEST(OutputContractTest, LidarStepsAreCastFromThePoseAtTheirTime) {
  testing::TempDir dir;
  dir.Write("wall.obj", testing::ObjBox("wall", 600, 1, 60, -200, 20, -30));
  const fs::path level =
      WriteLevel(dir, "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n",
                 "[[robot.sensor]]\nname = \"lidar\"\ntype = \"lidar\"\nelevations_deg = [0]\n"
                 "azimuth_steps = 360\nrange_m = 100\nrotation_hz = 10\nrate_hz = 10\n");
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 100; ++i) poses.push_back(FastPass(0.01 * i));
  const fs::path recording = Replay(dir, level, poses);
  const auto sweeps = Recorded<sandbox_msgs::lidar_scan_t>(recording, "W/LIDAR");
  ASSERT_EQ(sweeps.size(), 10u);  // at 0, 0.1, ..., 0.9 s of input time

  // The wall as a caster that does not compensate sees it from the end pose.
  const scene::Level loaded = scene::LoadLevel(level);
  const scene::CollisionWorld world(loaded);
  sensors::RayCaster caster(1);
  sensors::RayFilter filter;
  filter.ignore_robot = 0;
  const sensors::Lidar lidar(sensors::LidarConfig::Uniform(1, 0, 0, 360, 100.0, 10.0));

  int checked = 0;
  double worst_m = 0.0, worst_uncompensated_m = 0.0;
  for (const auto& sweep : sweeps) {
    const double end_s = double(sweep.utime - kStartUtime) * 1e-6;
    if (end_s - sweep.sweep_s < 0.0) continue;  // began before the flight: nothing to interpolate
    EXPECT_DOUBLE_EQ(sweep.sweep_s, 0.1);
    const Eigen::Isometry3d start = FastPass(end_s - 0.1), end = FastPass(end_s);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(sweep.start_position[k], start.translation()[k], 1e-9);
      EXPECT_NEAR(sweep.end_position[k], end.translation()[k], 1e-9);
    }
    sensors::LidarScan uncompensated;
    lidar.Sweep(world, caster, filter, end, end, &uncompensated);
    for (int k = 0; k < sweep.steps; ++k) {
      // Where the robot really was when step k was cast, and the beam from there.
      const Eigen::Isometry3d X_WS = FastPass(end_s - sweep.sweep_s + sweep.time_s[k]);
      const double a = 2.0 * M_PI * k / sweep.steps;
      const Eigen::Vector3d beam_W = X_WS.linear() * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
      if (sweep.hit[k]) {
        const Eigen::Vector3d point = X_WS.translation() + double(sweep.range_m[k]) * beam_W;
        worst_m = std::max(worst_m, std::abs(point.y() - 20.0));
        ++checked;
      }
      if (uncompensated.hit[std::size_t(k)]) {
        const Eigen::Vector3d point =
            X_WS.translation() + double(uncompensated.range_m[std::size_t(k)]) * beam_W;
        worst_uncompensated_m = std::max(worst_uncompensated_m, std::abs(point.y() - 20.0));
      }
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_LT(worst_m, 0.01);               // every point on the wall to 1 cm
  EXPECT_GT(worst_uncompensated_m, 0.5);  // cast from the end pose, they are metres off
}

// Face f's in-plane axes (u, v) in the box frame (docs/reference/sensors.md).
void FaceAxes(int f, Eigen::Vector3d* u, Eigen::Vector3d* v, Eigen::Vector3d* axis) {
  *u = f < 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  *v = f < 4 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  *axis = Eigen::Vector3d::Zero();
  (*axis)[f / 2] = f % 2 == 0 ? 1.0 : -1.0;
}

Eigen::Isometry3d FaceFrame(const sandbox_msgs::robot_state_t& state, int f) {
  const Eigen::Isometry3d X_WR = Pose(
      {state.position[0], state.position[1], state.position[2]},
      {state.orientation[0], state.orientation[1], state.orientation[2], state.orientation[3]});
  const double* p = &state.face_positions[3 * f];
  const double* q = &state.face_orientations[4 * f];
  return X_WR * Pose({p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]});
}

// Every point of every face lies on its ray as STATE's face frame places it:
// at the grid point's in-plane coordinates, along the face axis (free: at E).
void ExpectFramesPlaceThePoints(const sandbox_msgs::robot_state_t& state,
                                const std::vector<sandbox_msgs::scan_face_t>& faces, double res,
                                double E) {
  std::map<int, const sandbox_msgs::scan_face_t*> last;  // the latest scan of each face
  for (const auto& face : faces) last[face.face] = &face;
  ASSERT_EQ(last.size(), 6u);
  for (const auto& [f, face] : last) {
    const Eigen::Isometry3d X_FW = FaceFrame(state, f).inverse();
    Eigen::Vector3d u, v, axis;
    FaceAxes(f, &u, &v, &axis);
    const Eigen::Vector3d origin(face->origin[0], face->origin[1], face->origin[2]);
    for (int r = 0; r < face->n; ++r) {
      for (int c = 0; c < face->n; ++c) {
        const int k = r * face->n + c;
        const Eigen::Vector3d point_W =
            origin + Eigen::Vector3d(face->xyz[3 * k], face->xyz[3 * k + 1], face->xyz[3 * k + 2]);
        const Eigen::Vector3d q = X_FW * point_W;
        ASSERT_NEAR(q.dot(u), -E + c * res, 1e-3) << "face " << f << " row " << r << " col " << c;
        ASSERT_NEAR(q.dot(v), -E + r * res, 1e-3) << "face " << f << " row " << r << " col " << c;
        if (face->occupancy[k] == 0) {
          ASSERT_NEAR(q.dot(axis), E, 1e-3) << "face " << f;
        } else {
          ASSERT_GE(q.dot(axis), -1e-3) << "face " << f;
          ASSERT_LE(q.dot(axis), E + 1e-3) << "face " << f;
        }
      }
    }
  }
}

TEST(OutputContractTest, StateFaceFramesAreTheBoxesTheFacesWereScannedIn) {
  for (const std::string aligned : {"body", "world"}) {
    SCOPED_TRACE(aligned);
    testing::TempDir dir;
    dir.Write("box.obj", testing::ObjBox("box", 4, 4, 4, 2, -6, 0));
    const fs::path level = WriteLevel(
        dir, "[[actor]]\nname = \"box\"\nfile = \"box.obj\"\n",
        "[[robot.sensor]]\nname = \"faces\"\ntype = \"face\"\nposition = [1, -2, 0.5]\n"
        "rpy_deg = [10, 20, 30]\nresolution_m = 0.5\nhalf_extent_m = 4\nrefresh = \"six_stage\"\n"
        "aligned = \"" +
            aligned + "\"\n");
    // A turning, climbing robot: each face is scanned at another pose.
    std::vector<Eigen::Isometry3d> poses;
    for (int i = 0; i < 12; ++i) {
      poses.push_back(Pose({0.5 * i, 0.2 * i, 3.0 + 0.1 * i}, Rpy(0.1 * i, 0.05 * i, 0.2 * i)));
    }
    const fs::path recording = Replay(dir, level, poses);
    const auto states = Recorded<sandbox_msgs::robot_state_t>(recording, "W/STATE");
    const auto faces = Recorded<sandbox_msgs::scan_face_t>(recording, "W/SCAN_FACE");
    ASSERT_EQ(states.size(), 12u);
    ASSERT_EQ(faces.size(), 12u);
    ExpectFramesPlaceThePoints(states.back(), faces, 0.5, 4.0);
    // The face scanned this tick (tick 11: face 5) sits on the mount as declared.
    const Eigen::Quaterniond mount = Rpy(10 * M_PI / 180, 20 * M_PI / 180, 30 * M_PI / 180);
    const Eigen::Isometry3d X_RF = FaceFrame(states.back(), 5);
    const Eigen::Isometry3d X_WR = poses.back();
    const Eigen::Isometry3d expected = aligned == "body" ? X_WR * Pose({1, -2, 0.5}, mount)
                                                         : Pose(X_WR * Eigen::Vector3d(1, -2, 0.5),
                                                                Eigen::Quaterniond::Identity());
    EXPECT_LT((X_RF.matrix() - expected.matrix()).norm(), 1e-9);
    // Faces scanned at earlier poses differ from the mount now (the robot turned).
    EXPECT_GT((FaceFrame(states.back(), 0).matrix() - expected.matrix()).norm(), 0.1);
  }
}

TEST(OutputContractTest, ScansTwoHundredKilometresOutAreAsPreciseAsAtTheOrigin) {
  testing::TempDir dir;
  // A 10 m box whose top is at z = 5, placed 200 km east.
  dir.Write("box.obj", testing::ObjBox("box", 10, 10, 10, -5, -5, -5));
  const fs::path level =
      WriteLevel(dir, "[[actor]]\nname = \"far\"\nfile = \"box.obj\"\nposition = [200000, 0, 0]\n",
                 "[[robot.sensor]]\nname = \"faces\"\ntype = \"face\"\nresolution_m = 0.5\n"
                 "half_extent_m = 20\nrefresh = \"full\"\n");
  // Out from the origin in 5 km steps, then three ticks over the box.
  const Eigen::Vector3d over(200000.37, 0.21, 20.13);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i <= 40; ++i)
    poses.push_back(Pose(over * i / 40.0, Eigen::Quaterniond::Identity()));
  for (int i = 0; i < 3; ++i) poses.push_back(Pose(over, Eigen::Quaterniond::Identity()));
  std::string out;
  const fs::path recording = Replay(dir, level, poses, &out);
  EXPECT_NE(out.find("floating origin: moved 40 times"), std::string::npos) << out;
  const auto faces = Recorded<sandbox_msgs::scan_face_t>(recording, "W/SCAN_FACE");
  ASSERT_EQ(faces.size(), 6u * poses.size());
  // The -Z face of the last tick: rays over the box top stop on it at z = 5,
  // the grid point's x and y kept (computed here, to 1 mm).
  const sandbox_msgs::scan_face_t& down = faces[faces.size() - 1];
  ASSERT_EQ(down.face, 5);
  const Eigen::Vector3d origin(down.origin[0], down.origin[1], down.origin[2]);
  int on_top = 0;
  for (int r = 0; r < down.n; ++r) {
    for (int c = 0; c < down.n; ++c) {
      const int k = r * down.n + c;
      const Eigen::Vector3d grid = over + Eigen::Vector3d(-20 + 0.5 * c, -20 + 0.5 * r, 0);
      const Eigen::Vector3d point =
          origin + Eigen::Vector3d(down.xyz[3 * k], down.xyz[3 * k + 1], down.xyz[3 * k + 2]);
      ASSERT_NEAR(point.x(), grid.x(), 1e-3) << r << " " << c;
      ASSERT_NEAR(point.y(), grid.y(), 1e-3) << r << " " << c;
      const bool over_box = std::abs(grid.x() - 200000) < 4.999 && std::abs(grid.y()) < 4.999;
      if (over_box) {
        ASSERT_EQ(down.occupancy[k], 1) << r << " " << c;
        ASSERT_NEAR(point.z(), 5.0, 1e-3) << r << " " << c;
        ++on_top;
      }
    }
  }
  EXPECT_EQ(on_top, 20 * 20);  // x and y from -4.63 to 4.87 (and -4.79 to 4.71) in 0.5 m steps
  // The -X face: rays starting inside the box (z below its top) stop on its
  // -x wall, 199995, along x (where 200 km of float would round by 8 mm).
  const sandbox_msgs::scan_face_t& back = faces[faces.size() - 5];
  ASSERT_EQ(back.face, 1);
  int on_wall = 0;
  for (int r = 0; r < back.n; ++r) {
    for (int c = 0; c < back.n; ++c) {
      const double y = over.y() - 20 + 0.5 * c, z = over.z() - 20 + 0.5 * r;
      if (std::abs(y) > 4.999 || std::abs(z) > 4.999) continue;
      const int k = r * back.n + c;
      ASSERT_EQ(back.occupancy[k], 1) << r << " " << c;
      ASSERT_NEAR(back.origin[0] + back.xyz[3 * k], 199995.0, 1e-3) << r << " " << c;
      ++on_wall;
    }
  }
  EXPECT_EQ(on_wall, 10 * 20);
  // And the same points as a one-shot scan there.
  const fs::path one_shot = dir.path() / "one_shot.csv";
  const auto scan = RunSandbox("scan " + level.string() +
                               " --at 200000.37,0.21,20.13 --resolution 0.5 --half-extent 20 "
                               "--out " +
                               one_shot.string());
  ASSERT_EQ(scan.exit_code, 0) << scan.out;
  std::ifstream csv(one_shot);
  std::string line;
  std::getline(csv, line);  // face,row,col,occupancy,x,y,z,surface,nx,ny,nz
  int compared = 0;
  while (std::getline(csv, line)) {
    int f, r, c, occupancy, surface;
    double x, y, z;
    ASSERT_EQ(std::sscanf(line.c_str(), "%d,%d,%d,%d,%lf,%lf,%lf,%d", &f, &r, &c, &occupancy, &x,
                          &y, &z, &surface),
              8)
        << line;
    const sandbox_msgs::scan_face_t& face = faces[faces.size() - 6 + std::size_t(f)];
    ASSERT_EQ(face.face, f);
    const int k = r * face.n + c;
    EXPECT_EQ(face.occupancy[k], occupancy) << line;
    ASSERT_EQ(face.num_surface, face.num_points);  // surface ids are on by default
    EXPECT_EQ(face.surface[k], surface) << line;
    const Eigen::Vector3d point =
        Eigen::Vector3d(face.origin[0], face.origin[1], face.origin[2]) +
        Eigen::Vector3d(face.xyz[3 * k], face.xyz[3 * k + 1], face.xyz[3 * k + 2]);
    EXPECT_LT((point - Eigen::Vector3d(x, y, z)).norm(), 1e-3) << line;
    ++compared;
  }
  EXPECT_EQ(compared, 6 * 81 * 81);
}

// A robot driven by UDP doubles whose layout has the sender's time and
// counter: the outputs are tagged with them, not with the receive count.
TEST(OutputContractTest, OutputsFromUdpDoublesCarryThePacketsOwnSeqAndTime) {
  testing::TempDir dir;
  const int port = testing::FreeUdpPort();
  const fs::path level = dir.Write(
      "level.toml", "[[robot]]\nname = \"W\"\nfile = \"" + Wing() +
                        "\"\nbones = [\"root\"]\n\n[robot.bridge]\nbind_address = \"127.0.0.1\"\n"
                        "udp_doubles_port = " +
                        std::to_string(port) +
                        "\nudp_doubles_layout = [\"time\", \"seq\", \"position\"]\n");
  const fs::path recording = dir.path() / "out.lcmlog";
  std::atomic<bool> done{false};
  std::thread sender([&] {
    const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
    for (int i = 0; !done; ++i) {  // packet i: seq 1000 + i at 50 + 0.01 i s
      const double packet[5] = {50.0 + 0.01 * i, 1000.0 + i, 0.1 * i, 0, 10};
      ::sendto(s, packet, sizeof(packet), 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
      usleep(10000);
    }
    ::close(s);
  });
  const auto run = RunSandbox("run " + level.string() +
                              " --lcm-url memq:// --duration 3 --record " + recording.string());
  done = true;
  sender.join();
  ASSERT_EQ(run.exit_code, 0) << run.out;
  int tagged = 0;
  for (const auto& state : Recorded<sandbox_msgs::robot_state_t>(recording, "W/STATE")) {
    if (state.input_seq < 0) continue;  // before the first packet
    ASSERT_GE(state.input_seq, 1000);
    const std::int64_t i = state.input_seq - 1000;
    EXPECT_EQ(state.input_utime, 50'000'000 + 10'000 * i);
    EXPECT_NEAR(state.position[0], 0.1 * double(i), 1e-9);  // the pose of that packet
    ++tagged;
  }
  EXPECT_GT(tagged, 0) << run.out;
}

}  // namespace
}  // namespace sandbox
