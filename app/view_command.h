#pragma once
// `sandbox view LOG`: a recorded flight in the browser. The log's inputs are
// replayed in lock-step first (as `sandbox run --replay` does, with its
// progress line), keeping each tick's browser state; then the browser view
// serves them with a player: play, pause, speed, a time slider and a jump to
// a tick (docs/reference/web.md).

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Returns the exit code (0 ok, 1 bad level, log or address, 2 bad usage).
int RunView(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
