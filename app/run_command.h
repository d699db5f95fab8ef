#pragma once
// `sandbox run`: the loop. Each tick drains the LCM inputs (newest message per
// channel), applies robot poses, bones and actor placements, runs the sensors
// that are due, and publishes their outputs, the robot state and (once a
// second) a status heartbeat; then waits for the next tick. A late tick is
// followed at once by the next; ticks are never bunched to catch up.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"

namespace sandbox::app {

// In-process additions to the loop (the demo's fallback pilot).
struct RunHooks {
  // Called at the start of each tick, before the inputs are drained, with the
  // seconds since the loop started.
  std::function<void(bridge::LcmLink& link, double wall_s)> before_tick;
  // Called before the link closes (however the loop ends): let go of what
  // before_tick subscribed.
  std::function<void(bridge::LcmLink& link)> before_close;
};

// Returns the exit code (0 ok, 1 bad level or LCM, 2 bad usage).
int RunLoop(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
            const RunHooks& hooks = {});

}  // namespace sandbox::app
