#include "app/process_stats.h"

#include <fstream>
#include <string>

namespace sandbox::app {
namespace {

double StatusFieldMiB(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) / 1024.0;
  }
  return 0.0;
}

}  // namespace

double PeakResidentMiB() { return StatusFieldMiB("VmHWM"); }

}  // namespace sandbox::app
