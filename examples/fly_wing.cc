// An external model in miniature: flies the bundled flying wing (ELAHA) in a
// circle 60 m above the sample level, bending both wings and working the
// elevators, and publishes its pose and bones over LCM as a Simulink model or
// a C++ solver would.
//
//   fly_wing [--rate HZ] [--duration S] [--poses N] [--lcm-url URL] [--robot NAME]
//
// It stops after --duration seconds or after --poses poses, whichever comes first.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <thread>
#include <vector>

#include "bridge/example_flight.h"

int main(int argc, char** argv) {
  double rate_hz = 100.0, duration_s = 10.0;
  long long poses = -1;
  std::string url, robot = "ELAHA";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--rate"))
      rate_hz = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--duration"))
      duration_s = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--poses"))
      poses = std::atoll(argv[i + 1]), duration_s = 1e9;
    else if (!std::strcmp(argv[i], "--lcm-url"))
      url = argv[i + 1];
    else if (!std::strcmp(argv[i], "--robot"))
      robot = argv[i + 1];
    else {
      std::fprintf(stderr,
                   "usage: fly_wing [--rate HZ] [--duration S] [--poses N] [--lcm-url URL] "
                   "[--robot NAME]\n");
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
    if (t >= duration_s || seq == poses) break;
    const std::int64_t utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count();
    sandbox_msgs::robot_pose_t pose;
    sandbox_msgs::bone_values_t bones;
    sandbox::bridge::ExampleFlight(t, seq, utime, &pose, &bones);  // the flight itself
    std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
    pose.encode(bytes.data(), 0, int(bytes.size()));
    lcm.publish(robot + "/POSE", bytes.data(), unsigned(bytes.size()));
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
