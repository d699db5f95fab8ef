// The loop's pacing rules on given times (no clock): a tick starts one period
// after the last deadline; a late tick is followed at once and the deadlines
// restart from its end, so ticks never bunch up to catch up. And when the
// things that run at their own rate (sensors, cameras) are due.

#include "app/tick_pacer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "app/rate_schedule.h"

namespace sandbox::app {
namespace {

TEST(TickPacerTest, OnTimeTicksStartOnePeriodApart) {
  TickPacer pacer(0.01, 0.0);
  bool overrun = true;
  double start = 0.0;
  for (int tick = 0; tick < 5; ++tick) {
    EXPECT_EQ(pacer.Lateness(start), 0.0);
    start = pacer.Next(start + 0.002, &overrun);  // 2 ms of work
    EXPECT_FALSE(overrun);
    EXPECT_NEAR(start, 0.01 * (tick + 1), 1e-12);
  }
}

TEST(TickPacerTest, ALateTickIsFollowedAtOnceAndTheDeadlinesRestartFromIt) {
  TickPacer pacer(0.01, 0.0);
  bool overrun = false;
  // Tick 0 on time; tick 1 takes 40 ms (four periods).
  double start = pacer.Next(0.002, &overrun);
  ASSERT_NEAR(start, 0.01, 1e-12);
  start = pacer.Next(start + 0.040, &overrun);
  EXPECT_TRUE(overrun);
  EXPECT_NEAR(start, 0.050, 1e-12);  // at once: when tick 1 ended
  // The next deadlines count from there: 60, 70, 80 ms, never 20, 30, 40 ms.
  for (const double expected : {0.060, 0.070, 0.080}) {
    start = pacer.Next(start + 0.001, &overrun);
    EXPECT_FALSE(overrun);
    EXPECT_NEAR(start, expected, 1e-12);
  }
}

TEST(TickPacerTest, LatenessIsTheStartAfterTheDeadline) {
  TickPacer pacer(0.01, 0.0);
  bool overrun = false;
  const double next = pacer.Next(0.001, &overrun);
  EXPECT_NEAR(pacer.Lateness(next + 0.0003), 0.0003, 1e-12);  // woken 0.3 ms late
  EXPECT_EQ(pacer.Lateness(next - 0.001), 0.0);
  // A tick that overran: the next starts at its end, on time by definition.
  const double after = pacer.Next(next + 0.05, &overrun);
  EXPECT_EQ(pacer.Lateness(after), 0.0);
}

TEST(TickPacerTest, FreeRunningNeverWaitsNorOverruns) {
  TickPacer pacer(0.0, 0.0);
  bool overrun = true;
  EXPECT_EQ(pacer.Next(0.5, &overrun), 0.5);
  EXPECT_FALSE(overrun);
  EXPECT_EQ(pacer.Lateness(3.0), 0.0);
}

TEST(TickPacerTest, RestartAfterAPause) {
  TickPacer pacer(0.01, 0.0);
  pacer.Restart(5.0);
  bool overrun = true;
  EXPECT_NEAR(pacer.Next(5.001, &overrun), 5.01, 1e-12);
  EXPECT_FALSE(overrun);
}

// Runs `schedule` over ticks `tick_s` apart for `seconds`; returns the times it ran.
std::vector<double> RunTimes(RateSchedule schedule, double tick_s, double seconds) {
  std::vector<double> times;
  for (int i = 0; i * tick_s <= seconds + 1e-12; ++i) {
    const double t = i * tick_s;
    if (!schedule.Due(t)) continue;
    schedule.Done(t);
    times.push_back(t);
  }
  return times;
}

TEST(RateScheduleTest, DueTimesThatFallOnTicksStayOnThem) {
  // 10 Hz on 50 Hz ticks: exactly every fifth tick, 0.1 s apart, for 100 s
  // (summed periods drift off the ticks after a few).
  const std::vector<double> times = RunTimes(RateSchedule(10.0), 0.02, 100.0);
  ASSERT_EQ(times.size(), 1001u);
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], 0.1 * double(k), 1e-9);
  // 30 Hz on 100 Hz ticks: frame k at the first tick at or after k / 30.
  const std::vector<double> frames = RunTimes(RateSchedule(30.0), 0.01, 10.0);
  ASSERT_EQ(frames.size(), 301u);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_NEAR(frames[k], std::ceil(double(k) / 30.0 / 0.01 - 1e-6) * 0.01, 1e-9) << k;
  }
}

TEST(RateScheduleTest, FallingBehindRestartsWithoutABurst) {
  RateSchedule schedule(100.0);
  ASSERT_TRUE(schedule.Due(0.0));
  schedule.Done(0.0);
  // The loop stalled for half a second: one run, then 10 ms from there.
  EXPECT_TRUE(schedule.Due(0.5));
  schedule.Done(0.5);
  EXPECT_FALSE(schedule.Due(0.505));
  EXPECT_TRUE(schedule.Due(0.51));
}

TEST(RateScheduleTest, NoRateMeansEveryTick) {
  const std::vector<double> times = RunTimes(RateSchedule(0.0), 0.01, 0.1);
  EXPECT_EQ(times.size(), 11u);
}

}  // namespace
}  // namespace sandbox::app
