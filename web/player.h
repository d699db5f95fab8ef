#pragma once
// The playhead of a recorded run in the browser (`sandbox view`): which tick
// the page is shown, moved by the page's commands (play, pause, speed, seek)
// and by time while playing, at `speed` times the run's own clock. One
// playhead for every client: what one does, all see.

#include <cstddef>
#include <vector>

#include "web/commands.h"

namespace sandbox::web {

class Playhead {
 public:
  // The ticks' times (seconds, not decreasing); paused at the first.
  explicit Playhead(std::vector<double> times_s);

  // A command at wall time now_s (a seek past the ends goes to the end).
  void Apply(const PlayerCommand& command, double now_s);
  // The tick to show at wall time now_s: playing, the last tick whose time is
  // reached (and paused at the end); paused, the one it stopped at.
  std::size_t At(double now_s);

  bool playing() const { return playing_; }
  double speed() const { return speed_; }
  std::size_t ticks() const { return times_s_.size(); }

 private:
  std::vector<double> times_s_;
  bool playing_{false};
  double speed_{1.0};
  std::size_t tick_{0};     // where it was at anchor_s_
  double anchor_s_{0.0};    // wall time of the last command
};

}  // namespace sandbox::web
