#pragma once
// How a robot is connected ([robot.bridge] in the level manifest; every key is
// optional): channel names, the convention its pose publisher speaks, when an
// input counts as stale, and the UDP adapters for senders without LCM.
//
//   [robot.bridge]
//   channel_prefix = "ELAHA"          # channels <prefix>/POSE, ... (default: the robot name)
//   pose_convention = "enu"           # enu, ned, unreal, geodetic
//   geodetic_origin = [47.0, 8.0, 500.0]   # lat, lon (deg), alt (m) of the world origin
//   stale_after_s = 0.5
//   state_in_pose_convention = false  # STATE's pose in pose_convention instead of world ENU
//   bind_address = "127.0.0.1"        # for the UDP adapters
//   net_fdm_port = 5505               # FlightGear net_fdm v24 (0: off); pose is geodetic
//   net_fdm_elevator = ["E1", "E2", "E3"]   # bones driven by a control surface
//   net_fdm_max_deflection_deg = 25   # surface 1.0 turns those bones this far
//   udp_doubles_port = 0              # a plain vector of doubles (0: off)
//   udp_doubles_layout = ["position", "quaternion", "bones"]   # or "rpy" for roll, pitch, yaw
//   udp_doubles_big_endian = false

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bridge/translation.h"
#include "scene/geodetic.h"
#include "scene/level.h"
#include "scene/robot_model.h"

namespace sandbox::bridge {

struct RobotBridgeConfig {
  std::string channel_prefix;
  Translation pose;
  bool geodetic_origin_given{false};  // else, on a level with [[terrain]], its anchor
  double stale_after_s{0.5};
  bool state_in_pose_convention{false};
  std::string bind_address{"127.0.0.1"};
  int net_fdm_port{0};
  // net_fdm surface field ("elevator", "left_aileron", ...) -> bone-map indices.
  std::map<std::string, std::vector<int>> net_fdm_surfaces;
  double net_fdm_max_deflection_rad{25.0 * M_PI / 180.0};
  int udp_doubles_port{0};
  std::vector<std::string> udp_doubles_layout{"position", "quaternion", "bones"};
  bool udp_doubles_big_endian{false};

  // Reads the robot's [robot.bridge] settings. Throws scene::LevelError naming
  // the manifest, line and key: an unknown key or convention, a port out of
  // range, a bind address that is no IPv4 address, a surface bone that is not
  // in the bone map or has no angle, a UDP layout that repeats or mixes items.
  static RobotBridgeConfig FromModel(const scene::RobotModel& model);
};

// Every robot's bridge settings, checked together as `sandbox run` needs
// them: each robot's own, no two robots on one channel prefix, no UDP port
// taken twice, no two sensors of a robot on one channel
// (CheckOutputChannels). Throws scene::LevelError naming both sides.
// A gnss sensor on a level without a geodetic anchor is refused here too.
std::vector<RobotBridgeConfig> RobotBridgeConfigs(const scene::Level& level);

// The world's geodetic anchor (the world origin's WGS84 point): the
// [[terrain]]'s, else the first robot's geodetic_origin; none without either.
std::optional<scene::GeodeticPoint> WorldAnchor(const scene::Level& level,
                                                const std::vector<RobotBridgeConfig>& configs);

}  // namespace sandbox::bridge
