#include "bridge/robot_bridge_config.h"

namespace sandbox::bridge {
namespace {

const char* kSurfaces[] = {"elevator",     "elevator_trim_tab", "left_flap", "right_flap",
                           "left_aileron", "right_aileron",     "rudder",    "nose_wheel",
                           "speedbrake",   "spoilers"};

}  // namespace

RobotBridgeConfig RobotBridgeConfig::FromModel(const scene::RobotModel& model) {
  scene::SettingsReader read(model.bridge);
  RobotBridgeConfig config;
  config.channel_prefix = read.Text("channel_prefix", model.name);
  if (config.channel_prefix.empty())
    read.Fail("channel_prefix", "'channel_prefix' must not be empty");
  const std::string convention = read.Text("pose_convention", "enu");
  const auto parsed = ParseConvention(convention);
  if (!parsed) {
    read.Fail("pose_convention",
              "'pose_convention' must be enu, ned, unreal or geodetic, got '" + convention + "'");
  }
  config.pose.convention = *parsed;
  const std::vector<double> origin = read.Numbers("geodetic_origin");
  if (!origin.empty()) {
    if (origin.size() != 3 || std::abs(origin[0]) > 90.0) {
      read.Fail("geodetic_origin",
                "'geodetic_origin' must be [latitude_deg, longitude_deg, altitude_m]");
    }
    config.pose.origin = {origin[0], origin[1], origin[2]};
  }
  config.stale_after_s = read.Number("stale_after_s", config.stale_after_s);
  if (!(config.stale_after_s > 0.0)) read.Fail("stale_after_s", "'stale_after_s' must be positive");
  config.state_in_pose_convention = read.Flag("state_in_pose_convention", false);
  config.bind_address = read.Text("bind_address", config.bind_address);
  auto port = [&](const std::string& key) {
    const int value = read.Whole(key, 0);
    if (value < 0 || value > 65535) read.Fail(key, "'" + key + "' must be a port, 0 to 65535");
    return value;
  };
  config.net_fdm_port = port("net_fdm_port");
  config.udp_doubles_port = port("udp_doubles_port");
  config.net_fdm_max_deflection_rad =
      read.Number("net_fdm_max_deflection_deg", 25.0) * M_PI / 180.0;
  for (const char* surface : kSurfaces) {
    const std::string key = std::string("net_fdm_") + surface;
    for (const std::string& bone : read.Texts(key)) {
      const int index = model.FindBone(bone);
      if (index < 0)
        read.Fail(key, "'" + key + "' names bone '" + bone + "', which is not in the bone map");
      if (model.bones[std::size_t(index)].rotation != scene::BoneRotation::kAngles) {
        read.Fail(key, "bone '" + bone + "' must take angles to follow a control surface");
      }
      config.net_fdm_surfaces[surface].push_back(index);
    }
  }
  if (read.Has("udp_doubles_layout")) {
    config.udp_doubles_layout = read.Texts("udp_doubles_layout");
    for (const std::string& item : config.udp_doubles_layout) {
      if (item != "position" && item != "quaternion" && item != "rpy" && item != "bones") {
        read.Fail("udp_doubles_layout",
                  "'udp_doubles_layout' items are position, quaternion, rpy and bones, got '" +
                      item + "'");
      }
    }
  }
  config.udp_doubles_big_endian = read.Flag("udp_doubles_big_endian", false);
  read.RejectUnknownKeys("robot bridge");
  return config;
}

}  // namespace sandbox::bridge
