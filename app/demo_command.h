#pragma once
// `sandbox demo`: the README's main command. The sample level with the flying
// wing flown by the example model (examples/fly_wing) as a separate process
// over LCM, inside a private network namespace (scripts/netns-run) so that
// nothing reaches the LAN; where no namespace can be made, the model flies in
// the sandbox's own process over memq://. Face scanner on, chase, trailing and
// belly cameras writing JPEG and an mp4 each, the face scan as PLY every
// second, frame statistics and their plot; it ends by saying where
// everything is.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

// Returns the exit code (0 ok, 1 failure, 2 bad usage).
int RunDemo(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
