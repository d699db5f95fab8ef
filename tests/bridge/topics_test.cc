// The topic monitor (sandbox topics) on memq://: every channel name LCM can
// deliver is counted, control characters included. (LCM 1.3.1 delivers no
// channel whose name is not UTF-8 to any subscriber: its channel regex is a
// GRegex; `sandbox topics --log` lists those from a log, tests/app/replay_test.cc.)

#include "bridge/topics.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bridge/lcm_link.h"

namespace sandbox::bridge {
namespace {

TEST(TopicMonitorTest, ChannelsWithControlCharactersAndLongNamesAreCounted) {
  LcmLink link("memq://");
  TopicMonitor monitor(link);
  const std::string longest(63, 'L');  // LCM's longest channel name
  const std::vector<std::string> names = {"plain",     "with\nnewline", std::string("ctrl\x01x"),
                                          "tab\there", "utf8-\xc3\xa9", longest};
  const unsigned char data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  for (int round = 0; round < 2; ++round) {
    for (const std::string& name : names) ASSERT_TRUE(link.Publish(name, data, 8)) << name;
  }
  monitor.Listen(0.05);
  for (const std::string& name : names) {
    ASSERT_EQ(monitor.stats().count(name), 1u) << name;
    EXPECT_EQ(monitor.stats().at(name).messages, 2) << name;
    EXPECT_EQ(monitor.stats().at(name).bytes, 16) << name;
  }
}

}  // namespace
}  // namespace sandbox::bridge
