#pragma once
// What `sandbox run` reports: a replay's progress while it runs; at the end,
// the summary it prints, the tick plot (ticks.png) and the last of the
// statistics file, gathered from the parts that ran.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "app/camera_director.h"
#include "app/frame_pipeline.h"
#include "app/live_view.h"
#include "app/run_options.h"
#include "app/scan_files.h"
#include "app/tick_stats.h"
#include "bridge/lcm_link.h"
#include "bridge/robot_feed.h"
#include "bridge/unknown_robots.h"
#include "web/foxglove_server.h"
#include "web/stream_server.h"

namespace sandbox::app {

// What ran, as the loop leaves it. Null pointers: that part did not run.
struct RunRecord {
  const RunOptions* options{nullptr};
  std::string level_name;
  std::int64_t ticks{0};
  double elapsed_s{0.0};
  TickStats* stats{nullptr};  // flushed here
  const bridge::EventReader* replay{nullptr};
  std::int64_t origin_moves{0};
  double longest_origin_move_ms{0.0};
  Eigen::Vector3d origin{Eigen::Vector3d::Zero()};
  const ScanFileWriter* scan_files{nullptr};
  const LiveView* live_view{nullptr};
  const web::StreamServer* web{nullptr};         // the browser view, when served
  const web::FoxgloveServer* foxglove{nullptr};  // the Foxglove server, when served
  const CameraDirector* cameras{nullptr};
  const bridge::LcmLink* link{nullptr};
  const FramePipeline* frames{nullptr};  // null unless frames were written
  std::vector<const bridge::RobotFeed*> feeds;
  std::vector<std::int64_t> published;  // messages each robot published, as feeds
  const bridge::UnknownRobots* unknown_robots{nullptr};
  std::optional<scene::TerrainStreamer::Figures> terrain;  // a level with [[terrain]]
};

// A replay's progress bar, on one line of `err`: read, ticks, ticks/s, time left.
// The browser view's line of the summary: clients, states, bytes, refusals.
void PrintWebCounts(const web::ServerCounts& counts, std::ostream& out);
void PrintFoxgloveCounts(const web::FoxgloveCounts& counts, std::ostream& out);

void PrintReplayProgress(const bridge::EventReader& replay, std::int64_t ticks, double wall_s,
                         std::ostream& err);

// The name of the pace: "100 Hz", "free running" or "lock-step".
std::string PaceName(const RunOptions& options);

// Prints the summary to `out` (a replay's end and failures to `err`), plots
// ticks.png and flushes ticks.csv. Returns false when some output could not
// be written (each loss is reported).
bool ReportRun(const RunRecord& run, std::ostream& out, std::ostream& err);

}  // namespace sandbox::app
