#include "app/topics_command.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/command_line.h"
#include "app/stop_request.h"
#include "bridge/topics.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox topics [--seconds S] [--every S] [--json] [--lcm-url URL]\n"
    "       sandbox topics --log FILE [--json]\n"
    "  a table of every LCM channel heard: message type, messages, rate, mean size and\n"
    "  bandwidth (LCM does not say who publishes), updated live:\n"
    "  --seconds  listen this long (default: until Ctrl-C on a terminal, else 2 s)\n"
    "  --every    print the table every S seconds, rates over that window (default: 1 on a\n"
    "             terminal, redrawn in place; else only once, at the end)\n"
    "  --json     each table as one JSON object on a line (JSON Lines), for scripts\n"
    "  --log FILE the same for the events of an LCM log or MCAP file (rates by the events' times)\n";

// Escapes a string for a JSON value (channel names are anyone's bytes).
std::string Json(const std::string& text) {
  std::ostringstream out;
  out << '"';
  for (const unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out << '\\' << c;
    } else if (c < 0x20 || c >= 0x7f) {
      out << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
    } else {
      out << c;
    }
  }
  out << '"';
  return out.str();
}

// A channel name for the table: printable ASCII as it is, every other byte
// (control characters, UTF-8, bytes that are not UTF-8) as \xNN, backslash as \\.
std::string Escaped(const std::string& text) {
  std::string out;
  for (const unsigned char c : text) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7f) {
      out += char(c);
    } else {
      char hex[5];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  return out;
}

// One table: per channel the totals, and rates over `window_s` (0: over the
// time between each channel's first and last message).
void PrintTable(const std::map<std::string, bridge::ChannelStats>& stats, double t_s,
                double window_s, bool json, std::ostream& out) {
  auto rate = [window_s](const bridge::ChannelStats& s) {
    return window_s > 0.0 ? double(s.window_messages) / window_s : s.rate_hz();
  };
  auto bandwidth = [window_s](const bridge::ChannelStats& s) {
    return window_s > 0.0 ? double(s.window_bytes) / window_s : s.bandwidth_Bps();
  };
  if (json) {
    out << "{\"t_s\":" << t_s << ",\"window_s\":" << window_s << ",\"channels\":[";
    bool first = true;
    for (const auto& [channel, s] : stats) {
      out << (first ? "" : ",") << "{\"channel\":" << Json(channel) << ",\"type\":" << Json(s.type)
          << ",\"messages\":" << s.messages << ",\"bytes\":" << s.bytes
          << ",\"rate_hz\":" << rate(s)
          << ",\"mean_bytes\":" << double(s.bytes) / double(s.messages)
          << ",\"bandwidth_Bps\":" << bandwidth(s) << "}";
      first = false;
    }
    out << "]}\n" << std::flush;
    return;
  }
  // Columns as wide as their longest entry: every name whole.
  std::size_t channel_width = 24, type_width = 20;
  for (const auto& [channel, s] : stats) {
    channel_width = std::max(channel_width, Escaped(channel).size() + 2);
    type_width = std::max(type_width, s.type.size() + 2);
  }
  const int cw = int(channel_width), tw = int(type_width);
  out << std::left << std::setw(cw) << "channel" << std::setw(tw) << "type" << std::right
      << std::setw(10) << "messages" << std::setw(10) << "rate Hz" << std::setw(12) << "mean bytes"
      << std::setw(12) << "kB/s"
      << "\n";
  double total_Bps = 0.0;
  for (const auto& [channel, s] : stats) {
    total_Bps += bandwidth(s);
    out << std::left << std::setw(cw) << Escaped(channel) << std::setw(tw) << s.type << std::right
        << std::setw(10) << s.messages << std::setw(10) << std::fixed << std::setprecision(1)
        << rate(s) << std::setw(12) << std::setprecision(0) << double(s.bytes) / double(s.messages)
        << std::setw(12) << std::setprecision(1) << bandwidth(s) * 1e-3 << "\n";
  }
  if (!stats.empty()) {
    out << std::left << std::setw(cw + tw + 32) << "total" << std::right << std::setw(12)
        << std::fixed << std::setprecision(1) << total_Bps * 1e-3 << "\n";
  }
  out << std::defaultfloat << std::flush;
}

}  // namespace

int RunTopics(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed = ParseArgs(args, "topics", {"--seconds", "--every", "--lcm-url", "--log"},
                                {"--json"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help || parsed->level) {
    (parsed->help ? out : err) << kUsage;
    return parsed->help ? 0 : 2;
  }
  try {
    const std::string log = parsed->Value("--log");
    const bool json = parsed->flags.count("--json") > 0;
    if (!log.empty() && (parsed->values.count("--seconds") || parsed->values.count("--lcm-url") ||
                         parsed->values.count("--every"))) {
      throw UsageError("--log reads a file: it takes no --seconds, --every or --lcm-url");
    }
    if (!log.empty()) {
      std::string stopped_early;
      const auto stats = bridge::ReadLogTopics(log, &stopped_early);
      PrintTable(stats, 0.0, 0.0, json, out);
      if (stats.empty() && !json) out << "(no events in " << log << ")\n";
      if (!stopped_early.empty()) {
        err << "sandbox topics: the log '" << log << "' is " << stopped_early << "\n";
        return 1;
      }
      return 0;
    }
    // Live on a terminal: until Ctrl-C, redrawn every second.
    const bool terminal = &out == &std::cout && isatty(STDOUT_FILENO);
    auto seconds_option = [&](const std::string& option, double fallback) {
      if (!parsed->values.count(option)) return fallback;
      const double value = ParseNumber(parsed->Value(option), option);
      if (!(value > 0.0 && value <= 86400.0)) {
        throw UsageError(option + " must be above 0 and at most 86400");
      }
      return value;
    };
    const double seconds = seconds_option("--seconds", terminal ? 0.0 : 2.0);  // 0: Ctrl-C
    const double every = seconds_option("--every", terminal ? 1.0 : 0.0);      // 0: at the end
    bridge::LcmLink link(parsed->Value("--lcm-url"));
    bridge::TopicMonitor monitor(link);
    StopRequest stop;
    const SignalRoute signals(stop);
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto elapsed = [&start] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    double window_start = 0.0;
    while (!stop.requested() && (seconds == 0.0 || elapsed() < seconds)) {
      double until = seconds > 0.0 ? seconds : 1e300;
      if (every > 0.0) until = std::min(until, window_start + every);
      monitor.Listen(std::min(0.1, std::max(0.0, until - elapsed())));
      if (every > 0.0 && elapsed() >= window_start + every) {
        if (terminal && !json) out << "\033[H\033[2J";  // redrawn in place
        const double now = elapsed();
        PrintTable(monitor.stats(), now, now - window_start, json, out);
        if (!json && monitor.stats().empty()) out << "(nothing heard yet)\n";
        monitor.StartWindow();
        window_start = now;
      }
    }
    if (every == 0.0) {  // one table: totals, rates over the whole listen
      PrintTable(monitor.stats(), elapsed(), 0.0, json, out);
      if (monitor.stats().empty() && !json) out << "(nothing heard in " << elapsed() << " s)\n";
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
