#pragma once
// What `sandbox run` is asked to do, as values: its command line parsed and
// checked. ParseRunOptions throws CommandError naming the option.

#include <cstdint>
#include <set>
#include <string>

#include "app/command_line.h"
#include "app/frame_pipeline.h"

namespace sandbox::app {

// The rates --rate takes (the loop waits at most one period, and any wait
// ends at once on Ctrl-C or at the end of --duration).
constexpr double kMinRateHz = 0.01, kMaxRateHz = 100000.0;

struct RunOptions {
  std::string level;             // a scene file or manifest
  double rate_hz{100.0};         // 0: free running (--rate max)
  double duration_s{0.0};        // 0: until stopped
  std::string lcm_url;           // empty: LCM's default
  bool lockstep{false};          // one pose message a tick (a replay is always lock-step)
  std::string replay_file;       // an LCM log read instead of the network
  std::string record_file;       // every output written to an LCM log
  std::string out_dir;           // statistics, frames and scans; empty: none
  FramePipelineConfig frames;    // image, video and depth formats (out_dir set later)
  double scans_every_s{0.0};     // 0: no scan files
  bool view{false};              // the live view
  bool isolate{false};           // load the level in a child process first
  bool realtime{true};           // ask for SCHED_FIFO
  std::int64_t ticks{0};         // stop after this many ticks; 0: no limit
  bool sensors{true};            // false: no sensor runs (--no-sensors, --frames-only)
  bool publish{true};            // false: nothing published (--frames-only)
  std::string web_address;       // the browser view's address (--web [ADDR:]PORT); empty: none
  int web_port{-1};              // its port; -1: no browser view (0: any free port)
  bool web_control{false};       // the page may steer the cameras (--web-control)
  std::string foxglove_address;  // the Foxglove WebSocket server's (--foxglove [ADDR:]PORT)
  int foxglove_port{-1};         // its port; -1: none (0: any free port)

  bool free_running() const { return rate_hz == 0.0; }
  bool replay() const { return !replay_file.empty(); }
};

// The value options and flags `sandbox run` takes.
extern const std::set<std::string> kRunValueOptions, kRunFlags;

// Throws UsageError for a bad value or combination.
RunOptions ParseRunOptions(const ParsedArgs& args);
// --web's value, [ADDRESS:]PORT (the address 127.0.0.1 when left out;
// [IPv6]:PORT), into *options; the address is checked when the server binds.
void ParseWebAddress(const std::string& text, RunOptions* options);
// The same for `option` (--web, --foxglove) into *address and *port.
void ParseServerAddress(const std::string& text, const std::string& option, std::string* address,
                        int* port);

}  // namespace sandbox::app
