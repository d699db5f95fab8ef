#include "web/player.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

namespace sandbox::web {

PlayerCommand ParsePlayerCommand(std::string_view text) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    throw std::invalid_argument("a player command must be a JSON object");
  if (json.value("type", nlohmann::json()) != "player")
    throw std::invalid_argument("'type' must be \"player\"");
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

Playhead::Playhead(std::vector<double> times_s) : times_s_(std::move(times_s)) {
  if (times_s_.empty()) throw std::invalid_argument("a playhead needs at least one tick");
}

void Playhead::Apply(const PlayerCommand& command, double now_s) {
  tick_ = At(now_s);  // where it is now: the anchor of what follows
  anchor_s_ = now_s;
  if (command.seek) tick_ = std::min<std::size_t>(std::size_t(*command.seek), times_s_.size() - 1);
  if (command.speed) speed_ = *command.speed;
  if (command.play) playing_ = *command.play && tick_ + 1 < times_s_.size();
  if (command.play && *command.play && !playing_) {  // play at the end: from the start
    tick_ = 0;
    playing_ = times_s_.size() > 1;
  }
}

std::size_t Playhead::At(double now_s) {
  if (!playing_) return tick_;
  const double t = times_s_[tick_] + (now_s - anchor_s_) * speed_;
  const std::size_t at =
      std::size_t(std::upper_bound(times_s_.begin() + std::ptrdiff_t(tick_), times_s_.end(), t) -
                  times_s_.begin()) - 1;
  if (at + 1 >= times_s_.size()) {  // the end: paused there
    playing_ = false;
    tick_ = times_s_.size() - 1;
    anchor_s_ = now_s;
    return tick_;
  }
  return at;
}

}  // namespace sandbox::web
