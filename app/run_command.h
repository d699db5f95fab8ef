#pragma once
// `sandbox run`: the loop. Each tick drains the LCM inputs (newest message per
// channel), applies robot poses, bones and actor placements, runs the sensors
// that are due, and publishes their outputs, the robot state and (once a
// second) a status heartbeat; then waits for the next tick. A late tick is
// followed at once by the next; ticks are never bunched to catch up.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Returns the exit code (0 ok, 1 bad level or LCM, 2 bad usage).
int RunLoop(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
