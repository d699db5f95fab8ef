#include "web/commands.h"

#include <nlohmann/json.hpp>

namespace sandbox::web {
namespace {

// The object `text` is, of type `type`; throws naming what is wrong.
nlohmann::json CommandObject(std::string_view text, const std::string& type) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    throw std::invalid_argument("a " + type + " command must be a JSON object");
  if (json.value("type", nlohmann::json()) != type)
    throw std::invalid_argument("'type' must be \"" + type + "\"");
  return json;
}

}  // namespace

PlayerCommand ParsePlayerCommand(std::string_view text) {
  const nlohmann::json json = CommandObject(text, "player");
  PlayerCommand command;
  for (const auto& [key, value] : json.items()) {
    if (key == "type") continue;
    if (key == "play") {
      if (!value.is_boolean()) throw std::invalid_argument("'play' must be true or false");
      command.play = value.get<bool>();
    } else if (key == "speed") {
      if (!value.is_number() || !(value.get<double>() >= 0.01 && value.get<double>() <= 100.0))
        throw std::invalid_argument("'speed' must be a number from 0.01 to 100");
      command.speed = value.get<double>();
    } else if (key == "seek") {
      if (!value.is_number_integer() || value.get<std::int64_t>() < 0)
        throw std::invalid_argument("'seek' must be a tick, a whole number from 0");
      command.seek = value.get<std::int64_t>();
    } else {
      throw std::invalid_argument("unknown field '" + key + "' (play, speed, seek)");
    }
  }
  return command;
}

std::string ParseCameraCommand(std::string_view text) {
  const nlohmann::json json = CommandObject(text, "camera");
  for (const auto& [key, value] : json.items()) {
    if (key != "type" && key != "key") throw std::invalid_argument("unknown field '" + key + "' (key)");
  }
  const auto key = json.find("key");
  if (key == json.end() || !key->is_string())
    throw std::invalid_argument("'key' must be one of next_camera, pan_left, pan_right, tilt_up, "
                                "tilt_down, zoom_in, zoom_out, overlay");
  for (const char* known : kCameraKeys) {
    if (*key == known) return known;
  }
  throw std::invalid_argument("'key' must be one of next_camera, pan_left, pan_right, tilt_up, "
                              "tilt_down, zoom_in, zoom_out, overlay, got '" +
                              key->get<std::string>() + "'");
}

}  // namespace sandbox::web
