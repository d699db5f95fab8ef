#pragma once
// What is on an LCM network: per channel, how many messages, how often, how
// big, and of which sandbox type (LCM 1.3.1 does not say who published them).

#include <cstdint>
#include <map>
#include <string>

#include "bridge/lcm_link.h"

namespace sandbox::bridge {

struct ChannelStats {
  std::int64_t messages{0};
  std::int64_t bytes{0};
  std::int64_t first_utime{0}, last_utime{0};
  std::string type;  // "robot_pose_t", or the fingerprint in hex for other types

  double rate_hz() const;  // over the time between first and last message
};

// Listens to every channel on `link` for `seconds`.
std::map<std::string, ChannelStats> ListenToAll(LcmLink& link, double seconds);

// The same for every event of an LCM log file (times are the events' own).
// Throws std::runtime_error naming the file (see LogReader); a log cut short
// is read up to the break, which *stopped_early then tells.
std::map<std::string, ChannelStats> ReadLogTopics(const std::string& path,
                                                  std::string* stopped_early);

}  // namespace sandbox::bridge
