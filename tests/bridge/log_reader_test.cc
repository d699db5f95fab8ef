// LogReader's progress: by the events' times, so that a log whose first
// megabytes are outputs recorded before the first pose does not read as
// nearly done; by bytes when the log is cut short and its end has no time.

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

// Ten 500 kB events at 1 s, then 100 small ones 0.1 s apart (to 11 s).
std::string WriteLog(const testing::TempDir& dir) {
  const std::string path = (dir.path() / "run.lcmlog").string();
  LogWriter log(path);
  const std::vector<std::uint8_t> big(500'000, 7), small(10, 1);
  for (int i = 0; i < 10; ++i)
    log.Write("ELAHA/SCAN_FACE", big.data(), unsigned(big.size()), 1'000'000);
  for (int k = 1; k <= 100; ++k) {
    log.Write("ELAHA/POSE", small.data(), unsigned(small.size()), 1'000'000 + k * 100'000);
  }
  EXPECT_TRUE(log.Close());
  return path;
}

TEST(LogReaderTest, ProgressFollowsTheEventsTimesNotTheirBytes) {
  testing::TempDir dir;
  LogReader reader(WriteLog(dir));
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  EXPECT_DOUBLE_EQ(reader.fraction_read(), 0.0);
  for (int i = 0; i < 11; ++i) ASSERT_TRUE(reader.Next(&channel, &data, &utime));
  // At 1.1 s of 1 .. 11 s; more than 99% of the bytes are behind.
  EXPECT_EQ(channel, "ELAHA/POSE");
  EXPECT_NEAR(reader.fraction_read(), 0.1 / 10.0, 1e-12);
  for (int i = 0; i < 49; ++i) ASSERT_TRUE(reader.Next(&channel, &data, &utime));
  EXPECT_NEAR(reader.fraction_read(), 5.0 / 10.0, 1e-12);
  while (reader.Next(&channel, &data, &utime)) {
  }
  EXPECT_DOUBLE_EQ(reader.fraction_read(), 1.0);
  EXPECT_TRUE(reader.stopped_early().empty());
}

TEST(LogReaderTest, ALogCutShortCountsProgressByBytes) {
  testing::TempDir dir;
  const std::string path = WriteLog(dir);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 5);  // the last event cut
  LogReader reader(path);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(reader.Next(&channel, &data, &utime));
  const double bytes = 10.0 * (28 + 15 + 500'000) / double(size - 5);
  EXPECT_NEAR(reader.fraction_read(), bytes, 1e-12);
}

// Found by the fuzz target: times at the ends of int64 (their differences
// overflow) still give a fraction from 0 to 1.
TEST(LogReaderTest, TimesAtTheEndsOfInt64GiveAFractionFrom0To1) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "extreme.lcmlog").string();
  {
    LogWriter log(path);
    const std::uint8_t byte = 0;
    log.Write("A", &byte, 1, std::numeric_limits<std::int64_t>::min());
    log.Write("A", &byte, 1, std::numeric_limits<std::int64_t>::max());
    log.Write("A", &byte, 1, std::numeric_limits<std::int64_t>::max());
    ASSERT_TRUE(log.Close());
  }
  LogReader reader(path);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  while (reader.Next(&channel, &data, &utime)) {
    EXPECT_GE(reader.fraction_read(), 0.0);
    EXPECT_LE(reader.fraction_read(), 1.0);
  }
  EXPECT_DOUBLE_EQ(reader.fraction_read(), 1.0);
}

}  // namespace
}  // namespace sandbox::bridge
