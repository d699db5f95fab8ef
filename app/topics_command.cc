#include "app/topics_command.h"

#include <iomanip>

#include "app/command_line.h"
#include "bridge/topics.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox topics [--seconds S] [--lcm-url URL] | --log FILE\n"
    "  listens to every LCM channel for S seconds (default 2) and prints, per channel,\n"
    "  the message type, count, rate and mean size (LCM does not say who publishes);\n"
    "  --log FILE: the same for the events of an LCM log (rates by the events' times)\n";

}  // namespace

int RunTopics(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed =
      ParseArgs(args, "topics", {"--seconds", "--lcm-url", "--log"}, {}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help || parsed->level) {
    (parsed->help ? out : err) << kUsage;
    return parsed->help ? 0 : 2;
  }
  try {
    const std::string log = parsed->Value("--log");
    if (!log.empty() && (parsed->values.count("--seconds") || parsed->values.count("--lcm-url"))) {
      throw UsageError("--log reads a file: it takes no --seconds or --lcm-url");
    }
    const double seconds = parsed->values.count("--seconds")
                               ? ParseNumber(parsed->Value("--seconds"), "--seconds")
                               : 2.0;
    if (!(seconds > 0.0 && seconds <= 86400.0)) {
      throw UsageError("--seconds must be above 0 and at most 86400");
    }
    std::string stopped_early;
    std::map<std::string, bridge::ChannelStats> stats;
    if (log.empty()) {
      bridge::LcmLink link(parsed->Value("--lcm-url"));
      stats = bridge::ListenToAll(link, seconds);
    } else {
      stats = bridge::ReadLogTopics(log, &stopped_early);
    }
    out << std::left << std::setw(24) << "channel" << std::setw(20) << "type" << std::right
        << std::setw(10) << "messages" << std::setw(10) << "rate Hz" << std::setw(12)
        << "mean bytes"
        << "\n";
    for (const auto& [channel, s] : stats) {
      out << std::left << std::setw(24) << bridge::Printable(channel, 64) << std::setw(20) << s.type
          << std::right << std::setw(10) << s.messages << std::setw(10) << std::fixed
          << std::setprecision(1) << s.rate_hz() << std::setw(12) << std::setprecision(0)
          << double(s.bytes) / double(s.messages) << "\n";
    }
    if (stats.empty() && log.empty()) out << "(nothing heard in " << seconds << " s)\n";
    if (stats.empty() && !log.empty()) out << "(no events in " << log << ")\n";
    if (!stopped_early.empty()) {
      err << "sandbox topics: the log '" << log << "' is " << stopped_early << "\n";
      return 1;
    }
    return 0;
  } catch (const UsageError& error) {
    err << "sandbox topics: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    err << "sandbox topics: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
