// Frame statistics with bounded memory: histogram quantiles against the exact
// nearest-rank quantiles of the same values, and the plot's pooled points.

#include "app/tick_stats.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace sandbox::app {
namespace {

TEST(TickStatsTest, HistogramQuantilesAreWithinABinOfTheExactOnes) {
  std::mt19937 random(7);
  std::lognormal_distribution<double> ms(-1.0, 1.2);  // mostly under 1 ms, a tail to tens
  std::vector<double> values;
  Histogram histogram;
  for (int i = 0; i < 100000; ++i) {
    values.push_back(ms(random));
    histogram.Add(values.back());
  }
  for (const double q : {0.01, 0.5, 0.9, 0.99, 0.999}) {
    const double exact = Quantile(values, q);
    const double bin = exact < 1.0 ? 0.001 : exact < 100.0 ? 0.01 : 1.0;
    EXPECT_GE(histogram.Quantile(q), exact) << q;  // the upper edge of the value's bin
    EXPECT_LE(histogram.Quantile(q), exact + bin + 1e-12) << q;
  }
  EXPECT_EQ(Histogram().Quantile(0.5), 0.0);
}

TEST(TickStatsTest, LongRunsKeepABoundedPlotThatStillShowsEverySpike) {
  TickStats stats;
  const long ticks = 100000;
  for (long i = 0; i < ticks; ++i) {
    TickRecord record;
    record.tick = i;
    record.duration_ms = i == 77777 ? 50.0 : 0.3 + 0.001 * double(i % 10);
    stats.Add(record, i == 77777);
  }
  const std::vector<double> points = stats.PlotPoints();
  EXPECT_LE(points.size(), TickStats::kMaxPlotPoints);
  EXPECT_GE(points.size(), TickStats::kMaxPlotPoints / 4);
  // Every tick is in one point: full blocks and the partial last one.
  EXPECT_LT(long(points.size() - 1) * stats.ticks_per_point(), ticks);
  EXPECT_GE(long(points.size()) * stats.ticks_per_point(), ticks);
  EXPECT_EQ(*std::max_element(points.begin(), points.end()), 50.0);  // the spike survives pooling
  EXPECT_EQ(std::count(points.begin(), points.end(), 50.0), 1);
  const StatsSummary summary = stats.Summary();
  EXPECT_EQ(summary.ticks, ticks);
  EXPECT_EQ(summary.max_ms, 50.0);
  EXPECT_EQ(summary.overruns, 1);
  EXPECT_NEAR(summary.p50_ms, 0.305, 0.0011);
}

}  // namespace
}  // namespace sandbox::app
