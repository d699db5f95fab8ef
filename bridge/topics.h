#pragma once
// What is on an LCM network: per channel, how many messages, how often, how
// big, and of which sandbox type (LCM 1.3.1 does not say who published them).
// Threads: the link's (the caller's).

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
  // Since the last TopicMonitor::StartWindow().
  std::int64_t window_messages{0}, window_bytes{0};

  double rate_hz() const;        // over the time between first and last message
  double bandwidth_Bps() const;  // bytes over that time
};

// Every channel heard on a link, counted as messages arrive: totals, and
// counts over a window the caller restarts (the live table's rates).
class TopicMonitor {
 public:
  explicit TopicMonitor(LcmLink& link);  // subscribes to every channel
  ~TopicMonitor();
  TopicMonitor(const TopicMonitor&) = delete;
  TopicMonitor& operator=(const TopicMonitor&) = delete;

  // Handles what arrives for `seconds`.
  void Listen(double seconds);
  // Starts a new window (the window counts go back to zero).
  void StartWindow();
  const std::map<std::string, ChannelStats>& stats() const { return stats_; }

  void OnMessage(const std::string& channel, const std::uint8_t* data, std::uint32_t size,
                 std::int64_t utime);

 private:
  LcmLink& link_;
  void* subscription_{nullptr};
  std::map<std::string, ChannelStats> stats_;
};

// The same for every event of an LCM log file (times are the events' own).
// Throws std::runtime_error naming the file (see LogReader); a log cut short
// is read up to the break, which *stopped_early then tells.
std::map<std::string, ChannelStats> ReadLogTopics(const std::string& path,
                                                  std::string* stopped_early);

}  // namespace sandbox::bridge
