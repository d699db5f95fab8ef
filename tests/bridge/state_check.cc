// Waits for what a running sandbox publishes about a robot, and exits 0 as
// soon as it shows what is expected (1 when nothing does within S seconds):
//
//   state_check ROBOT X Y Z TOLERANCE_M [--seconds S]
//       <ROBOT>/STATE: the robot, moved by an external pose, within
//       TOLERANCE_M of the world position (X, Y, Z);
//   state_check ROBOT --seq N [--seconds S]
//       <ROBOT>/STATE: computed from the pose input with seq N or later;
//   state_check ROBOT --good N [--seconds S]
//       <ROBOT>/STATUS: at least N good messages (received and not rejected)
//       on <ROBOT>/POSE.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "tests/bridge/receive.h"

struct Watch {
  std::string robot;
  double expected[3]{0, 0, 0};
  double tolerance{0};
  long long want_good{-1};  // >= 0: watch STATUS instead
  long long want_seq{-1};   // >= 0: watch STATE for this input seq
  bool any{false}, there{false};
  double p[3]{0, 0, 0};
  long long good{0};

  void OnState(const lcm::ReceiveBuffer* buffer, const std::string&) {
    sandbox_msgs::robot_state_t m;
    if (!sandbox::testing::Decode(buffer, &m) ||
        m.input_seq <= 0) {  // not a state, or still the spawn pose
      return;
    }
    any = true;
    for (int k = 0; k < 3; ++k) p[k] = m.position[k];
    if (want_seq >= 0) {
      there = there || m.input_seq >= want_seq;
    } else {
      there = there || Error() <= tolerance;
    }
  }
  void OnStatus(const lcm::ReceiveBuffer* buffer, const std::string&) {
    sandbox_msgs::status_t m;
    if (!sandbox::testing::Decode(buffer, &m)) {
      return;
    }
    const int c = sandbox::testing::StatusColumn(m, robot + "/POSE");
    if (c >= 0) good = m.received[std::size_t(c)] - m.rejected[std::size_t(c)];
    there = there || good >= want_good;
  }
  double Error() const {
    return std::hypot(p[0] - expected[0], p[1] - expected[1], p[2] - expected[2]);
  }
};

int main(int argc, char** argv) {
  const bool status = argc >= 4 && !std::strcmp(argv[2], "--good");
  const bool seq = argc >= 4 && !std::strcmp(argv[2], "--seq");
  if (argc < 6 && !status && !seq) {
    std::fprintf(stderr,
                 "usage: state_check ROBOT X Y Z TOLERANCE_M [--seconds S]\n"
                 "       state_check ROBOT --seq N [--seconds S]\n"
                 "       state_check ROBOT --good N [--seconds S]\n");
    return 2;
  }
  Watch watch;
  watch.robot = argv[1];
  int next = 6;
  if (status || seq) {
    (status ? watch.want_good : watch.want_seq) = std::atoll(argv[3]);
    next = 4;
  } else {
    for (int k = 0; k < 3; ++k) watch.expected[k] = std::atof(argv[2 + k]);
    watch.tolerance = std::atof(argv[5]);
  }
  const double seconds =
      argc > next + 1 && !std::strcmp(argv[next], "--seconds") ? std::atof(argv[next + 1]) : 3.0;
  lcm::LCM lcm("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  if (status) {
    lcm.subscribe(watch.robot + "/STATUS", &Watch::OnStatus, &watch);
  } else {
    lcm.subscribe(watch.robot + "/STATE", &Watch::OnState, &watch);
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!watch.there && std::chrono::steady_clock::now() < end) lcm.handleTimeout(50);
  if (status) {
    std::printf("state_check: %s/POSE %lld good messages received, expected %lld\n",
                watch.robot.c_str(), watch.good, watch.want_good);
  } else if (seq) {
    std::printf("state_check: %s/STATE %s input seq %lld\n", watch.robot.c_str(),
                watch.there ? "reached" : "did not reach", watch.want_seq);
  } else {
    std::printf(
        "state_check: robot at (%.3f, %.3f, %.3f), expected (%.3f, %.3f, %.3f), off by %.4f m\n",
        watch.p[0], watch.p[1], watch.p[2], watch.expected[0], watch.expected[1], watch.expected[2],
        watch.Error());
  }
  return watch.there ? 0 : 1;
}
