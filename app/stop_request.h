#pragma once
// A request to end the loop, owned by the loop: any thread may make one (the
// live view's window, a test, a signal), and every wait of the loop ends at
// once when it does. Request() only sets a flag and writes one byte to a pipe
// (both async-signal-safe); waits poll that pipe, so a signal ends them
// whichever thread the kernel delivered it to. std::this_thread::sleep_until
// cannot be used for this: it restarts itself after a signal.

#include <atomic>
#include <chrono>

namespace sandbox::app {

class StopRequest {
 public:
  using Clock = std::chrono::steady_clock;

  StopRequest();  // its own wake-up pipe; throws std::runtime_error when none can be made
  ~StopRequest();
  StopRequest(const StopRequest&) = delete;
  StopRequest& operator=(const StopRequest&) = delete;

  // Any thread, and signal handlers.
  void Request();
  bool requested() const { return requested_; }
  // Sleeps until `deadline`; returns false at once when a stop is requested
  // before it (or was already).
  bool SleepUntil(Clock::time_point deadline) const;

 private:
  std::atomic<bool> requested_{false};
  int read_fd_{-1}, write_fd_{-1};
};

// Routes SIGINT and SIGTERM to `stop` until destroyed; then their default
// actions (ending the process) return. Signals are process-wide: one route
// at a time.
class SignalRoute {
 public:
  explicit SignalRoute(StopRequest& stop);
  ~SignalRoute();
  SignalRoute(const SignalRoute&) = delete;
  SignalRoute& operator=(const SignalRoute&) = delete;
};

}  // namespace sandbox::app
