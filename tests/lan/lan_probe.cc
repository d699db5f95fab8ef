// Listens to one robot's channels on a "machine" of the virtual LAN
// (scripts/lan-run) and reports what crossed it: the model's poses (count,
// gaps in seq, latency from the model's stamp), the sandbox's STATE echoes
// (count, gaps, latency from a pose to the first echo of it) and scan
// faces. All namespaces share one clock, so the latencies are exact.
//
//   lan_probe [--robot NAME] [--seconds S] [--idle S] [--lcm-url URL]
//
// It stops after --seconds, or --idle seconds after the last pose heard.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"

namespace {

// Messages on one channel: how many, how many a gap in seq says were lost,
// and each one's latency in ms.
struct Stream {
  std::int64_t heard{0}, lost{0}, last_seq{-1};
  std::vector<double> latency_ms;

  // `sent_utime` <= 0: no latency for this one.
  void Add(std::int64_t seq, std::int64_t sent_utime, std::int64_t receive_utime) {
    if (last_seq >= 0 && seq > last_seq + 1) lost += seq - last_seq - 1;
    last_seq = std::max(last_seq, seq);
    ++heard;
    if (sent_utime > 0) latency_ms.push_back(1e-3 * double(receive_utime - sent_utime));
  }
  double Quantile(double q) {
    if (latency_ms.empty()) return 0.0;
    std::sort(latency_ms.begin(), latency_ms.end());
    return latency_ms[std::size_t(q * double(latency_ms.size() - 1))];
  }
};

struct Probe {
  Stream poses, states;
  std::int64_t faces{0}, last_state_input{-1};
  std::chrono::steady_clock::time_point last_pose;

  void OnPose(const lcm::ReceiveBuffer* buffer, const std::string&,
              const sandbox_msgs::robot_pose_t* pose) {
    poses.Add(pose->seq, pose->utime, buffer->recv_utime);
    last_pose = std::chrono::steady_clock::now();
  }
  void OnState(const lcm::ReceiveBuffer* buffer, const std::string&,
               const sandbox_msgs::robot_state_t* state) {
    // Latency from a pose to the first state computed from it (the sandbox
    // echoes its state every tick, new pose or not).
    const bool fresh = state->input_seq != last_state_input;
    last_state_input = state->input_seq;
    states.Add(state->seq, fresh ? state->input_utime : 0, buffer->recv_utime);
  }
  void OnFace(const lcm::ReceiveBuffer*, const std::string&, const sandbox_msgs::scan_face_t*) {
    ++faces;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string robot = "ELAHA", url;
  double seconds = 60.0, idle_s = 2.0;
  for (int i = 1; i < argc; i += 2) {
    const std::string option = argv[i];
    if (i + 1 >= argc) {
      argc = -1;
      break;
    }
    if (option == "--robot") {
      robot = argv[i + 1];
    } else if (option == "--seconds") {
      seconds = std::atof(argv[i + 1]);
    } else if (option == "--idle") {
      idle_s = std::atof(argv[i + 1]);
    } else if (option == "--lcm-url") {
      url = argv[i + 1];
    } else {
      argc = -1;
      break;
    }
  }
  if (argc < 0) {
    std::fprintf(stderr,
                 "usage: lan_probe [--robot NAME] [--seconds S] [--idle S] [--lcm-url URL]\n");
    return 2;
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "lan_probe: cannot open LCM URL '%s'\n", url.c_str());
    return 1;
  }
  Probe probe;
  lcm.subscribe(robot + "/POSE", &Probe::OnPose, &probe)->setQueueCapacity(10000);
  lcm.subscribe(robot + "/STATE", &Probe::OnState, &probe)->setQueueCapacity(10000);
  lcm.subscribe(robot + "/SCAN_FACE", &Probe::OnFace, &probe)->setQueueCapacity(10000);
  std::printf("lan_probe: listening to %s/POSE, /STATE, /SCAN_FACE\n", robot.c_str());
  std::fflush(stdout);
  using Clock = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  const auto idle = std::chrono::duration<double>(idle_s);
  while (Clock::now() < end) {
    lcm.handleTimeout(100);
    if (probe.poses.heard > 0 && Clock::now() - probe.last_pose > idle) break;
  }
  std::printf(
      "lan_probe: poses %lld heard, %lld lost, latency median %.3f ms p99 %.3f ms; "
      "states %lld heard, %lld lost, pose-to-state median %.3f ms p99 %.3f ms; faces %lld\n",
      static_cast<long long>(probe.poses.heard), static_cast<long long>(probe.poses.lost),
      probe.poses.Quantile(0.5), probe.poses.Quantile(0.99),
      static_cast<long long>(probe.states.heard), static_cast<long long>(probe.states.lost),
      probe.states.Quantile(0.5), probe.states.Quantile(0.99),
      static_cast<long long>(probe.faces));
  return 0;
}
