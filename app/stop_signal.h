#pragma once
// SIGINT and SIGTERM as a stop request that every wait of the loop wakes up
// for. The handler only sets a flag and writes one byte to a pipe (both
// async-signal-safe); waits poll that pipe, so a signal ends them at once
// whichever thread the kernel delivered it to. std::this_thread::sleep_until
// cannot be used for this: it restarts itself after a signal.
//
// Signals are process-wide, so is this. Any thread.

#include <chrono>

namespace sandbox::app {

class StopSignal {
 public:
  using Clock = std::chrono::steady_clock;

  // Routes SIGINT and SIGTERM here until the object is destroyed; then
  // their default actions (ending the process) return.
  StopSignal();
  ~StopSignal();
  StopSignal(const StopSignal&) = delete;
  StopSignal& operator=(const StopSignal&) = delete;

  // Forgets earlier requests.
  static void Clear();
  // Whether a stop was requested (a signal, or Request()) since the last Clear().
  static bool requested();
  // Requests a stop, as a signal would.
  static void Request();
  // Sleeps until `deadline`; returns false at once when a stop is requested
  // before it (or was already).
  static bool SleepUntil(Clock::time_point deadline);
};

}  // namespace sandbox::app
