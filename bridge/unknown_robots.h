#pragma once
// Poses addressed to robots this level does not have: any "<PREFIX>/POSE"
// whose prefix is no robot's. They are counted per channel, logged (once per
// channel per second, through the RejectLog) and never applied: a misspelt
// prefix, or the robots of another sandbox on the same LCM network.
// Threads: the loop thread (the link's).

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/reject_log.h"

namespace sandbox::bridge {

class UnknownRobots {
 public:
  // At most this many channels are counted apart (a flood of made-up names
  // cannot grow the table); the rest are counted as one.
  static constexpr std::size_t kMaxChannels = 64;

  // `prefixes`: the channel prefixes of the level's robots.
  UnknownRobots(LcmLink& link, const std::vector<std::string>& prefixes, RejectLog* log);
  ~UnknownRobots();
  UnknownRobots(const UnknownRobots&) = delete;
  UnknownRobots& operator=(const UnknownRobots&) = delete;

  // Poses heard per channel of an unknown robot ("(other channels)" beyond kMaxChannels).
  const std::map<std::string, std::int64_t>& poses() const { return poses_; }
  std::int64_t total() const { return total_; }

  // Called by the subscription (inside LcmLink::Drain()).
  void OnPose(const std::string& channel);

 private:
  LcmLink& link_;
  std::set<std::string> known_;  // "<PREFIX>/POSE" of each robot
  std::string reason_;           // the logged reason, naming the robots there are
  RejectLog* log_;
  void* subscription_{nullptr};
  std::map<std::string, std::int64_t> poses_;
  std::int64_t total_{0};
};

}  // namespace sandbox::bridge
