// An external model for a robot from a description: publishes its pose on
// <ROBOT>/POSE and its joint values by name on <ROBOT>/JOINTS over LCM.
//
//   drive_joints --motion wave|circuit [--robot NAME] [--rate HZ] [--duration S]
//                [--lcm-url URL]
//
// wave (default robot "arm", assets/arm/arm.urdf): the bundled arm stands at
// the origin and waves every joint within its limits.
// circuit (default robot "plane", PX4's plane.sdf): the plane flies a 200 m by
// 80 m racetrack 40 m up at 18 m/s, banking into the turns; its elevons roll
// it, the elevator holds the turn, the rudder coordinates, the flaps stay out
// on the straights, and the propeller turns at 80 rev/s.
// Exit status 1 when LCM reported a send as failed.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <thread>
#include <vector>

#include "sandbox_msgs/joint_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace {

struct Sample {
  double position[3]{0, 0, 0};
  double roll{0}, pitch{0}, yaw{0};
  std::vector<std::string> names;
  std::vector<double> values;
};

Sample Wave(double t) {
  Sample s;
  s.names = {"base_yaw", "shoulder", "elbow", "extend", "wrist_roll"};
  s.values = {0.8 * std::sin(0.5 * t), 0.6 * std::sin(0.9 * t + 1.0), 1.2 * std::sin(0.7 * t) - 0.3,
              0.075 + 0.07 * std::sin(1.3 * t), 2.5 * std::sin(0.4 * t)};
  return s;
}

// The racetrack: two 200 m straights joined by half circles of 40 m radius.
Sample Circuit(double t) {
  const double speed = 18.0, straight = 200.0, radius = 40.0;
  const double lap = 2.0 * straight + 2.0 * M_PI * radius;
  double d = std::fmod(speed * t, lap);
  Sample s;
  double bank = 0.0;
  if (d < straight) {  // east along y = -radius
    s.position[0] = d - straight / 2, s.position[1] = -radius, s.yaw = 0.0;
  } else if ((d -= straight) < M_PI * radius) {  // turning left, north
    const double a = d / radius;
    s.position[0] = straight / 2 + radius * std::sin(a);
    s.position[1] = -radius * std::cos(a);
    s.yaw = a, bank = std::atan(speed * speed / (radius * 9.81));
  } else if ((d -= M_PI * radius) < straight) {  // west along y = +radius
    s.position[0] = straight / 2 - d, s.position[1] = radius, s.yaw = M_PI;
  } else {
    const double a = (d - straight) / radius;
    s.position[0] = -straight / 2 - radius * std::sin(a);
    s.position[1] = radius * std::cos(a);
    s.yaw = M_PI + a, bank = std::atan(speed * speed / (radius * 9.81));
  }
  s.position[2] = 40.0;
  s.roll = bank;
  const double turning = bank > 0.0 ? 1.0 : 0.0;
  s.names = {"left_elevon_joint", "right_elevon_joint", "elevator_joint",    "rudder_joint",
             "left_flap_joint",   "right_flap_joint",   "rotor_puller_joint"};
  const double roll_input = 0.15 * turning + 0.05 * std::sin(2.0 * t);
  s.values = {-roll_input,
              roll_input,
              -0.25 * turning,
              0.1 * turning,
              0.2 * (1 - turning),
              0.2 * (1 - turning),
              std::fmod(2.0 * M_PI * 80.0 * t, 1e6)};
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::string motion = "wave", robot, url;
  double rate_hz = 100.0, duration_s = 30.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--motion")) {
      motion = argv[i + 1];
    } else if (!std::strcmp(argv[i], "--robot")) {
      robot = argv[i + 1];
    } else if (!std::strcmp(argv[i], "--rate")) {
      rate_hz = std::atof(argv[i + 1]);
    } else if (!std::strcmp(argv[i], "--duration")) {
      duration_s = std::atof(argv[i + 1]);
    } else if (!std::strcmp(argv[i], "--lcm-url")) {
      url = argv[i + 1];
    } else {
      std::fprintf(stderr, "drive_joints: unknown option '%s'\n", argv[i]);
      return 2;
    }
  }
  if ((motion != "wave" && motion != "circuit") || !(rate_hz > 0.0) || !(duration_s >= 0.0)) {
    std::fprintf(stderr,
                 "usage: drive_joints --motion wave|circuit [--robot NAME] [--rate HZ] "
                 "[--duration S] [--lcm-url URL]\n");
    return 2;
  }
  if (robot.empty()) robot = motion == "wave" ? "arm" : "plane";
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "drive_joints: cannot open LCM '%s'\n", url.c_str());
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  long failed = 0, sent = 0;
  for (long n = 0;; ++n) {
    const double t = double(n) / rate_hz;
    if (t > duration_s) break;
    std::this_thread::sleep_until(start + std::chrono::duration<double>(t));
    const Sample s = motion == "wave" ? Wave(t) : Circuit(t);
    const std::int64_t utime = std::int64_t(t * 1e6);
    sandbox_msgs::robot_pose_t pose{};
    pose.utime = utime, pose.seq = n;
    std::copy(s.position, s.position + 3, pose.position);
    const double cr = std::cos(s.roll / 2), sr = std::sin(s.roll / 2);
    const double cp = std::cos(s.pitch / 2), sp = std::sin(s.pitch / 2);
    const double cy = std::cos(s.yaw / 2), sy = std::sin(s.yaw / 2);
    pose.orientation[0] = cr * cp * cy + sr * sp * sy;
    pose.orientation[1] = sr * cp * cy - cr * sp * sy;
    pose.orientation[2] = cr * sp * cy + sr * cp * sy;
    pose.orientation[3] = cr * cp * sy - sr * sp * cy;
    sandbox_msgs::joint_values_t joints{};
    joints.utime = utime, joints.seq = n;
    joints.num_names = int(s.names.size()), joints.names = s.names;
    joints.num_values = int(s.values.size()), joints.values = s.values;
    failed += lcm.publish(robot + "/JOINTS", &joints) != 0;
    failed += lcm.publish(robot + "/POSE", &pose) != 0;
    ++sent;
  }
  std::printf("drive_joints: published %ld poses and %ld joint messages\n", sent, sent);
  if (failed > 0) std::fprintf(stderr, "drive_joints: %ld sends failed\n", failed);
  return failed > 0 ? 1 : 0;
}
