#pragma once
// Logs rejected input once per cause per second: the first time at once, then
// at most once a second with the count since. Threads: the loop thread.

#include <chrono>
#include <cstdint>
#include <map>
#include <ostream>
#include <string>

namespace sandbox::bridge {

class RejectLog {
 public:
  // At most this many causes are logged apart; more are "other reasons".
  static constexpr std::size_t kMaxCauses = 64;

  explicit RejectLog(std::ostream* out) : out_(out) {}
  // `source` is the channel or socket, `reason` the cause.
  void Note(const std::string& source, const std::string& reason);

 private:
  struct Entry {
    std::chrono::steady_clock::time_point last;
    std::int64_t unlogged{0};
    bool logged{false};
  };
  std::ostream* out_;
  std::map<std::string, Entry> entries_;
};

}  // namespace sandbox::bridge
