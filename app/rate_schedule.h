#pragma once
// When something that runs at a rate (a sensor, a camera, scan files) is due
// on the loop's clock: at origin + k / rate for k = 0, 1, ..., each time
// computed rather than summed, so that due times falling on tick times stay
// on them (a 10 Hz camera on 50 Hz input is due at 0.1 s, not 0.1 s plus a
// rounding error and so one tick later). A schedule that falls a whole
// period behind restarts from the tick that caught up: no burst to catch up.

#include <cstdint>

namespace sandbox::app {

class RateSchedule {
 public:
  // `rate_hz` 0 or less: due every tick.
  explicit RateSchedule(double rate_hz) : period_s_(rate_hz > 0.0 ? 1.0 / rate_hz : 0.0) {}

  bool Due(double t) const { return t >= next_s() - kSlack_s; }
  // After running at `t`.
  void Done(double t) {
    ++k_;
    if (next_s() < t - kSlack_s) origin_s_ = t, k_ = 1;  // the run at t was the first
  }

 private:
  static constexpr double kSlack_s = 1e-9;
  double next_s() const { return origin_s_ + double(k_) * period_s_; }

  double period_s_;
  double origin_s_{0.0};
  std::int64_t k_{0};
};

}  // namespace sandbox::app
