#pragma once
// The LCM connection the loop owns, latest-value input channels on it, and
// LCM log files read and written natively. Threads: everything here belongs
// to the loop thread.
//
// Everything that arrives is untrusted (LCM is unauthenticated multicast:
// anyone on the LAN may publish on any channel). An input checks each message
// when it arrives, within a byte budget, so that a malformed or hostile
// message is counted and dropped and never displaces the last good one.

#include <cstdint>
#include <cstdio>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bridge/event_log.h"
#include "bridge/reject_log.h"

namespace sandbox::bridge {

// Now as LCM messages stamp it: wall-clock microseconds since the epoch.
std::int64_t NowUtime();

// A subscriber URL with a receive buffer big enough for 250 KB messages:
// UDP multicast URLs ("udpm://...", and LCM's default, the empty URL) get
// recv_buf_size=4194304 unless they set one; others are returned as they are.
std::string WithReceiveBuffer(const std::string& url);

// Writes an LCM log file event by event, in lcm-logger's format (see
// LogReader). Write errors (a full disk, /dev/full) are kept, not thrown: the
// first one stops the writing and error() says what happened.
class LogWriter final : public EventWriter {
 public:
  // Throws std::runtime_error naming the file when it cannot be opened for
  // writing, or is a FIFO, a socket or a folder (a FIFO would block).
  explicit LogWriter(const std::string& path);
  ~LogWriter() override;
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  bool Write(const std::string& channel, const void* data, unsigned size,
             std::int64_t utime) override;
  bool Close() override;  // flushes and closes
  // Empty while everything was written, else "cannot write 'x.lcmlog' after
  // 12 events: No space left on device".
  std::string error() const override { return error_; }
  std::int64_t events() const override { return events_; }

 private:
  void Fail(int error_number);

  std::string path_;
  std::FILE* file_{nullptr};
  std::int64_t events_{0};
  std::string error_;
};

class LcmLink {
 public:
  // `url` as LCM takes it (empty: LCM's default). Throws std::runtime_error
  // naming the URL when LCM cannot open it.
  explicit LcmLink(const std::string& url = "");
  ~LcmLink();
  LcmLink(const LcmLink&) = delete;
  LcmLink& operator=(const LcmLink&) = delete;

  const std::string& url() const { return url_; }

  // Handles the messages already waiting, without blocking, for at most
  // `budget_s` seconds (a flood cannot hold the loop); returns how many. What
  // is left waits for the next call, in LCM's queue (kQueueCapacity a channel).
  int Drain(double budget_s = 0.005);
  // Publishes raw bytes (an encoded LCM message). Returns false on failure.
  bool Publish(const std::string& channel, const void* data, unsigned size);
  // Also hands every message Publish() sends to `tap` (on the publishing thread).
  using PublishTap =
      std::function<void(const std::string& channel, const void* data, unsigned size)>;
  void set_publish_tap(PublishTap tap) { tap_ = std::move(tap); }
  // Publishes without recording (a replay feeding its inputs through memq://).
  bool Inject(const std::string& channel, const void* data, unsigned size);
  // Waits up to `timeout_ms` for one message and handles it; false on timeout.
  bool Wait(int timeout_ms);

  // Also writes every message this link publishes to a recording (an MCAP
  // file for a name ending in ".mcap", else an LCM log file), stamped with the
  // time set by set_record_utime() (deterministic in lock-step runs). Throws
  // std::runtime_error naming the file when it cannot be opened; a later
  // write error is kept in record_error() and stops the recording.
  void RecordTo(const std::string& path);
  void set_record_utime(std::int64_t utime) { record_utime_ = utime; }
  // Also writes a Foxglove view no LCM message carries (a link frame, a
  // camera image) to the recording, when it takes them (an MCAP file).
  bool RecordsViews() const { return record_ && record_->TakesViews(); }
  void RecordView(MakeView make, std::int64_t utime, std::size_t bytes) {
    if (RecordsViews()) record_->WriteView(std::move(make), utime, bytes);
  }
  // Also writes an input message as it arrives (before it is checked) to a
  // recording that takes inputs (MCAP), stamped with its receive time, or
  // with the time set by set_input_utime() (a replayed event's own).
  void RecordInput(const std::string& channel, const void* data, unsigned size,
                   std::int64_t receive_utime) {
    if (record_ && record_->TakesInputs()) {
      record_->WriteInput(channel, data, size, input_utime_ >= 0 ? input_utime_ : receive_utime);
    }
  }
  void set_input_utime(std::int64_t utime) { input_utime_ = utime; }  // < 0: the receive time
  // Closes the recording (flushing it); false when any of it could not be written.
  bool FinishRecording();
  // Empty while the recording (if any) is whole.
  std::string record_error() const { return record_ ? record_->error() : std::string(); }
  std::int64_t recorded() const { return record_ ? record_->events() : 0; }

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::string url_;
  std::unique_ptr<Impl> impl_;
  std::unique_ptr<EventWriter> record_;
  std::int64_t record_utime_{0};
  std::int64_t input_utime_{-1};
  PublishTap tap_;
};

// Reads an LCM log file event by event (no network), for replays. The
// format (lcm-logger's): per event a big-endian sync word 0xEDA1DA01, event
// number (int64), utime (int64), channel length and data length (int32),
// then the channel name and the data.
class LogReader final : public EventReader {
 public:
  // Events larger than this are skipped without being read (counted in skipped()).
  static constexpr std::uint32_t kDefaultMaxEventBytes = 64u << 20;

  // Throws std::runtime_error naming the file when it cannot be read, is not
  // a regular file (a FIFO would block) or does not start like an LCM log.
  explicit LogReader(const std::string& path,
                     std::uint32_t max_event_bytes = kDefaultMaxEventBytes);
  ~LogReader() override;
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  bool Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) override;
  // How far the replay is, 0 .. 1: by the events' times (the time of the
  // last event read between the first event's and the last's), else, when
  // the last event cannot be found (a log cut short), by bytes.
  double fraction_read() const override;
  std::int64_t events() const override { return events_; }
  std::int64_t skipped() const override { return skipped_; }
  // Empty after a clean end; otherwise where and why reading stopped, e.g.
  // "truncated: event 1201 at byte 120345 of 120400 needs 88 bytes".
  const std::string& stopped_early() const override { return stopped_early_; }

 private:
  // The time of the event that ends the file, when one does within its last megabyte.
  std::optional<std::int64_t> LastEventUtime();

  std::string path_;
  std::uint32_t max_event_bytes_;
  std::FILE* file_{nullptr};
  std::int64_t size_{1}, offset_{0}, events_{0}, skipped_{0};
  std::int64_t first_utime_{0}, end_utime_{0}, utime_{0};  // end_utime_ <= first_utime_: unknown
  std::string stopped_early_;
};

// Why an arriving message is not acceptable, or "" when it is: its decode and
// every check that does not depend on the robot's state.
using MessageCheck = std::function<std::string(const std::uint8_t* data, std::size_t size)>;

// One subscribed channel that keeps only its newest good message, copied raw
// and decoded by the user when taken. Each message is checked when it
// arrives: one over the byte budget is rejected before it is copied, one the
// check refuses is rejected with the check's reason; neither displaces the
// good message waiting. Counts what arrived, what newer good messages
// superseded before anyone took them, and what was rejected, by reason.
class LatestInput {
 public:
  // Messages LCM may hold for one input between two drains (LCM's default, 30,
  // lost the newest messages above 3 kHz at 100 ticks a second).
  static constexpr int kQueueCapacity = 1000;
  // Lock-step queues hold at most this many bytes; later messages are rejected.
  static constexpr std::size_t kMaxQueuedBytes = 64u << 20;
  // At most this many distinct reasons are counted apart ("other" beyond).
  static constexpr std::size_t kMaxReasons = 32;

  // `check` empty: every message within `max_bytes` is good.
  LatestInput(LcmLink& link, std::string channel, MessageCheck check = {},
              std::size_t max_bytes = 1u << 20);
  ~LatestInput();
  LatestInput(const LatestInput&) = delete;
  LatestInput& operator=(const LatestInput&) = delete;

  const std::string& channel() const { return channel_; }
  std::size_t max_bytes() const { return max_bytes_; }

  // The newest good message that arrived since the last call, or nullptr.
  const std::vector<std::uint8_t>* TakeNewest();

  // Lock-step mode: keep every good message in arrival order instead of the
  // newest, and LCM's queue for the channel unbounded (a loop held up for a
  // while delays its inputs, it does not lose them).
  void set_queue(bool queue);
  std::size_t queued() const { return queue_messages_.size(); }
  // The oldest queued message (nullptr when none), and dropping it.
  const std::vector<std::uint8_t>* Peek();
  void Pop();
  // Counts a message as rejected, by reason (shown sanitised: printable, at
  // most 160 characters); the user keeps its last good value.
  void Reject(const std::string& reason);
  // Where rejections are also logged, once per cause per second (nullptr: nowhere).
  void set_log(RejectLog* log) { log_ = log; }
  // Marks the message last returned by TakeNewest() or Peek() as applied:
  // its arrival makes the input fresh.
  void Accept() { last_accept_utime_ = taken_utime_; }

  std::int64_t received() const { return received_; }
  std::int64_t superseded() const { return superseded_; }
  std::int64_t rejected() const { return rejected_; }
  const std::map<std::string, std::int64_t>& rejected_by_reason() const { return reasons_; }
  const std::string& last_reject_reason() const { return last_reason_; }
  std::int64_t last_receive_utime() const { return last_receive_utime_; }  // of any message
  std::int64_t last_accept_utime() const { return last_accept_utime_; }
  // No good message within `max_age_s` of `now_utime` (or never one).
  bool Stale(std::int64_t now_utime, double max_age_s) const;

  // Called by the subscription (loop thread, inside LcmLink::Drain()).
  void OnMessage(const void* data, unsigned size, std::int64_t receive_utime);

 private:
  LcmLink& link_;
  std::string channel_;
  MessageCheck check_;
  std::size_t max_bytes_;
  void* subscription_{nullptr};
  struct Message {
    std::vector<std::uint8_t> bytes;
    std::int64_t receive_utime{0};
  };
  Message newest_, taken_;
  bool queue_{false};
  std::deque<Message> queue_messages_;
  std::size_t queued_bytes_{0};
  bool fresh_{false};
  std::int64_t received_{0}, superseded_{0}, rejected_{0};
  std::int64_t last_receive_utime_{0}, taken_utime_{-1}, last_accept_utime_{-1};
  std::map<std::string, std::int64_t> reasons_;
  RejectLog* log_{nullptr};
  std::string last_reason_;
};

// `text` made safe to print and to keep: control and non-ASCII bytes as '?',
// at most `max_chars` characters ("..." marks a cut).
std::string Printable(const std::string& text, std::size_t max_chars = 160);

}  // namespace sandbox::bridge
