#pragma once
// The LCM connection the loop owns, and latest-value input channels on it.
// Threads: everything here belongs to the loop thread.

#include <cstdint>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bridge/reject_log.h"

namespace sandbox::bridge {

// Now as LCM messages stamp it: wall-clock microseconds since the epoch.
std::int64_t NowUtime();

// A subscriber URL with a receive buffer big enough for 250 KB messages:
// UDP multicast URLs ("udpm://...", and LCM's default, the empty URL) get
// recv_buf_size=4194304 unless they set one; others are returned as they are.
std::string WithReceiveBuffer(const std::string& url);

class LcmLink {
 public:
  // `url` as LCM takes it (empty: LCM's default). Throws std::runtime_error
  // naming the URL when LCM cannot open it.
  explicit LcmLink(const std::string& url = "");
  ~LcmLink();
  LcmLink(const LcmLink&) = delete;
  LcmLink& operator=(const LcmLink&) = delete;

  const std::string& url() const { return url_; }

  // Handles every message already waiting, without blocking; returns how many.
  int Drain();
  // Publishes raw bytes (an encoded LCM message). Returns false on failure.
  bool Publish(const std::string& channel, const void* data, unsigned size);
  // Publishes without recording (a replay feeding its inputs through memq://).
  bool Inject(const std::string& channel, const void* data, unsigned size);
  // Waits up to `timeout_ms` for one message and handles it; false on timeout.
  bool Wait(int timeout_ms);

  // Also writes every message this link publishes to an LCM log file, stamped
  // with the time set by set_record_utime() (deterministic in lock-step runs).
  // Throws std::runtime_error naming the file when it cannot be opened.
  void RecordTo(const std::string& path);
  void set_record_utime(std::int64_t utime) { record_utime_ = utime; }

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::string url_;
  std::unique_ptr<Impl> impl_;
  std::int64_t record_utime_{0};
};

// Reads an LCM log file event by event (no network), for replays. The
// format (lcm-logger's): per event a big-endian sync word 0xEDA1DA01, event
// number (int64), utime (int64), channel length and data length (int32),
// then the channel name and the data.
class LogReader {
 public:
  // Throws std::runtime_error naming the file when it cannot be read or does
  // not start like an LCM log.
  explicit LogReader(const std::string& path);
  ~LogReader();
  // The next event, or false at the end of the file or of its valid part.
  bool Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime);
  double fraction_read() const;                    // 0 .. 1
  std::int64_t events() const { return events_; }  // read so far
  // Empty after a clean end; otherwise where and why reading stopped, e.g.
  // "truncated: event 1201 at byte 120345 of 120400 needs 88 bytes".
  const std::string& stopped_early() const { return stopped_early_; }

 private:
  std::string path_;
  std::FILE* file_{nullptr};
  std::int64_t size_{1}, offset_{0}, events_{0};
  std::string stopped_early_;
};

// One subscribed channel that keeps only its newest message, copied raw and
// decoded by the user only when taken. Counts what arrived, what newer
// messages superseded before anyone took them, and what the user rejected.
class LatestInput {
 public:
  LatestInput(LcmLink& link, std::string channel);
  ~LatestInput();
  LatestInput(const LatestInput&) = delete;
  LatestInput& operator=(const LatestInput&) = delete;

  const std::string& channel() const { return channel_; }

  // The newest message that arrived since the last call, or nullptr.
  const std::vector<std::uint8_t>* TakeNewest();

  // Lock-step mode: keep every message in arrival order instead of the newest.
  void set_queue(bool queue) { queue_ = queue; }
  std::size_t queued() const { return queue_messages_.size(); }
  // The oldest queued message (nullptr when none), and dropping it.
  const std::vector<std::uint8_t>* Peek() const;
  void Pop();
  // Counts a taken message as rejected, by reason; the user keeps its last good value.
  void Reject(const std::string& reason);
  // Where rejections are also logged, once per cause per second (nullptr: nowhere).
  void set_log(RejectLog* log) { log_ = log; }
  // Marks the last taken message as applied (its time makes the input fresh).
  void Accept(std::int64_t receive_utime);

  std::int64_t received() const { return received_; }
  std::int64_t superseded() const { return superseded_; }
  std::int64_t rejected() const { return rejected_; }
  const std::map<std::string, std::int64_t>& rejected_by_reason() const { return reasons_; }
  const std::string& last_reject_reason() const { return last_reason_; }
  std::int64_t last_receive_utime() const { return last_receive_utime_; }
  std::int64_t last_accept_utime() const { return last_accept_utime_; }
  // No good message within `max_age_s` of `now_utime` (or never one).
  bool Stale(std::int64_t now_utime, double max_age_s) const;

  // Called by the subscription (loop thread, inside LcmLink::Drain()).
  void OnMessage(const void* data, unsigned size, std::int64_t receive_utime);

 private:
  LcmLink& link_;
  std::string channel_;
  void* subscription_{nullptr};
  std::vector<std::uint8_t> newest_, taken_;
  bool queue_{false};
  std::deque<std::vector<std::uint8_t>> queue_messages_;
  bool fresh_{false};
  std::int64_t received_{0}, superseded_{0}, rejected_{0};
  std::int64_t last_receive_utime_{0}, last_accept_utime_{-1};
  std::map<std::string, std::int64_t> reasons_;
  RejectLog* log_{nullptr};
  std::string last_reason_;
};

}  // namespace sandbox::bridge
