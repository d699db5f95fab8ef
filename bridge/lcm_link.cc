#include "bridge/lcm_link.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "bridge/lcm_link_impl.h"
#include "scene/files.h"

namespace sandbox::bridge {

std::int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string WithReceiveBuffer(const std::string& url) {
  const bool multicast = url.empty() || url.rfind("udpm://", 0) == 0;
  if (!multicast || url.find("recv_buf_size=") != std::string::npos) return url;
  const std::string base = url.empty() ? "udpm://239.255.76.67:7667?ttl=0" : url;
  return base + (base.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=4194304";
}

std::string Printable(const std::string& text, std::size_t max_chars) {
  std::string out;
  out.reserve(std::min(text.size(), max_chars));
  for (const char c : text) {
    if (out.size() == max_chars) {
      out.replace(max_chars - 3, 3, "...");
      break;
    }
    out += c >= 0x20 && c < 0x7f ? c : '?';
  }
  return out;
}

namespace {

constexpr std::uint32_t kLogSync = 0xEDA1DA01;

std::uint64_t BigEndian(const unsigned char* bytes, int n) {
  std::uint64_t value = 0;
  for (int i = 0; i < n; ++i) value = value << 8 | bytes[i];
  return value;
}

void PutBigEndian(std::uint64_t value, int n, unsigned char* bytes) {
  for (int i = n - 1; i >= 0; --i, value >>= 8) bytes[i] = static_cast<unsigned char>(value);
}

}  // namespace

LogWriter::LogWriter(const std::string& path) : path_(path) {
  // Regular files and character devices (/dev/null) only: a FIFO blocks.
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISCHR(info.st_mode)) {
    throw std::runtime_error("cannot write the log '" + path + "': " +
                             (S_ISDIR(info.st_mode) ? "it is a folder" : "not a regular file"));
  }
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw std::runtime_error("cannot write the log '" + path + "': " + std::strerror(errno));
  }
}

LogWriter::~LogWriter() { Close(); }

void LogWriter::Fail(int error_number) {
  if (error_.empty()) {
    error_ = "cannot write '" + path_ + "' after " + std::to_string(events_) +
             " events: " + std::strerror(error_number != 0 ? error_number : EIO);
  }
}

bool LogWriter::Write(const std::string& channel, const void* data, unsigned size,
                      std::int64_t utime) {
  if (file_ == nullptr || !error_.empty()) return false;
  unsigned char header[28];
  PutBigEndian(kLogSync, 4, header);
  PutBigEndian(std::uint64_t(events_), 8, header + 4);
  PutBigEndian(std::uint64_t(utime), 8, header + 12);
  PutBigEndian(channel.size(), 4, header + 20);
  PutBigEndian(size, 4, header + 24);
  errno = 0;
  if (std::fwrite(header, 1, sizeof(header), file_) != sizeof(header) ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      std::fwrite(data, 1, size, file_) != size) {
    Fail(errno);
    return false;
  }
  ++events_;
  return true;
}

bool LogWriter::Close() {
  if (file_ == nullptr) return error_.empty();
  errno = 0;
  if (std::fflush(file_) != 0) Fail(errno);
  if (std::fclose(file_) != 0) Fail(errno);
  file_ = nullptr;
  return error_.empty();
}

LcmLink::LcmLink(const std::string& url)
    : url_(WithReceiveBuffer(url)), impl_(std::make_unique<Impl>(url_)) {
  if (!impl_->lcm.good())
    throw std::runtime_error("LcmLink::LcmLink(): cannot open LCM URL '" + url_ + "'");
}

LcmLink::~LcmLink() = default;

int LcmLink::Drain(double budget_s) {
  using Clock = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration<double>(budget_s);
  int handled = 0;
  while (impl_->lcm.handleTimeout(0) > 0) {
    // The clock is read every 16 messages: cheap when idle, bounded in a flood.
    if (++handled % 16 == 0 && Clock::now() >= end) break;
  }
  return handled;
}

bool LcmLink::Publish(const std::string& channel, const void* data, unsigned size) {
  if (record_) record_->Write(channel, data, size, record_utime_);
  if (tap_) tap_(channel, data, size);
  return impl_->lcm.publish(channel, data, size) == 0;
}

bool LcmLink::Inject(const std::string& channel, const void* data, unsigned size) {
  return impl_->lcm.publish(channel, data, size) == 0;
}

bool LcmLink::Wait(int timeout_ms) { return impl_->lcm.handleTimeout(timeout_ms) > 0; }

void LcmLink::RecordTo(const std::string& path) { record_ = OpenEventWriter(path); }

bool LcmLink::FinishRecording() { return !record_ || record_->Close(); }

LogReader::LogReader(const std::string& path, std::uint32_t max_event_bytes)
    : path_(path), max_event_bytes_(max_event_bytes) {
  if (const std::string problem = scene::RegularFileProblem(path); !problem.empty()) {
    throw std::runtime_error("cannot read the LCM log '" + path + "': " + problem);
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw std::runtime_error("cannot read the LCM log '" + path + "'");
  size_ = std::max<std::int64_t>(1, std::int64_t(scene::FileBytes(path)));
  unsigned char sync[4];
  if (std::fread(sync, 1, 4, file_) != 4 || BigEndian(sync, 4) != kLogSync) {
    std::fclose(file_);
    file_ = nullptr;
    throw std::runtime_error("'" + path +
                             "' is not an LCM log (it does not start with the sync word "
                             "0xEDA1DA01)");
  }
  unsigned char header[28];
  if (std::fseek(file_, 0, SEEK_SET) == 0 && std::fread(header, 1, 28, file_) == 28) {
    first_utime_ = utime_ = std::int64_t(BigEndian(header + 12, 8));
    end_utime_ = LastEventUtime().value_or(first_utime_);
  }
  std::fseek(file_, 0, SEEK_SET);
}

std::optional<std::int64_t> LogReader::LastEventUtime() {
  // The last megabyte, searched from its end for an event header whose event
  // ends exactly at the end of the file.
  const std::int64_t tail = std::min<std::int64_t>(size_, 1 << 20);
  std::vector<unsigned char> bytes(std::size_t(tail), 0);
  if (std::fseek(file_, long(size_ - tail), SEEK_SET) != 0 ||
      std::fread(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    return std::nullopt;
  }
  for (std::int64_t at = tail - 28; at >= 0; --at) {
    const unsigned char* header = bytes.data() + at;
    if (BigEndian(header, 4) != kLogSync) continue;
    const std::int64_t channel_length = std::int64_t(BigEndian(header + 20, 4)),
                       data_length = std::int64_t(BigEndian(header + 24, 4));
    if (channel_length >= 1 && channel_length <= 256 &&
        size_ - tail + at + 28 + channel_length + data_length == size_) {
      return std::int64_t(BigEndian(header + 12, 8));
    }
  }
  return std::nullopt;
}

LogReader::~LogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool LogReader::Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) {
  for (;;) {
    if (file_ == nullptr || !stopped_early_.empty()) return false;
    unsigned char header[28];
    const std::size_t got = std::fread(header, 1, sizeof(header), file_);
    if (got == 0) return false;  // a clean end
    auto stop = [&](const std::string& why) {
      stopped_early_ = why + ": event " + std::to_string(events_ + skipped_ + 1) + " at byte " +
                       std::to_string(offset_) + " of " + std::to_string(size_);
      return false;
    };
    if (got < sizeof(header)) return stop("truncated inside an event header");
    if (BigEndian(header, 4) != kLogSync) return stop("corrupt (no sync word)");
    const std::int64_t event_utime = std::int64_t(BigEndian(header + 12, 8));
    utime_ = event_utime;
    const std::uint64_t channel_length = BigEndian(header + 20, 4),
                        data_length = BigEndian(header + 24, 4);
    if (channel_length == 0 || channel_length > 256) return stop("corrupt (channel name length)");
    const std::int64_t needed = 28 + std::int64_t(channel_length + data_length);
    if (offset_ + needed > size_) {
      return stop("truncated (the event needs " + std::to_string(needed) + " bytes)");
    }
    // Events over the budget are stepped over unread.
    if (data_length > max_event_bytes_) {
      if (std::fseek(file_, long(channel_length + data_length), SEEK_CUR) != 0) {
        return stop("unreadable");
      }
      offset_ += needed;
      ++skipped_;
      continue;
    }
    channel->resize(channel_length);
    data->resize(data_length);
    if (std::fread(channel->data(), 1, channel_length, file_) != channel_length ||
        std::fread(data->data(), 1, data_length, file_) != data_length) {
      return stop("unreadable");
    }
    *utime = event_utime;
    offset_ += needed;
    ++events_;
    return true;
  }
}

double LogReader::fraction_read() const {
  if (end_utime_ > first_utime_) {
    // In double: a hostile log's times may be any int64, their differences overflow.
    const double done = double(utime_) - double(first_utime_);
    return std::clamp(done / (double(end_utime_) - double(first_utime_)), 0.0, 1.0);
  }
  return double(offset_) / double(size_);
}

namespace {

void Deliver(const lcm::ReceiveBuffer* buffer, const std::string& /*channel*/, LatestInput* input) {
  input->OnMessage(buffer->data, buffer->data_size, buffer->recv_utime);
}

}  // namespace

LatestInput::LatestInput(LcmLink& link, std::string channel, MessageCheck check,
                         std::size_t max_bytes)
    : link_(link), channel_(std::move(channel)), check_(std::move(check)), max_bytes_(max_bytes) {
  lcm::Subscription* subscription = link_.impl().lcm.subscribeFunction(channel_, &Deliver, this);
  if (subscription == nullptr) {
    throw std::runtime_error("LatestInput::LatestInput(): cannot subscribe to '" +
                             Printable(channel_) + "'");
  }
  subscription->setQueueCapacity(kQueueCapacity);
  subscription_ = subscription;
}

void LatestInput::set_queue(bool queue) {
  queue_ = queue;
  static_cast<lcm::Subscription*>(subscription_)->setQueueCapacity(queue ? 0 : kQueueCapacity);
}

LatestInput::~LatestInput() {
  link_.impl().lcm.unsubscribe(static_cast<lcm::Subscription*>(subscription_));
}

void LatestInput::OnMessage(const void* data, unsigned size, std::int64_t receive_utime) {
  link_.RecordInput(channel_, data, size, receive_utime);
  ++received_;
  last_receive_utime_ = receive_utime;
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  // Checked before anything is copied: a bad message leaves the good one waiting.
  if (size > max_bytes_) {
    return Reject("over the channel's budget of " + std::to_string(max_bytes_) + " bytes");
  }
  if (check_) {
    if (std::string problem = check_(bytes, size); !problem.empty()) return Reject(problem);
  }
  if (queue_) {
    if (queued_bytes_ + size > kMaxQueuedBytes) {
      return Reject("lock-step queue full (" + std::to_string(kMaxQueuedBytes >> 20) + " MB)");
    }
    queue_messages_.push_back({{bytes, bytes + size}, receive_utime});
    queued_bytes_ += size;
    return;
  }
  if (fresh_) ++superseded_;  // the one waiting was never taken
  newest_.bytes.assign(bytes, bytes + size);
  newest_.receive_utime = receive_utime;
  fresh_ = true;
}

const std::vector<std::uint8_t>* LatestInput::Peek() {
  if (queue_messages_.empty()) return nullptr;
  taken_utime_ = queue_messages_.front().receive_utime;
  return &queue_messages_.front().bytes;
}

void LatestInput::Pop() {
  if (queue_messages_.empty()) return;
  queued_bytes_ -= queue_messages_.front().bytes.size();
  queue_messages_.pop_front();
}

const std::vector<std::uint8_t>* LatestInput::TakeNewest() {
  if (!fresh_) return nullptr;
  fresh_ = false;
  std::swap(taken_, newest_);
  taken_utime_ = taken_.receive_utime;
  return &taken_.bytes;
}

void LatestInput::Reject(const std::string& reason) {
  ++rejected_;
  last_reason_ = Printable(reason);
  // Reasons may quote what arrived: a bounded number are counted apart.
  if (reasons_.size() < kMaxReasons || reasons_.count(last_reason_) > 0) {
    ++reasons_[last_reason_];
  } else {
    ++reasons_["other"];
  }
  if (log_ != nullptr) log_->Note(channel_, last_reason_);
}

bool LatestInput::Stale(std::int64_t now_utime, double max_age_s) const {
  return last_accept_utime_ < 0 || double(now_utime - last_accept_utime_) * 1e-6 > max_age_s;
}

}  // namespace sandbox::bridge
