#include "app/topics_command.h"

#include <iomanip>

#include "app/command_line.h"
#include "bridge/topics.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox topics [--seconds S] [--lcm-url URL]\n"
    "  listens to every LCM channel for S seconds (default 2) and prints, per channel,\n"
    "  the message type, count, rate and mean size (LCM does not say who publishes)\n";

}  // namespace

int RunTopics(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed = ParseArgs(args, "topics", {"--seconds", "--lcm-url"}, {}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help || parsed->level) {
    (parsed->help ? out : err) << kUsage;
    return parsed->help ? 0 : 2;
  }
  try {
    const double seconds = parsed->values.count("--seconds")
                               ? ParseNumbers(parsed->Value("--seconds"), "--seconds").at(0)
                               : 2.0;
    bridge::LcmLink link(parsed->Value("--lcm-url"));
    const auto stats = bridge::ListenToAll(link, seconds);
    out << std::left << std::setw(24) << "channel" << std::setw(20) << "type" << std::right
        << std::setw(10) << "messages" << std::setw(10) << "rate Hz" << std::setw(12)
        << "mean bytes"
        << "\n";
    for (const auto& [channel, s] : stats) {
      out << std::left << std::setw(24) << channel << std::setw(20) << s.type << std::right
          << std::setw(10) << s.messages << std::setw(10) << std::fixed << std::setprecision(1)
          << s.rate_hz() << std::setw(12) << std::setprecision(0)
          << double(s.bytes) / double(s.messages) << "\n";
    }
    if (stats.empty()) out << "(nothing heard in " << seconds << " s)\n";
    return 0;
  } catch (const std::exception& error) {
    err << "sandbox topics: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
