// Waits for <ROBOT>/STATE from a running sandbox and checks that the robot
// stands at the expected world position. Exit 0 when it does.
//
//   state_check ROBOT X Y Z TOLERANCE_M [--seconds S]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "sandbox_msgs/robot_state_t.hpp"

struct Last {
  bool any{false};
  double p[3]{0, 0, 0};
  void On(const lcm::ReceiveBuffer*, const std::string&, const sandbox_msgs::robot_state_t* m) {
    if (m->input_seq <= 0) return;  // still the spawn pose
    any = true;
    for (int k = 0; k < 3; ++k) p[k] = m->position[k];
  }
};

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: state_check ROBOT X Y Z TOLERANCE_M [--seconds S]\n");
    return 2;
  }
  const double expected[3] = {std::atof(argv[2]), std::atof(argv[3]), std::atof(argv[4])};
  const double tolerance = std::atof(argv[5]);
  const double seconds = argc > 7 && !std::strcmp(argv[6], "--seconds") ? std::atof(argv[7]) : 3.0;
  lcm::LCM lcm("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  Last last;
  lcm.subscribe(std::string(argv[1]) + "/STATE", &Last::On, &last);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) lcm.handleTimeout(50);
  const double error =
      std::hypot(last.p[0] - expected[0], last.p[1] - expected[1], last.p[2] - expected[2]);
  std::printf(
      "state_check: robot at (%.3f, %.3f, %.3f), expected (%.3f, %.3f, %.3f), off by %.4f m\n",
      last.p[0], last.p[1], last.p[2], expected[0], expected[1], expected[2], error);
  return last.any && error <= tolerance ? 0 : 1;
}
