#include "web/player.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sandbox::web {

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
