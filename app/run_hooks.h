#pragma once
// In-process additions to `sandbox run`'s loop: the demo's fallback pilot and
// its heartbeat listener, `sandbox view`'s recording of states, the Python
// module's outputs, and test aids (a slow tick). All run on the
// loop thread.

#include <cstdint>
#include <functional>

#include "bridge/lcm_link.h"
#include "web/stream_state.h"

namespace sandbox::app {

struct RunHooks {
  // Called at the start of each tick, before the inputs are drained, with the
  // seconds since the loop started.
  std::function<void(bridge::LcmLink& link, double wall_s)> before_tick;
  // Called at the end of each tick's work, inside its measured duration (a
  // test slows given ticks here).
  std::function<void(std::int64_t tick)> end_of_tick;
  // Called after each tick with the browser view's state of it (`sandbox view`
  // keeps them), with the sensors' samples once every web_samples_every_s of
  // the run's time.
  std::function<void(web::StreamState&& state)> web_state;
  double web_samples_every_s{1.0};
  // Called before the link closes: let go of what before_tick subscribed.
  std::function<void(bridge::LcmLink& link)> before_close;
  // Every message the loop publishes, as it is published.
  bridge::LcmLink::PublishTap published;
  // False: SIGINT and SIGTERM are left to the caller (an interpreter's own).
  bool route_signals{true};
};

}  // namespace sandbox::app
