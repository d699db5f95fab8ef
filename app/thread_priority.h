#pragma once
// The loop thread's scheduling: real-time priority while a paced loop runs.

#include <pthread.h>
#include <sched.h>

namespace sandbox::app {

// SCHED_FIFO for the calling thread (threads it starts later inherit it;
// threads started earlier do not). False when not permitted.
inline bool RaiseToRealTime() {
  sched_param param{};
  param.sched_priority = 10;  // above every normal thread, below the kernel's own
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

// Back to normal priority, however the scope ends.
struct NormalPriorityAtExit {
  ~NormalPriorityAtExit() {
    sched_param param{};
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
  }
};

}  // namespace sandbox::app
