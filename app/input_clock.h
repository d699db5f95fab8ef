#pragma once
// Lock-step time from input times: seconds since the first input, kept
// monotonic. Input times that jump back (a model restarting its clock, a log
// stitched from two runs) continue the clock by the last step seen instead,
// so the sensors' and cameras' schedules keep running; negative input times
// are times like any other.
//
// Threads: the loop thread.

#include <cstdint>

namespace sandbox::app {

class InputClock {
 public:
  // The next input's time; returns the loop's time in seconds for it.
  double Advance(std::int64_t input_utime) {
    if (!started_) {
      started_ = true, first_utime_ = last_utime_ = input_utime;
    } else if (input_utime >= last_utime_) {
      const std::int64_t step_us = input_utime - last_utime_;
      if (step_us > 0) last_step_us_ = step_us;  // several robots' inputs share a time
      elapsed_us_ += step_us;
      last_utime_ = input_utime;
    } else {  // back: on by the last step
      elapsed_us_ += last_step_us_;
      last_utime_ = input_utime;
    }
    return t_s();
  }
  double t_s() const { return double(elapsed_us_) * 1e-6; }
  bool started() const { return started_; }
  std::int64_t first_utime() const { return first_utime_; }

 private:
  bool started_{false};
  std::int64_t first_utime_{0}, last_utime_{0};
  std::int64_t elapsed_us_{0}, last_step_us_{0};
};

}  // namespace sandbox::app
