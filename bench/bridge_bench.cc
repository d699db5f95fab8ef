// Middleware figures, over real UDP multicast: run it inside a private network
// namespace (scripts/netns-run build/bench/bench_bridge); it refuses otherwise.
//  1. Encode + publish cost of a full face scan (six faces) and the decode cost.
//  2. Loss: full scans published at 100 Hz, received by a subscriber with the
//     documented URL (recv_buf_size=4194304) and, as the reference, with LCM's
//     default socket buffer.
//  3. Pose latency: a model publishing at 1 kHz, a loop at 100 Hz draining and
//     applying the newest pose; the age of the pose at the moment it is applied.
//
//   bench_bridge [--seconds S]   (for the loss run, default 60)

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <thread>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "scene/level.h"
#include "sensors/face_scanner.h"

namespace {

using namespace sandbox;
using Clock = std::chrono::steady_clock;

const char* kGroup = "udpm://239.255.76.67:7667?ttl=0";

using bridge::NowUtime;

// A full scan of the sample level from above the valley.
sensors::FaceScan FullScan() {
  const scene::Level level =
      scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
  const scene::CollisionWorld world(level);
  sensors::FaceScannerConfig config;
  config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner scanner(config);
  sensors::RayCaster caster(1);
  sensors::FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, Eigen::Isometry3d(Eigen::Translation3d(20, -25, 22)), 0, &scan);
  return scan;
}

struct Counter {
  std::atomic<std::int64_t> messages{0}, bytes{0};
  void On(const lcm::ReceiveBuffer* buffer, const std::string&) {
    ++messages;
    bytes += buffer->data_size;
  }
};

// Publishes `scans` full scans at 100 Hz while a subscriber on `url` counts.
std::int64_t Received(const std::string& url, const sensors::SensorOutput& scan, int scans) {
  lcm::LCM subscriber(url);
  Counter counter;
  subscriber.subscribe("BENCH/SCAN_FACE", &Counter::On, &counter);
  std::atomic<bool> done{false};
  std::thread listen([&] {
    while (!done) subscriber.handleTimeout(50);
  });
  bridge::LcmLink link(kGroup);
  bridge::RobotOutputs outputs(link, "BENCH");
  auto next = Clock::now();
  for (int i = 0; i < scans; ++i) {
    outputs.Publish(scan, {"bench", "SCAN_FACE"}, 0, {i, NowUtime()}, NowUtime());
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  done = true;
  listen.join();
  return counter.messages;
}

}  // namespace

int main(int argc, char** argv) {
  if (std::getenv("SANDBOX_IN_NETNS") == nullptr) {
    std::fprintf(stderr,
                 "bench_bridge: run it in a private network namespace: "
                 "scripts/netns-run build/bench/bench_bridge\n");
    return 2;
  }
  double seconds = 60.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--seconds")) seconds = std::atof(argv[i + 1]);
  }
  sensors::FaceScan scan = FullScan();
  for (auto& face : scan.faces) face.tick = 0;  // all six faces count as scanned this tick

  // 1. Encode + publish, decode.
  {
    bridge::LcmLink link(kGroup);
    bridge::RobotOutputs outputs(link, "BENCH");
    const int rounds = 200;
    const auto start = Clock::now();
    const sensors::SensorOutput output = scan;
    for (int i = 0; i < rounds; ++i) {
      outputs.Publish(output, {"bench", "SCAN_FACE"}, 0, {i, 0}, NowUtime());
    }
    const double publish_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count() / rounds;
    // One face encoded, decoded many times.
    sandbox_msgs::scan_face_t face{};
    face.n = scan.n;
    face.num_points = scan.n * scan.n;
    face.occupancy.assign(std::size_t(face.num_points), 1);
    face.num_xyz = 3 * face.num_points;
    face.xyz.assign(std::size_t(face.num_xyz), 1.5f);
    std::vector<std::uint8_t> bytes(std::size_t(face.getEncodedSize()));
    face.encode(bytes.data(), 0, int(bytes.size()));
    const auto decode_start = Clock::now();
    for (int i = 0; i < rounds * 6; ++i) {
      sandbox_msgs::scan_face_t back{};
      back.decode(bytes.data(), 0, int(bytes.size()));
    }
    const double decode_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - decode_start).count() / rounds;
    std::printf(
        "full scan (6 faces, %d points, %.0f KB): encode + publish %.3f ms, decode %.3f ms\n",
        6 * face.num_points, 6.0 * double(bytes.size()) / 1024.0, publish_ms, decode_ms);
  }

  // 2. Loss at 100 Hz.
  const int scans = int(seconds * 100.0);
  const std::int64_t with_buffer = Received(bridge::WithReceiveBuffer(kGroup), scan, scans);
  const std::int64_t reference = Received(kGroup, scan, std::min(scans, 500));
  std::printf(
      "loss, %d full scans at 100 Hz (%.0f s): %lld of %d face messages received with "
      "recv_buf_size=4194304 (%lld lost); reference, default buffer, %d scans: %lld of %d\n",
      scans, seconds, static_cast<long long>(with_buffer), 6 * scans,
      static_cast<long long>(6 * scans - with_buffer), std::min(scans, 500),
      static_cast<long long>(reference), 6 * std::min(scans, 500));

  // 3. Pose latency: model at 1 kHz, loop at 100 Hz.
  {
    std::atomic<bool> done{false};
    std::thread model([&] {
      lcm::LCM lcm(kGroup);
      auto next = Clock::now();
      for (std::int64_t seq = 0; !done; ++seq) {
        sandbox_msgs::robot_pose_t pose{};
        pose.utime = NowUtime();
        pose.seq = seq;
        pose.orientation[0] = 1.0;
        lcm.publish("BENCH/POSE", &pose);
        next += std::chrono::milliseconds(1);
        std::this_thread::sleep_until(next);
      }
    });
    bridge::LcmLink link(kGroup);
    bridge::LatestInput input(link, "BENCH/POSE");
    std::vector<double> ages_ms;
    auto next = Clock::now();
    for (int tick = 0; tick < 500; ++tick) {
      link.Drain();
      if (const auto* bytes = input.TakeNewest()) {
        sandbox_msgs::robot_pose_t pose{};
        pose.decode(bytes->data(), 0, int(bytes->size()));
        if (tick > 10) ages_ms.push_back(double(NowUtime() - pose.utime) / 1e3);
      }
      next += std::chrono::milliseconds(10);
      std::this_thread::sleep_until(next);
    }
    done = true;
    model.join();
    std::sort(ages_ms.begin(), ages_ms.end());
    std::printf(
        "pose latency, model 1 kHz, loop 100 Hz, %zu ticks: age of the applied pose median "
        "%.3f ms, p99 %.3f ms, max %.3f ms (bound: one loop period + 1 ms = 11 ms); "
        "superseded %lld of %lld\n",
        ages_ms.size(), ages_ms[ages_ms.size() / 2], ages_ms[ages_ms.size() * 99 / 100],
        ages_ms.back(), static_cast<long long>(input.superseded()),
        static_cast<long long>(input.received()));
  }
  return 0;
}
