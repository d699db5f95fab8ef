#pragma once
// Frame statistics of the loop: every tick's start, duration, lateness and
// what it did, written as CSV; a summary (mean, p50, p99, max, overruns); and
// a plot of tick duration against tick number drawn with OpenCV, like the
// evaluation plots of a report. Memory stays bounded however long the run:
// quantiles come from histograms (1 us bins to 1 ms, 10 us to 100 ms, 1 ms
// to 10 s; a quantile is its bin's upper edge) and the plot keeps at most
// 20,000 points, each the longest of a block of ticks.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/row_file.h"

namespace sandbox::app {

struct TickRecord {
  std::int64_t tick{0};
  double start_s{0.0};      // since the loop started
  double duration_ms{0.0};  // the work of the tick (the wait after it excluded)
  double lateness_ms{0.0};  // start after its deadline (0 in lock-step)
  int inputs{0};            // input messages applied
  std::int64_t rays{0};     // rays cast
  int frames{0};            // camera frames submitted
};

struct StatsSummary {
  std::int64_t ticks{0};
  double mean_ms{0}, p50_ms{0}, p99_ms{0}, max_ms{0};  // tick duration
  double lateness_p50_ms{0}, lateness_p99_ms{0}, lateness_max_ms{0};
  std::int64_t overruns{0};  // ticks that ended after the next one was due
};

// The value at quantile q (0..1) of `values` (nearest rank); 0 when empty.
double Quantile(std::vector<double> values, double q);

// Counts of values in bins that widen with the value (see above).
class Histogram {
 public:
  Histogram();
  void Add(double ms);
  double Quantile(double q) const;  // nearest rank, the bin's upper edge; 0 when empty
  std::int64_t count() const { return count_; }

 private:
  static std::size_t Bin(double ms);
  static double UpperEdge(std::size_t bin);
  std::vector<std::int64_t> bins_;
  std::int64_t count_{0};
};

class TickStats {
 public:
  // `csv_path` empty: kept in memory only. Throws std::runtime_error naming
  // the file when it cannot be created.
  explicit TickStats(const std::string& csv_path = "");

  void Add(const TickRecord& record, bool overrun);
  StatsSummary Summary() const;
  // Flushes the CSV; false when some of it could not be written (a full
  // disk: those rows are lost, the file stays whole, later rows are written
  // when there is room again).
  bool Flush();
  std::int64_t lost_rows() const { return csv_ ? csv_->lost_rows() : 0; }
  std::int64_t overruns() const { return overruns_; }
  // Tick durations for the plot: one point per `ticks_per_point` ticks (the
  // longest of them), the last block possibly partial.
  std::vector<double> PlotPoints() const;
  std::int64_t ticks_per_point() const { return block_; }

  static constexpr std::size_t kMaxPlotPoints = 20000;

 private:
  std::unique_ptr<RowFile> csv_;
  Histogram durations_, lateness_;
  double sum_ms_{0}, max_ms_{0}, max_lateness_ms_{0};
  std::int64_t overruns_{0};
  std::vector<double> plot_;  // completed blocks
  std::int64_t block_{1};     // ticks per plot point
  double partial_max_{0};     // the block being filled
  std::int64_t partial_count_{0};
};

// One series of a plot: values against their index, in a colour (B, G, R).
struct PlotSeries {
  std::string label;
  std::vector<double> values;
  int b{200}, g{80}, r{30};
  double frames_per_value{1.0};  // x of value i is i * frames_per_value
};

// Draws the series as lines against frame number with axes, ticks, a legend
// and, when period_ms > 0, the period as a dashed line; writes a PNG.
// Throws std::runtime_error naming the file when it cannot be written.
void PlotFrameDurations(const std::vector<PlotSeries>& series, const std::string& title,
                        double period_ms, const std::string& png_path);

}  // namespace sandbox::app
