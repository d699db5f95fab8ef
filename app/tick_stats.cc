#include "app/tick_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sandbox::app {

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t rank = std::min(
      values.size() - 1, std::size_t(std::ceil(q * double(values.size()))) - (q > 0 ? 1 : 0));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
  return values[rank];
}

Histogram::Histogram() : bins_(1000 + 9900 + 9900 + 1, 0) {}

std::size_t Histogram::Bin(double ms) {
  if (!(ms > 0)) return 0;
  if (ms < 1.0) return std::size_t(ms * 1000.0);                  // 1 us
  if (ms < 100.0) return 1000 + std::size_t((ms - 1.0) * 100.0);  // 10 us
  if (ms < 10000.0) return 10900 + std::size_t(ms - 100.0);       // 1 ms
  return 20800;                                                   // beyond 10 s
}

double Histogram::UpperEdge(std::size_t bin) {
  if (bin < 1000) return double(bin + 1) / 1000.0;
  if (bin < 10900) return 1.0 + double(bin - 1000 + 1) / 100.0;
  if (bin < 20800) return 100.0 + double(bin - 10900 + 1);
  return std::numeric_limits<double>::infinity();
}

void Histogram::Add(double ms) {
  ++bins_[std::min(Bin(ms), bins_.size() - 1)];
  ++count_;
}

double Histogram::Quantile(double q) const {
  if (count_ == 0) return 0.0;
  const std::int64_t rank = std::max<std::int64_t>(1, std::int64_t(std::ceil(q * double(count_))));
  std::int64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    seen += bins_[bin];
    if (seen >= rank) return UpperEdge(bin);
  }
  return UpperEdge(bins_.size() - 1);
}

TickStats::TickStats(const std::string& csv_path) {
  if (csv_path.empty()) return;
  csv_ = std::make_unique<RowFile>(csv_path,
                                   "tick,start_s,duration_ms,lateness_ms,inputs,rays,frames");
}

void TickStats::Add(const TickRecord& record, bool overrun) {
  durations_.Add(record.duration_ms);
  lateness_.Add(record.lateness_ms);
  sum_ms_ += record.duration_ms;
  max_ms_ = std::max(max_ms_, record.duration_ms);
  max_lateness_ms_ = std::max(max_lateness_ms_, record.lateness_ms);
  overruns_ += overrun;
  // The plot: blocks of ticks, halved in number when full.
  partial_max_ =
      partial_count_ == 0 ? record.duration_ms : std::max(partial_max_, record.duration_ms);
  if (++partial_count_ == block_) {
    plot_.push_back(partial_max_);
    partial_count_ = 0;
    if (plot_.size() == kMaxPlotPoints) {
      for (std::size_t i = 0; i < plot_.size() / 2; ++i)
        plot_[i] = std::max(plot_[2 * i], plot_[2 * i + 1]);
      plot_.resize(plot_.size() / 2);
      block_ *= 2;
    }
  }
  if (csv_) {
    char row[160];
    std::snprintf(row, sizeof(row), "%lld,%.6f,%.4f,%.4f,%d,%lld,%d",
                  static_cast<long long>(record.tick), record.start_s, record.duration_ms,
                  record.lateness_ms, record.inputs, static_cast<long long>(record.rays),
                  record.frames);
    csv_->Add(row);
    if (csv_->pending_rows() >= 256) csv_->Flush();  // about once a second at 100 Hz
  }
}

std::vector<double> TickStats::PlotPoints() const {
  std::vector<double> points = plot_;
  if (partial_count_ > 0) points.push_back(partial_max_);
  return points;
}

bool TickStats::Flush() { return !csv_ || (csv_->Flush() && csv_->lost_rows() == 0); }

StatsSummary TickStats::Summary() const {
  StatsSummary summary;
  summary.ticks = durations_.count();
  summary.overruns = overruns_;
  if (summary.ticks == 0) return summary;
  summary.mean_ms = sum_ms_ / double(summary.ticks);
  summary.p50_ms = durations_.Quantile(0.5);
  summary.p99_ms = durations_.Quantile(0.99);
  summary.max_ms = max_ms_;
  summary.lateness_p50_ms = lateness_.Quantile(0.5);
  summary.lateness_p99_ms = lateness_.Quantile(0.99);
  summary.lateness_max_ms = max_lateness_ms_;
  return summary;
}

namespace {

// An axis label with as many decimals as the step needs.
std::string Label(double value, double step = 1.0) {
  char text[32];
  const int decimals = step >= 1.0 ? 0 : int(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

// 1, 2 or 5 times a power of ten, about range / 5.
double NiceStep(double range) {
  const double rough = range / 5.0, power = std::pow(10.0, std::floor(std::log10(rough)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * power >= rough) return m * power;
  }
  return 10.0 * power;
}

}  // namespace

void PlotFrameDurations(const std::vector<PlotSeries>& series, const std::string& title,
                        double period_ms, const std::string& png_path) {
  const int width = 1000, height = 500, left = 70, right = 20, top = 40, bottom = 50;
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  double frames = 1;
  std::vector<double> all;
  for (const PlotSeries& s : series) {
    frames = std::max(frames, double(s.values.size()) * s.frames_per_value);
    all.insert(all.end(), s.values.begin(), s.values.end());
  }
  // The y axis reaches the largest value (a spike stays visible) or twice the period.
  double y_max = std::max(
      {all.empty() ? 1.0 : *std::max_element(all.begin(), all.end()), period_ms * 1.2, 1e-3});
  const double y_step = NiceStep(y_max);
  y_max = std::ceil(y_max / y_step) * y_step;
  const double x_step = NiceStep(frames);
  const int plot_w = width - left - right, plot_h = height - top - bottom;
  auto X = [&](double i) {
    return left + int(std::lround(i / std::max(frames - 1.0, 1.0) * plot_w));
  };
  auto Y = [&](double v) {
    return top + plot_h - int(std::lround(std::min(v, y_max) / y_max * plot_h));
  };
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (double v = 0; v <= y_max + 1e-9; v += y_step) {
    cv::line(image, {left, Y(v)}, {left + plot_w, Y(v)}, grid, 1);
    cv::putText(image, Label(v, y_step), {8, Y(v) + 5}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  for (double i = 0; i < frames; i += x_step) {
    cv::line(image, {X(i), top}, {X(i), top + plot_h}, grid, 1);
    cv::putText(image, Label(i), {X(i) - 12, top + plot_h + 20}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(image, {left, top}, {left + plot_w, top + plot_h}, ink, 1);
  if (period_ms > 0) {
    for (int x = left; x < left + plot_w; x += 12) {
      cv::line(image, {x, Y(period_ms)}, {std::min(x + 6, left + plot_w), Y(period_ms)},
               {0, 0, 220}, 1);
    }
    cv::putText(image, "period " + Label(period_ms, period_ms >= 1 ? 1.0 : 0.01) + " ms",
                {left + plot_w - 140, Y(period_ms) - 6}, font, 0.45, {0, 0, 220}, 1, cv::LINE_AA);
  }
  for (const PlotSeries& s : series) {
    std::vector<cv::Point> points;
    for (std::size_t i = 0; i < s.values.size(); ++i) {
      points.push_back({X(double(i) * s.frames_per_value), Y(s.values[i])});
    }
    if (points.size() >= 2)
      cv::polylines(image, points, false, cv::Scalar(s.b, s.g, s.r), 1, cv::LINE_AA);
  }
  for (std::size_t k = 0; k < series.size(); ++k) {
    const int y = top + 18 + 18 * int(k);
    cv::line(image, {left + 12, y - 4}, {left + 36, y - 4},
             cv::Scalar(series[k].b, series[k].g, series[k].r), 2);
    cv::putText(image, series[k].label, {left + 42, y}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  cv::putText(image, title, {left, 26}, font, 0.6, ink, 1, cv::LINE_AA);
  cv::putText(image, "frame", {left + plot_w / 2 - 20, height - 10}, font, 0.5, ink, 1,
              cv::LINE_AA);
  cv::putText(image, "ms", {8, top - 12}, font, 0.5, ink, 1, cv::LINE_AA);
  bool written = false;
  try {
    written = cv::imwrite(png_path, image);
  } catch (const cv::Exception&) {
  }
  if (!written) throw std::runtime_error("cannot write " + png_path);
}

}  // namespace sandbox::app
