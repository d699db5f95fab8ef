#pragma once
// `sandbox pose`: writes a robot posed from the command line as a mesh (PLY)
// and its bone frames (CSV), to check a pose in any mesh viewer.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Runs the command with its arguments (after "pose"); returns the exit code
// (0 ok, 1 bad level or pose, 2 bad usage).
int RunPose(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
