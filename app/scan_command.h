#pragma once
// `sandbox scan`: runs one sensor once at a pose and writes its samples as CSV
// or PLY (occupied points red, free points green).

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Returns the exit code (0 ok, 1 bad level or scan, 2 bad usage).
int RunScan(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
