// Floods a robot's input channels (POSE, BONES, ACTORS, CAMERA) with what a
// broken or hostile publisher sends: random bytes, the right fingerprint with
// a negative or huge count, oversized messages (64 KB to 1 MB, in LCM
// fragments), NaN poses, long quaternions, wrong bone counts, unknown actors.
// Nothing it sends is a good message. Prints how many it sent.
//
//   flood ROBOT [--seconds S] [--rate HZ] [--lcm-url URL]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

template <typename Message>
Bytes Encode(const Message& message) {
  Bytes bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  return bytes;
}

void PutInt32(std::int32_t value, std::size_t at, Bytes* bytes) {
  for (int i = 3; i >= 0; --i, value = std::int32_t(std::uint32_t(value) >> 8)) {
    (*bytes)[at + std::size_t(i)] = std::uint8_t(value);
  }
}

// One bad message for the channel `kind` (0 POSE, 1 BONES, 2 ACTORS, 3 CAMERA).
Bytes Bad(int kind, std::mt19937& random) {
  const int what = int(random() % 100);
  Bytes bytes;
  if (what < 30) {  // random bytes
    bytes.resize(1 + random() % 200);
    for (auto& b : bytes) b = std::uint8_t(random());
    return bytes;
  }
  if (what < 31) {  // oversized, the right fingerprint first
    bytes.resize((64u << 10) + random() % (960u << 10));
    for (auto& b : bytes) b = std::uint8_t(random());
    const Bytes head = Encode(sandbox_msgs::bone_values_t{});
    std::copy(head.begin(), head.begin() + 8, bytes.begin());
    return bytes;
  }
  sandbox_msgs::robot_pose_t pose{};
  pose.orientation[0] = 1;
  sandbox_msgs::bone_values_t bones{};
  sandbox_msgs::actor_placements_t actors{};
  actors.num_actors = 1, actors.names = {"gate"};
  actors.num_positions = 3, actors.positions = {0, 0, 0};
  actors.num_orientations = 4, actors.orientations = {1, 0, 0, 0};
  sandbox_msgs::camera_command_t camera{};
  camera.zoom = 1;
  switch (kind) {
    case 0:  // NaN, or a long quaternion
      if (what % 2)
        pose.position[0] = std::nan("");
      else
        pose.orientation[1] = 1;
      return Encode(pose);
    case 1:  // a negative or huge count, or the wrong number of values
      bones.num_values = 3, bones.values = {0, 0, 0};
      bytes = Encode(bones);
      if (what % 3 == 0) PutInt32(-7, 24, &bytes);
      if (what % 3 == 1) PutInt32(0x7fffffff, 24, &bytes);
      return bytes;
    case 2:  // an unknown actor, a static one, or a huge name count
      actors.names = {what % 2 ? "drawbridge" : "wall"};
      bytes = Encode(actors);
      if (what % 5 == 0) PutInt32(100000000, 24, &bytes);
      return bytes;
    default:  // a zero zoom, an unknown camera
      camera.zoom = 0;
      if (what % 2) camera.zoom = 1, camera.active_camera = "periscope";
      return Encode(camera);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: flood ROBOT [--seconds S] [--rate HZ] [--lcm-url URL]\n");
    return 2;
  }
  const std::string robot = argv[1];
  double seconds = 10, rate_hz = 4000;
  std::string url;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--seconds")) seconds = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--rate")) rate_hz = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--lcm-url")) url = argv[i + 1];
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) return 1;
  const char* channels[4] = {"/POSE", "/BONES", "/ACTORS", "/CAMERA"};
  std::mt19937 random(42);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  auto next = start;
  long long sent[4] = {0, 0, 0, 0}, bytes_sent = 0;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    const int kind = int(random() % 4);
    const Bytes bytes = Bad(kind, random);
    if (lcm.publish(robot + channels[kind], bytes.data(), unsigned(bytes.size())) == 0) {
      ++sent[kind];
      bytes_sent += static_cast<long long>(bytes.size());
    }
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  std::printf("flood: %lld POSE, %lld BONES, %lld ACTORS, %lld CAMERA (%lld MB)\n", sent[0],
              sent[1], sent[2], sent[3], bytes_sent >> 20);
  return 0;
}
