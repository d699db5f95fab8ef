#pragma once
// `sandbox run`: the command line of the loop (app/sandbox_loop.h).

#include <ostream>
#include <string>
#include <vector>

#include "app/run_hooks.h"

namespace sandbox::app {

// Returns the exit code (0 ok, 1 bad level, LCM URL, log or folder, 2 bad usage).
int RunLoop(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
            const RunHooks& hooks = {});

}  // namespace sandbox::app
