#include "bridge/robot_bridge_config.h"

#include <arpa/inet.h>
#include <lcm/lcm.h>

#include <set>

#include "bridge/outputs.h"

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
    config.geodetic_origin_given = true;
  }
  config.stale_after_s = read.Number("stale_after_s", config.stale_after_s);
  if (!(config.stale_after_s > 0.0)) read.Fail("stale_after_s", "'stale_after_s' must be positive");
  config.state_in_pose_convention = read.Flag("state_in_pose_convention", false);
  config.bind_address = read.Text("bind_address", config.bind_address);
  in_addr address{};
  if (inet_pton(AF_INET, config.bind_address.c_str(), &address) != 1) {
    read.Fail("bind_address", "'bind_address' must be an IPv4 address like 127.0.0.1, got '" +
                                  config.bind_address + "'");
  }
  auto port = [&](const std::string& key) {
    const int value = read.Whole(key, 0);
    if (value < 0 || value > 65535) read.Fail(key, "'" + key + "' must be a port, 0 to 65535");
    return value;
  };
  config.net_fdm_port = port("net_fdm_port");
  config.udp_doubles_port = port("udp_doubles_port");
  if (config.net_fdm_port > 0 && config.net_fdm_port == config.udp_doubles_port) {
    read.Fail("udp_doubles_port", "'udp_doubles_port' and 'net_fdm_port' are both " +
                                      std::to_string(config.net_fdm_port));
  }
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
    std::set<std::string> seen;
    for (const std::string& item : config.udp_doubles_layout) {
      if (item != "position" && item != "quaternion" && item != "rpy" && item != "bones" &&
          item != "time" && item != "seq") {
        read.Fail("udp_doubles_layout",
                  "'udp_doubles_layout' items are time, seq, position, quaternion, rpy and "
                  "bones, got '" +
                      item + "'");
      }
      if (!seen.insert(item).second) {
        read.Fail("udp_doubles_layout", "'udp_doubles_layout' names '" + item + "' twice");
      }
    }
    if (seen.count("quaternion") && seen.count("rpy")) {
      read.Fail("udp_doubles_layout", "'udp_doubles_layout' takes quaternion or rpy, not both");
    }
    if (config.udp_doubles_layout.empty()) {
      read.Fail("udp_doubles_layout", "'udp_doubles_layout' must name at least one item");
    }
  }
  config.udp_doubles_big_endian = read.Flag("udp_doubles_big_endian", false);
  read.RejectUnknownKeys("robot bridge");
  return config;
}

std::vector<RobotBridgeConfig> RobotBridgeConfigs(const scene::Level& level) {
  std::vector<RobotBridgeConfig> configs;
  std::map<std::string, std::string> prefixes;  // prefix -> robot
  std::map<int, std::string> ports;             // UDP port -> robot
  for (const scene::RobotModel& model : level.robots) {
    RobotBridgeConfig config = RobotBridgeConfig::FromModel(model);
    const scene::SettingsReader read(model.bridge);
    if (level.terrain && config.pose.convention == Convention::kGeodetic) {
      // Geodetic poses land on the terrain where its rasters say: one anchor for both.
      const scene::GeodeticPoint& anchor = level.terrain->anchor;
      const GeodeticOrigin terrain{anchor.latitude_deg, anchor.longitude_deg, anchor.height_m};
      if (!config.geodetic_origin_given) {
        config.pose.origin = terrain;
      } else if (config.pose.origin.latitude_deg != terrain.latitude_deg ||
                 config.pose.origin.longitude_deg != terrain.longitude_deg ||
                 config.pose.origin.altitude_m != terrain.altitude_m) {
        read.Fail("geodetic_origin",
                  "'geodetic_origin' differs from the [[terrain]] anchor; leave it out (the "
                  "anchor is taken) or make them equal, or poses will not land where the "
                  "rasters say");
      }
    }
    if (const auto [it, fresh] = prefixes.emplace(config.channel_prefix, model.name); !fresh) {
      read.Fail("channel_prefix", "robot '" + model.name + "' would use the channel prefix '" +
                                      config.channel_prefix + "' of robot '" + it->second +
                                      "'; give one of them its own 'channel_prefix'");
    }
    // LCM carries channel names of at most LCM_MAX_CHANNEL_NAME_LENGTH bytes, without NUL.
    auto too_long = [&](const std::string& topic) -> std::string {
      const std::string channel = config.channel_prefix + "/" + topic;
      if (channel.size() <= LCM_MAX_CHANNEL_NAME_LENGTH && channel.find('\0') == std::string::npos)
        return "";
      return "robot '" + model.name + "' would use the channel '" + channel + "' (" +
             std::to_string(channel.size()) + " bytes); LCM carries names of at most " +
             std::to_string(LCM_MAX_CHANNEL_NAME_LENGTH) + " bytes, without NUL";
    };
    for (const char* topic : {"POSE", "BONES", "JOINTS", "ACTORS", "CAMERA", "STATE", "STATUS"}) {
      if (const std::string why = too_long(topic); !why.empty())
        read.Fail("channel_prefix", why + ": give it a shorter 'channel_prefix'");
    }
    for (const scene::SensorSpec& spec : model.sensors) {
      if (const std::string why = too_long(sensors::OutputChannel(spec)); !why.empty())
        throw scene::LevelError(spec.Where() + why + ": give the sensor a shorter 'channel'");
    }
    for (const auto& [key, value] :
         {std::pair<const char*, int>{"net_fdm_port", config.net_fdm_port},
          {"udp_doubles_port", config.udp_doubles_port}}) {
      if (value == 0) continue;
      if (const auto [it, fresh] = ports.emplace(value, model.name); !fresh) {
        read.Fail(key, "port " + std::to_string(value) + " is taken by robot '" + it->second + "'");
      }
    }
    configs.push_back(std::move(config));
  }
  CheckOutputChannels(level);
  if (!WorldAnchor(level, configs)) {
    for (const scene::RobotModel& model : level.robots) {
      for (const scene::SensorSpec& spec : model.sensors) {
        if (sensors::ParseSensorKind(spec) != sensors::SensorKind::kGnss) continue;
        throw scene::LevelError(spec.settings.Where("type") +
                                "a gnss sensor needs the world's geodetic anchor: give the level "
                                "a [[terrain]] (its anchor) or a robot a geodetic_origin");
      }
    }
  }
  return configs;
}

std::optional<scene::GeodeticPoint> WorldAnchor(const scene::Level& level,
                                                const std::vector<RobotBridgeConfig>& configs) {
  if (level.terrain) return level.terrain->anchor;
  for (const RobotBridgeConfig& config : configs) {
    if (!config.geodetic_origin_given) continue;
    const GeodeticOrigin& origin = config.pose.origin;
    return scene::GeodeticPoint{origin.latitude_deg, origin.longitude_deg, origin.altitude_m};
  }
  return std::nullopt;
}

}  // namespace sandbox::bridge
