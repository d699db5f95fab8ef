#pragma once
// `sandbox topics`: a middleware manager's topic table of the LCM network.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

int RunTopics(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
