#pragma once
// `sandbox info LEVEL [--json]`: what a level holds and what loading it cost.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Runs the command with its arguments (after "info"). Prints to `out`, errors
// to `err`; returns the process exit code (0 ok, 1 bad level, 2 bad usage).
int RunInfo(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
