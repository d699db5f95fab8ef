#pragma once
// LCM log files of a known flight, written with LCM's own LogFile, for
// lock-step replays whose outputs are exact functions of the input.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "sandbox_msgs/robot_pose_t.hpp"
#include "tests/encoded.h"

namespace sandbox::testing {

// `poses` ELAHA/POSE messages `period_us` apart from `start_utime` (1 s), circling
// `radius_m` around the origin 60 m up (0: hovering over it, turning slowly),
// level, nose along the circle: pose i at angle a = 0.01 i, heading a + 90 deg.
// `mode` "a" appends to the log; `channel` is where the poses go.
inline void WriteFlightLog(const std::string& path, int poses, std::int64_t period_us = 20'000,
                           double radius_m = 100.0, const char* mode = "w",
                           const std::string& channel = "ELAHA/POSE",
                           std::int64_t start_utime = 1'000'000) {
  lcm::LogFile log(path, mode);
  ASSERT_TRUE(log.good()) << path;
  for (int i = 0; i < poses; ++i) {
    sandbox_msgs::robot_pose_t pose{};
    pose.utime = start_utime + period_us * std::int64_t(i);
    pose.seq = i;
    const double a = 0.01 * i;
    pose.position[0] = radius_m * std::cos(a);
    pose.position[1] = radius_m * std::sin(a);
    pose.position[2] = 60;
    pose.orientation[0] = std::cos((a + M_PI / 2) / 2);
    pose.orientation[3] = std::sin((a + M_PI / 2) / 2);
    std::vector<std::uint8_t> bytes = Encoded(pose);
    lcm::LogEvent event;
    event.eventnum = i;
    event.timestamp = pose.utime;
    event.channel = channel;
    event.datalen = int32_t(bytes.size());
    event.data = bytes.data();
    ASSERT_EQ(log.writeEvent(&event), 0);
  }
}

}  // namespace sandbox::testing
