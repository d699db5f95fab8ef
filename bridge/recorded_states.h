#pragma once
// A `--record` log replayed as inputs. Such a log holds what a run applied
// (each robot's <prefix>/STATE: its pose and bone values), not what it was
// sent. For a robot whose first pose-bearing event in the log is a STATE,
// each STATE becomes that robot's BONES and then its POSE, at the state's
// own time and sequence number and in the robot's pose convention, so that
// a lock-step replay redoes the recorded run's ticks: the sensors scan again,
// the cameras draw again. A robot whose log has a POSE first is replayed from
// its own inputs (an lcm-logger capture of a whole network holds both).
// Actor placements and camera commands are not in a STATE: not replayed.
// Threads: the caller's.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bridge/robot_bridge_config.h"
#include "bridge/translation.h"

namespace sandbox::bridge {

struct RecordedRobot {
  std::string channel_prefix;
  Translation pose;   // its POSE input's convention
  Translation state;  // its STATE's: the world (the default) or the pose convention
};

// One a robot, from the robots' bridge settings (Level::robots order).
std::vector<RecordedRobot> RecordedRobots(const std::vector<RobotBridgeConfig>& bridges);

struct LogEvent {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime{-1};  // its time, for a recording of the inputs; < 0: when it arrives
};

class StatesAsInputs {
 public:
  explicit StatesAsInputs(std::vector<RecordedRobot> robots);

  // Appends to `feed` what to deliver for one event of the log: the event
  // itself, or for a STATE of a robot replayed from its states, its BONES
  // (when it has bone values) and its POSE. A STATE that does not decode is
  // skipped, counted, and its reason returned ("" otherwise).
  std::string Translate(const std::string& channel, const std::vector<std::uint8_t>& data,
                        std::vector<LogEvent>* feed);

  // The prefixes of the robots replayed from their states, so far.
  std::vector<std::string> robots_from_states() const;
  // Those that became so since the last call (to be said once each).
  std::vector<std::string> TakeNewRobotsFromStates() { return std::exchange(newly_, {}); }
  std::int64_t states_replayed() const { return replayed_; }
  std::int64_t states_refused() const { return refused_; }

 private:
  enum class Source { kUnknown, kInputs, kStates };
  struct Robot {
    RecordedRobot config;
    Source source{Source::kUnknown};
  };
  std::vector<Robot> robots_;
  std::map<std::string, std::size_t> by_pose_, by_state_;  // channel -> robot
  std::vector<std::string> newly_;
  std::int64_t replayed_{0}, refused_{0};
};

}  // namespace sandbox::bridge
