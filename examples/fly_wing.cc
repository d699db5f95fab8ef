// An external model in miniature: flies the bundled flying wing (ELAHA) in a
// circle 60 m above the sample level, bending both wings and working the
// elevators, and publishes its pose and bones over LCM as a Simulink model or
// a C++ solver would.
//
//   fly_wing [--rate HZ] [--duration S] [--lcm-url URL] [--robot NAME]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <thread>
#include <vector>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

int main(int argc, char** argv) {
  double rate_hz = 100.0, duration_s = 10.0;
  std::string url, robot = "ELAHA";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--rate"))
      rate_hz = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--duration"))
      duration_s = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--lcm-url"))
      url = argv[i + 1];
    else if (!std::strcmp(argv[i], "--robot"))
      robot = argv[i + 1];
    else {
      std::fprintf(stderr,
                   "usage: fly_wing [--rate HZ] [--duration S] [--lcm-url URL] [--robot NAME]\n");
      return 2;
    }
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "fly_wing: cannot open LCM URL '%s'\n", url.c_str());
    return 1;
  }
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  auto next = start;
  std::int64_t seq = 0;
  for (;;) {
    const double t = std::chrono::duration<double>(Clock::now() - start).count();
    if (t >= duration_s) break;
    const std::int64_t utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count();
    // A 120 m circle at 15 m/s, banked into the turn.
    const double radius = 120.0, speed = 15.0, w = speed / radius, a = w * t;
    sandbox_msgs::robot_pose_t pose{};
    pose.utime = utime;
    pose.seq = seq;
    pose.position[0] = radius * std::cos(a);
    pose.position[1] = radius * std::sin(a);
    pose.position[2] = 60.0 + 5.0 * std::sin(0.3 * t);
    const double yaw = a + M_PI / 2, roll = -0.2;  // heading along the circle, banked left
    const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2), cr = std::cos(roll / 2),
                 sr = std::sin(roll / 2);
    pose.orientation[0] = cy * cr;  // Rz(yaw) Rx(roll)
    pose.orientation[1] = cy * sr;
    pose.orientation[2] = sy * sr;
    pose.orientation[3] = sy * cr;
    std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
    pose.encode(bytes.data(), 0, int(bytes.size()));
    lcm.publish(robot + "/POSE", bytes.data(), unsigned(bytes.size()));

    // Bones: root (2 angles), R1-R10 and L1-L10 (roll, pitch), E1-E3 (pitch).
    sandbox_msgs::bone_values_t bones{};
    bones.utime = utime;
    bones.seq = seq;
    bones.num_values = 45;
    bones.values.assign(45, 0.0);
    const double bend = 0.06 * std::sin(1.5 * t);  // up to 3.4 degrees a joint
    for (int b = 1; b <= 20; ++b) bones.values[std::size_t(2 * b)] = b <= 10 ? bend : -bend;
    for (int e = 0; e < 3; ++e) bones.values[std::size_t(42 + e)] = 0.2 * std::sin(2.0 * t + e);
    bytes.resize(std::size_t(bones.getEncodedSize()));
    bones.encode(bytes.data(), 0, int(bytes.size()));
    lcm.publish(robot + "/BONES", bytes.data(), unsigned(bytes.size()));
    ++seq;
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  std::printf("fly_wing: published %lld poses\n", static_cast<long long>(seq));
  return 0;
}
