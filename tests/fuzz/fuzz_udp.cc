// Fuzz target: the Simulink-friendly UDP decoders, as datagrams arrive: the
// FlightGear net_fdm packet, and plain doubles in each layout a robot may
// configure (the first byte picks one), applied to the flying wing's state.

#include <cstdint>
#include <vector>

#include "bridge/net_fdm.h"
#include "bridge/udp_inputs.h"
#include "scene/level.h"

namespace {

using namespace sandbox;

struct Wing {
  scene::Level level = scene::LoadLevel(SANDBOX_SAMPLE_LEVEL);
  scene::RobotState state{level.robots.at(0)};
};

Wing& TheWing() {
  static Wing* wing = new Wing();
  return *wing;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  TheWing();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  bridge::NetFdm fdm;
  bridge::DecodeNetFdm(data, size, &fdm);
  if (size == 0) return 0;
  static const std::vector<std::vector<std::string>> layouts = {
      {"position", "quaternion", "bones"}, {"position", "rpy"}, {"bones"}, {"rpy", "position"}};
  bridge::RobotBridgeConfig config;
  config.udp_doubles_layout = layouts[data[0] % layouts.size()];
  config.udp_doubles_big_endian = (data[0] & 0x10) != 0;
  config.pose.convention =
      (data[0] & 0x20) != 0 ? bridge::Convention::kNed : bridge::Convention::kEnu;
  Wing& wing = TheWing();
  Eigen::Isometry3d X_WB;
  std::vector<double> bones;
  if (bridge::DecodeDoubles(config, wing.state.model().num_values, data + 1, size - 1,
                            wing.state.pose(), &X_WB, &bones)
          .empty()) {
    wing.state.SetPose(X_WB);
    if (!bones.empty()) wing.state.SetBones(bones);
    wing.state.Update();
  }
  return 0;
}
