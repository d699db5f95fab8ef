#include "app/stop_signal.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>

namespace sandbox::app {
namespace {

std::atomic<bool> stop_requested{false};

// The wake-up pipe, made once for the process and never closed.
struct WakePipe {
  int read_fd{-1}, write_fd{-1};
  WakePipe() {
    int fds[2];
    if (::pipe2(fds, O_NONBLOCK | O_CLOEXEC) != 0) {
      std::perror("StopSignal: pipe2");
      std::abort();
    }
    read_fd = fds[0], write_fd = fds[1];
  }
};

WakePipe& Pipe() {
  static WakePipe pipe;
  return pipe;
}

void Wake() {
  stop_requested = true;
  const char byte = 1;
  // A full pipe already wakes every waiter; nothing else can go wrong here.
  [[maybe_unused]] const ssize_t written = ::write(Pipe().write_fd, &byte, 1);
}

void OnSignal(int) { Wake(); }

}  // namespace

StopSignal::StopSignal() {
  Pipe();  // made before a handler can need it
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
}

StopSignal::~StopSignal() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

void StopSignal::Clear() {
  stop_requested = false;
  char bytes[64];
  while (::read(Pipe().read_fd, bytes, sizeof(bytes)) > 0) {
  }
}

bool StopSignal::requested() { return stop_requested; }

void StopSignal::Request() { Wake(); }

bool StopSignal::SleepUntil(Clock::time_point deadline) {
  pollfd wake{Pipe().read_fd, POLLIN, 0};
  for (;;) {
    if (stop_requested) return false;
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) return true;
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
    const timespec timeout{time_t(ns / 1000000000), long(ns % 1000000000)};
    // The pipe stays readable after a request: every waiter sees it.
    if (::ppoll(&wake, 1, &timeout, nullptr) < 0 && errno != EINTR) return !stop_requested;
  }
}

}  // namespace sandbox::app
