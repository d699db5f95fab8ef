// Fuzz target: every LCM message the sandbox reads, as bytes off the network.
// - the checked decoder of every type: what it accepts, lcm-gen's decoder
//   reads exactly (encoding it again gives the same bytes);
// - a robot's four inputs (POSE, BONES, ACTORS, CAMERA) of the sample level,
//   each handed the bytes as its subscription would, then applied to the
//   robot state and the collision world, as the loop does.

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bridge/checked_decode.h"
#include "bridge/robot_inputs.h"
#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace {

using namespace sandbox;

// A message the checked decoder accepts must be read exactly.
template <typename Message>
void DecodeExactly(const std::uint8_t* data, std::size_t size) {
  Message message{};
  if (!bridge::DecodeChecked(data, size, &message).empty()) return;
  std::vector<std::uint8_t> again(std::size_t(message.getEncodedSize()));
  message.encode(again.data(), 0, int(again.size()));
  if (again.size() != size || !std::equal(again.begin(), again.end(), data)) std::abort();
}

struct World {
  scene::Level level = scene::LoadLevel(SANDBOX_SAMPLE_LEVEL);
  scene::CollisionWorld world{level};
  scene::RobotState state{level.robots.at(0)};
  bridge::LcmLink link{"memq://"};
  bridge::RobotInputs inputs{link, level, 0};
};

World& TheWorld() {
  static World* world = new World();  // kept for the process (the fuzzer never exits cleanly)
  return *world;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  TheWorld();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sandbox_msgs;
  DecodeExactly<robot_pose_t>(data, size);
  DecodeExactly<bone_values_t>(data, size);
  DecodeExactly<actor_placements_t>(data, size);
  DecodeExactly<camera_command_t>(data, size);
  DecodeExactly<ground_map_t>(data, size);
  DecodeExactly<imu_t>(data, size);
  DecodeExactly<gnss_t>(data, size);
  DecodeExactly<air_data_t>(data, size);
  DecodeExactly<lidar_scan_t>(data, size);
  DecodeExactly<range_t>(data, size);
  DecodeExactly<robot_state_t>(data, size);
  DecodeExactly<scan_face_t>(data, size);
  DecodeExactly<status_t>(data, size);
  DecodeExactly<surface_table_t>(data, size);
  DecodeExactly<wrench_t>(data, size);

  World& w = TheWorld();
  for (const bridge::LatestInput* input :
       {&w.inputs.pose(), &w.inputs.bones(), &w.inputs.actors(), &w.inputs.camera()}) {
    const_cast<bridge::LatestInput*>(input)->OnMessage(data, unsigned(size), 1);
  }
  const bridge::RobotInputs::Applied applied = w.inputs.Apply(&w.state, &w.world);
  if (applied.pose || applied.bones) {
    w.state.Update();
    w.world.UpdateRobot(0, w.state);
  }
  return 0;
}
