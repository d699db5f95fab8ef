#pragma once
// `sandbox convert IN OUT`: a recording from one format to the other (an LCM
// log to MCAP, or back), event by event.

#include <ostream>
#include <string>
#include <vector>

namespace sandbox::app {

int RunConvert(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
