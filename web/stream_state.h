#pragma once
// What the browser view is sent each time it is sent anything: the tick, the
// loop's timing, each robot's pose and status, and the movable actors'
// placements. Taken by the loop between ticks (copies of a few poses), encoded
// as JSON (nlohmann-json) on the stream's thread. The fields are listed in
// docs/reference/web.md.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace sandbox::web {

struct StreamState {
  struct Body {
    std::string name;
    Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};
    Eigen::Quaterniond q_W{Eigen::Quaterniond::Identity()};
  };
  struct Robot : Body {
    bool has_pose{false};            // a pose has arrived
    std::int64_t rejected{0};        // inputs refused so far
    std::vector<std::string> stale;  // its input channels gone quiet
  };
  std::int64_t tick{0};
  double time_s{0.0};   // since the run started (lock-step: the inputs' time)
  double tick_ms{0.0};  // the last tick's duration
  double late_ms{0.0};  // how late it started
  std::vector<Robot> robots;
  std::vector<Body> actors;  // the movable actors
};

std::string EncodeState(const StreamState& state);

}  // namespace sandbox::web
