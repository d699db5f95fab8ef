// An external model in miniature: flies the bundled flying wing (ELAHA) in a
// circle 60 m above the sample level, bending both wings and working the
// elevators, and publishes its pose and bones over LCM as a Simulink model or
// a C++ solver would. With --slot left or right it flies one of the wing's
// two quadrotor wingmen instead (assets/formation: QUAD1, QUAD2), one
// process per robot as separate models would be.
//
//   fly_wing [--slot wing|left|right] [--rate HZ] [--duration S] [--poses N]
//            [--lcm-url URL] [--robot NAME] [--log FILE] [--phase S]
//            [--flight circle|highlands] [--write-log FILE]
//
// --write-log: publishes nothing; writes the flight to FILE as fast as it can,
// stamped in flight time (a pose every 1/rate s), for `sandbox run --replay`.
// --flight highlands: the wing over assets/highlands instead, climbing from the
// airfield to 20 km while it crosses 100 km eastwards at 300 m/s.
// --phase: fly S seconds ahead on the circle (robots spread along it).
// --log: also writes every message it publishes to an LCM log (`sandbox run
// --replay FILE` then runs the same inputs again).
// --robot: the channel prefix (default ELAHA, QUAD1 for left, QUAD2 for right).
// It stops after --duration seconds or after --poses poses, whichever comes first.
// Exit status 1 when LCM reported a send as failed (the count is on stderr).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bridge/example_flight.h"

int main(int argc, char** argv) {
  double rate_hz = 100.0, duration_s = 10.0, phase_s = 0.0;
  long long poses = -1;
  std::string url, robot, slot = "wing", log_file, flight = "circle";
  bool offline = false;  // --write-log: the log only, in flight time, at once
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
    else if (!std::strcmp(argv[i], "--slot"))
      slot = argv[i + 1];
    else if (!std::strcmp(argv[i], "--log"))
      log_file = argv[i + 1];
    else if (!std::strcmp(argv[i], "--write-log"))
      log_file = argv[i + 1], offline = true;
    else if (!std::strcmp(argv[i], "--flight"))
      flight = argv[i + 1];
    else if (!std::strcmp(argv[i], "--phase"))
      phase_s = std::atof(argv[i + 1]);
    else {
      argc = -1;
      break;
    }
  }
  const int side = slot == "left" ? -1 : slot == "right" ? 1 : 0;
  if (argc < 0 || argc % 2 == 0 || (side == 0 && slot != "wing") || !(rate_hz > 0.0) ||
      (flight != "circle" && flight != "highlands")) {
    std::fprintf(stderr,
                 "usage: fly_wing [--slot wing|left|right] [--rate HZ] [--duration S] [--poses N]\n"
                 "                [--lcm-url URL] [--robot NAME] [--log FILE] [--phase S]\n"
                 "                [--flight circle|highlands] [--write-log FILE]\n");
    return 2;
  }
  if (robot.empty()) robot = side < 0 ? "QUAD1" : side > 0 ? "QUAD2" : "ELAHA";
  lcm::LCM lcm(offline ? "memq://" : url);
  if (!lcm.good()) {
    std::fprintf(stderr, "fly_wing: cannot open LCM URL '%s'\n", url.c_str());
    return 1;
  }
  std::unique_ptr<lcm::LogFile> log;
  if (!log_file.empty()) {
    log = std::make_unique<lcm::LogFile>(log_file, "w");
    if (!log->good()) {
      std::fprintf(stderr, "fly_wing: cannot write the log '%s'\n", log_file.c_str());
      return 1;
    }
  }
  long long failed = 0;  // sends LCM reported as failed
  auto publish = [&](const std::string& channel, std::vector<std::uint8_t>* bytes,
                     std::int64_t utime) {
    if (!offline && lcm.publish(channel, bytes->data(), unsigned(bytes->size())) != 0) ++failed;
    if (!log) return;
    lcm::LogEvent event{};
    event.timestamp = utime;
    event.channel = channel;
    event.datalen = std::int32_t(bytes->size());
    event.data = bytes->data();
    log->writeEvent(&event);
  };
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  auto next = start;
  std::int64_t seq = 0;
  for (;;) {
    const double t = offline ? double(seq) / rate_hz
                             : std::chrono::duration<double>(Clock::now() - start).count();
    if (t >= duration_s || seq == poses) break;
    static const std::int64_t start_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                                std::chrono::system_clock::now().time_since_epoch())
                                                .count();
    const std::int64_t utime = offline ? start_utime + std::int64_t(std::llround(t * 1e6))
                                       : std::chrono::duration_cast<std::chrono::microseconds>(
                                             std::chrono::system_clock::now().time_since_epoch())
                                             .count();
    sandbox_msgs::robot_pose_t pose;
    sandbox_msgs::bone_values_t bones;
    if (side == 0) {  // the flight itself
      if (flight == "highlands") {
        sandbox::bridge::HighlandsFlight(t + phase_s, seq, utime, &pose, &bones);
      } else {
        sandbox::bridge::ExampleFlight(t + phase_s, seq, utime, &pose, &bones);
      }
    } else {
      sandbox::bridge::WingmanFlight(side, t + phase_s, seq, utime, &pose, &bones);
    }
    // Bones first: a lock-step sandbox ticks on the pose and applies the
    // bones of its seq that have arrived by then.
    std::vector<std::uint8_t> bytes(std::size_t(bones.getEncodedSize()));
    bones.encode(bytes.data(), 0, int(bytes.size()));
    publish(robot + "/BONES", &bytes, utime);
    bytes.resize(std::size_t(pose.getEncodedSize()));
    pose.encode(bytes.data(), 0, int(bytes.size()));
    publish(robot + "/POSE", &bytes, utime);
    ++seq;
    if (offline) continue;
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  std::printf("fly_wing: published %lld poses\n", static_cast<long long>(seq));
  if (failed > 0) {
    std::fprintf(stderr, "fly_wing: %lld sends failed\n", failed);
    return 1;
  }
  return 0;
}
