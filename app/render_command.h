#pragma once
// `sandbox render`: one frame from a camera, colour (and depth for payload).

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

int RunRender(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
