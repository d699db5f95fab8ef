#include "app/run_summary.h"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include "app/process_stats.h"

namespace sandbox::app {

std::string PaceName(const RunOptions& options) {
  if (options.lockstep) return "lock-step";
  if (options.free_running()) return "free running";
  std::ostringstream out;
  out << options.rate_hz << " Hz";
  return out.str();
}

void PrintReplayProgress(const bridge::EventReader& replay, std::int64_t ticks, double wall_s,
                         std::ostream& err) {
  const double done = replay.fraction_read();
  err << "\rreplay: " << std::setw(3) << int(100 * done) << "% | " << ticks << " ticks | "
      << std::setprecision(0) << std::fixed << (wall_s > 0 ? double(ticks) / wall_s : 0.0)
      << " ticks/s | " << (done > 0 ? wall_s * (1 - done) / done : 0.0) << " s left  "
      << std::defaultfloat << std::setprecision(6) << std::flush;
}

bool ReportRun(const RunRecord& run, std::ostream& out, std::ostream& err) {
  const RunOptions& options = *run.options;
  bool output_lost = false;
  if (run.replay != nullptr) {
    err << "\rreplay: " << (run.replay->stopped_early().empty() ? "100% | " : "") << run.ticks
        << " ticks" << std::string(30, ' ') << "\n";
    if (!run.replay->stopped_early().empty()) {
      err << "sandbox run: the log '" << options.replay_file << "' is "
          << run.replay->stopped_early() << "; the " << run.replay->events()
          << " events before it were replayed\n";
    } else if (run.ticks == 0) {
      err << "sandbox run: the log '" << options.replay_file << "' has " << run.replay->events()
          << " events but no pose message for this level's robots\n";
    }
  }
  const StatsSummary summary = run.stats->Summary();
  out << "sandbox run: " << run.ticks << " ticks in " << std::fixed << std::setprecision(2)
      << run.elapsed_s << " s (" << (run.elapsed_s > 0 ? double(run.ticks) / run.elapsed_s : 0.0)
      << " Hz), mean tick " << std::setprecision(3) << summary.mean_ms << " ms, "
      << summary.overruns << " overruns\n";
  out << "  tick duration: p50 " << summary.p50_ms << " ms, p99 " << summary.p99_ms << " ms, max "
      << summary.max_ms << " ms\n";
  const bool paced = !options.lockstep && !options.free_running();
  if (paced) {
    out << "  tick lateness: p50 " << summary.lateness_p50_ms << " ms, p99 "
        << summary.lateness_p99_ms << " ms, max " << summary.lateness_max_ms << " ms\n";
  }
  if (run.origin_moves > 0) {
    out << "  floating origin: moved " << run.origin_moves << " times, longest "
        << run.longest_origin_move_ms << " ms, now at (" << run.origin.transpose() << ")\n";
  }
  if (run.terrain) {
    const scene::TerrainStreamer::Figures& f = *run.terrain;
    out << "  terrain: " << f.built << " tiles built (" << f.fine_built << " fine, " << f.from_cache
        << " from the cache), " << f.dropped << " dropped, " << f.failed << " failed; build total "
        << f.total_build_ms / 1e3 << " s, longest " << f.longest_build_ms << " ms, swap longest "
        << f.longest_swap_ms << " ms; peak " << f.peak_resident_tiles << " tiles, "
        << (f.peak_resident_bytes >> 20) << " MB";
    if (options.lockstep) {
      out << "; waited " << f.waits << " times, longest " << f.longest_wait_ms << " ms";
    } else {
      out << "; late " << f.late << " times";
    }
    out << "; process peak resident " << PeakResidentMiB() << " MiB\n";
  }
  if (!options.out_dir.empty()) {
    // Files that cannot be finished (a full disk) are reported; the run's results stand.
    const std::filesystem::path dir = options.out_dir;
    const std::string mode = PaceName(options);
    PlotSeries series{
        run.stats->ticks_per_point() == 1
            ? std::string("tick duration")
            : "longest of each " + std::to_string(run.stats->ticks_per_point()) + " ticks",
        run.stats->PlotPoints()};
    series.frames_per_value = double(run.stats->ticks_per_point());
    try {
      PlotFrameDurations({series},
                         run.level_name + ": " + std::to_string(run.ticks) + " ticks, " + mode,
                         paced ? 1e3 / options.rate_hz : 0.0, (dir / "ticks.png").string());
    } catch (const std::exception& error) {
      err << "sandbox run: warning: " << error.what() << "\n";
      output_lost = true;
    }
    if (!run.stats->Flush()) {
      err << "sandbox run: warning: " << (dir / "ticks.csv").string()
          << " is incomplete (cannot write)\n";
      output_lost = true;
    }
    out << "  statistics: " << (dir / "ticks.csv").string() << ", " << (dir / "ticks.png").string()
        << "\n";
    if (options.scans_every_s > 0.0) {
      output_lost = output_lost || run.scan_files->failed() > 0;
      out << "  scans: " << run.scan_files->written() << " PLY files written, "
          << run.scan_files->dropped() << " dropped, " << run.scan_files->failed() << " failed"
          << (run.scan_files->failed() > 0 ? " (" + run.scan_files->error() + ")" : "") << " -> "
          << (dir / "scans").string() << "\n";
    }
  }
  if (run.web != nullptr) PrintWebCounts(run.web->counts(), out);
  if (run.foxglove != nullptr) PrintFoxgloveCounts(run.foxglove->counts(), out);
  if (run.live_view != nullptr) {
    out << "  live view: " << run.live_view->shown() << " frames shown, last camera "
        << run.cameras->live_camera()
        << (run.cameras->controls().overlay ? ", overlay toggled" : "")
        << (run.cameras->controls().quit ? ", quit by key" : "") << "\n";
  }
  if (!options.record_file.empty()) {
    output_lost = output_lost || !run.link->record_error().empty();
    out << "  recording: " << run.link->recorded() << " messages -> " << options.record_file
        << (run.link->record_error().empty() ? ""
                                             : " (INCOMPLETE: " + run.link->record_error() + ")")
        << "\n";
  }
  if (run.frames != nullptr) {
    output_lost = output_lost || run.frames->failed() > 0;
    out << "  frames: " << run.frames->rendered() << " rendered, " << run.frames->written()
        << " written, " << run.frames->dropped() << " dropped, " << run.frames->failed()
        << " failed" << (run.frames->failed() > 0 ? " (" + run.frames->error() + ")" : "") << " -> "
        << options.out_dir << "\n";
  }
  for (std::size_t r = 0; r < run.feeds.size(); ++r) {
    const bridge::RobotFeed* feed = run.feeds[r];
    out << "  robot " << feed->config().channel_prefix << ": " << run.published[r]
        << " messages published, last input seq " << feed->input().seq
        << (feed->active_camera().empty() ? "" : ", active camera " + feed->active_camera())
        << "\n";
    for (const bridge::ChannelStatus& channel : feed->Channels(bridge::NowUtime())) {
      out << "    " << channel.channel << ": " << channel.received << " received, "
          << channel.superseded << " superseded, " << channel.rejected << " rejected"
          << (channel.rejected > 0 ? " (last: " + channel.last_reject_reason + ")" : "") << "\n";
    }
  }
  if (run.unknown_robots != nullptr && run.unknown_robots->total() > 0) {
    out << "  poses for robots this level does not have, not applied: "
        << run.unknown_robots->total() << "\n";
    for (const auto& [channel, poses] : run.unknown_robots->poses()) {
      out << "    " << bridge::Printable(channel, 64) << ": " << poses << "\n";
    }
  }
  return !output_lost;
}

void PrintFoxgloveCounts(const web::FoxgloveCounts& c, std::ostream& out) {
  out << "  foxglove: " << c.connections << " clients (" << c.clients << " at the end), "
      << c.channels << " channels, " << c.subscriptions << " subscriptions, " << c.messages_sent
      << " messages sent, " << c.messages_skipped << " skipped for slow clients, "
      << c.bytes_sent / 1024 << " KiB; refused: " << c.refused_origin << " other origin, "
      << c.refused_protocol << " not the Foxglove protocol, " << c.refused_full
      << " over the limit, " << c.requests_refused << " requests; closed: " << c.closed_oversized
      << " oversized messages, " << c.dropped_slow << " too slow\n";
}

void PrintWebCounts(const web::ServerCounts& c, std::ostream& out) {
  out << "  browser view: " << c.connections << " clients (" << c.clients << " at the end), "
      << c.states_sent << " states sent, " << c.states_skipped << " skipped for slow clients, "
      << c.bytes_sent / 1024 << " KiB; refused: " << c.refused_origin << " other origin, "
      << c.refused_full << " over the limit, " << c.failed
      << " bad handshakes; closed: " << c.closed_oversized << " oversized messages, "
      << c.closed_protocol << " bad frames, " << c.dropped_slow << " too slow";
  if (c.commands + c.commands_refused > 0) {
    out << "; commands: " << c.commands << " taken, " << c.commands_refused << " refused";
  }
  out << "\n";
}

}  // namespace sandbox::app
