#include "app/stop_request.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <string>

namespace sandbox::app {
namespace {

std::atomic<StopRequest*> signal_target{nullptr};
static_assert(std::atomic<StopRequest*>::is_always_lock_free);
static_assert(std::atomic<bool>::is_always_lock_free);

void OnSignal(int) {
  if (StopRequest* stop = signal_target.load()) stop->Request();
}

}  // namespace

StopRequest::StopRequest() {
  int fds[2];
  if (::pipe2(fds, O_NONBLOCK | O_CLOEXEC) != 0) {
    throw std::runtime_error(std::string("cannot make the stop pipe: ") + std::strerror(errno));
  }
  read_fd_ = fds[0], write_fd_ = fds[1];
}

StopRequest::~StopRequest() {
  ::close(read_fd_);
  ::close(write_fd_);
}

void StopRequest::Request() {
  requested_ = true;
  const char byte = 1;
  // A full pipe already wakes every waiter; nothing else can go wrong here.
  [[maybe_unused]] const ssize_t written = ::write(write_fd_, &byte, 1);
}

bool StopRequest::SleepUntil(Clock::time_point deadline) const {
  pollfd wake{read_fd_, POLLIN, 0};
  for (;;) {
    if (requested_) return false;
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) return true;
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
    const timespec timeout{time_t(ns / 1000000000), long(ns % 1000000000)};
    // The pipe stays readable after a request: every waiter sees it.
    if (::ppoll(&wake, 1, &timeout, nullptr) < 0 && errno != EINTR) return !requested_;
  }
}

SignalRoute::SignalRoute(StopRequest& stop) {
  signal_target = &stop;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
}

SignalRoute::~SignalRoute() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  signal_target = nullptr;
}

}  // namespace sandbox::app
