#pragma once
// `sandbox bench-frames`: the evaluation matrix a user of such a platform
// reports. {empty level, sample level} x {robot only, + face scanner,
// + scanner and debug overlay}: each frame flies the example flight one step
// (pose and 24 bones), moves the robot's collision body, scans when asked,
// publishes the outputs (memq://) and renders the chase camera (640 x 480)
// to the end. 3 runs of 500 frames per case; a table of frame-duration
// statistics, a CSV of every frame and one plot per case.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Returns the exit code (0 ok, 1 failure, 2 bad usage).
int RunBenchFrames(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
