#pragma once
// When the ticks of a paced loop start (../shared/DESIGN.md, "One tick of the
// loop"): each one period after the last deadline. A tick that ends after its
// next deadline is an overrun: the next tick starts at once and the deadlines
// restart from there, so ticks never bunch up to catch up. Pure arithmetic
// on the times it is given (seconds on any clock), for the loop and its tests.

namespace sandbox::app {

class TickPacer {
 public:
  // `period_s` 0: free running (every tick starts at once, none is late).
  TickPacer(double period_s, double start_s) : period_s_(period_s), deadline_s_(start_s) {}

  // How late a tick that starts at `start_s` is (0 when free running).
  double Lateness(double start_s) const {
    return period_s_ > 0.0 && start_s > deadline_s_ ? start_s - deadline_s_ : 0.0;
  }
  // Deadlines start again from `now_s` (after a pause).
  void Restart(double now_s) { deadline_s_ = now_s; }
  // After a tick that ended at `end_s`: when the next one starts. Sets
  // *overrun when the tick ended after that next deadline.
  double Next(double end_s, bool* overrun) {
    *overrun = false;
    if (period_s_ <= 0.0) return end_s;
    deadline_s_ += period_s_;
    if (end_s > deadline_s_) {
      *overrun = true;
      deadline_s_ = end_s;
    }
    return deadline_s_;
  }

 private:
  double period_s_;
  double deadline_s_;  // when the current tick should have started
};

}  // namespace sandbox::app
