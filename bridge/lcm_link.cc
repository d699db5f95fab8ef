#include "bridge/lcm_link.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "bridge/lcm_link_impl.h"

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

LcmLink::LcmLink(const std::string& url)
    : url_(WithReceiveBuffer(url)), impl_(std::make_unique<Impl>(url_)) {
  if (!impl_->lcm.good()) throw std::runtime_error("LcmLink: cannot open LCM URL '" + url_ + "'");
}

LcmLink::~LcmLink() = default;

int LcmLink::Drain() {
  int handled = 0;
  while (impl_->lcm.handleTimeout(0) > 0) ++handled;
  return handled;
}

bool LcmLink::Publish(const std::string& channel, const void* data, unsigned size) {
  if (impl_->record) {
    lcm::LogEvent event;
    event.eventnum = 0;
    event.timestamp = record_utime_;
    event.channel = channel;
    event.datalen = static_cast<std::int32_t>(size);
    event.data = const_cast<void*>(data);
    impl_->record->writeEvent(&event);
  }
  return impl_->lcm.publish(channel, data, size) == 0;
}

bool LcmLink::Inject(const std::string& channel, const void* data, unsigned size) {
  return impl_->lcm.publish(channel, data, size) == 0;
}

bool LcmLink::Wait(int timeout_ms) { return impl_->lcm.handleTimeout(timeout_ms) > 0; }

void LcmLink::RecordTo(const std::string& path) {
  impl_->record = std::make_unique<lcm::LogFile>(path, "w");
  if (!impl_->record->good()) {
    impl_->record.reset();
    throw std::runtime_error("LcmLink: cannot write the log file '" + path + "'");
  }
}

namespace {

constexpr std::uint32_t kLogSync = 0xEDA1DA01;

std::uint64_t BigEndian(const unsigned char* bytes, int n) {
  std::uint64_t value = 0;
  for (int i = 0; i < n; ++i) value = value << 8 | bytes[i];
  return value;
}

}  // namespace

LogReader::LogReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw std::runtime_error("cannot read the LCM log '" + path + "'");
  std::fseek(file_, 0, SEEK_END);
  size_ = std::max<std::int64_t>(1, std::ftell(file_));
  std::fseek(file_, 0, SEEK_SET);
  unsigned char sync[4];
  if (std::fread(sync, 1, 4, file_) != 4 || BigEndian(sync, 4) != kLogSync) {
    std::fclose(file_);
    file_ = nullptr;
    throw std::runtime_error("'" + path +
                             "' is not an LCM log (it does not start with the sync word "
                             "0xEDA1DA01)");
  }
  std::fseek(file_, 0, SEEK_SET);
}

LogReader::~LogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool LogReader::Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) {
  if (file_ == nullptr || !stopped_early_.empty()) return false;
  unsigned char header[28];
  const std::size_t got = std::fread(header, 1, sizeof(header), file_);
  if (got == 0) return false;  // a clean end
  auto stop = [&](const std::string& why) {
    stopped_early_ = why + ": event " + std::to_string(events_ + 1) + " at byte " +
                     std::to_string(offset_) + " of " + std::to_string(size_);
    return false;
  };
  if (got < sizeof(header)) return stop("truncated inside an event header");
  if (BigEndian(header, 4) != kLogSync) return stop("corrupt (no sync word)");
  const std::int64_t event_utime = std::int64_t(BigEndian(header + 12, 8));
  const std::uint64_t channel_length = BigEndian(header + 20, 4),
                      data_length = BigEndian(header + 24, 4);
  if (channel_length == 0 || channel_length > 256) return stop("corrupt (channel name length)");
  const std::int64_t needed = 28 + std::int64_t(channel_length + data_length);
  if (offset_ + needed > size_) {
    return stop("truncated (the event needs " + std::to_string(needed) + " bytes)");
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

double LogReader::fraction_read() const { return double(offset_) / double(size_); }

namespace {

void Deliver(const lcm::ReceiveBuffer* buffer, const std::string& /*channel*/, LatestInput* input) {
  input->OnMessage(buffer->data, buffer->data_size, buffer->recv_utime);
}

}  // namespace

LatestInput::LatestInput(LcmLink& link, std::string channel)
    : link_(link), channel_(std::move(channel)) {
  subscription_ = link_.impl().lcm.subscribeFunction(channel_, &Deliver, this);
}

LatestInput::~LatestInput() {
  link_.impl().lcm.unsubscribe(static_cast<lcm::Subscription*>(subscription_));
}

void LatestInput::OnMessage(const void* data, unsigned size, std::int64_t receive_utime) {
  ++received_;
  last_receive_utime_ = receive_utime;
  if (queue_) {
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    queue_messages_.emplace_back(bytes, bytes + size);
    return;
  }
  if (fresh_) ++superseded_;  // the one waiting was never taken
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  newest_.assign(bytes, bytes + size);
  fresh_ = true;
  last_receive_utime_ = receive_utime;
}

const std::vector<std::uint8_t>* LatestInput::Peek() const {
  return queue_messages_.empty() ? nullptr : &queue_messages_.front();
}

void LatestInput::Pop() {
  if (!queue_messages_.empty()) queue_messages_.pop_front();
}

const std::vector<std::uint8_t>* LatestInput::TakeNewest() {
  if (!fresh_) return nullptr;
  fresh_ = false;
  taken_.swap(newest_);
  return &taken_;
}

void LatestInput::Reject(const std::string& reason) {
  ++rejected_;
  ++reasons_[reason];
  last_reason_ = reason;
  if (log_ != nullptr) log_->Note(channel_, reason);
}

void LatestInput::Accept(std::int64_t receive_utime) { last_accept_utime_ = receive_utime; }

bool LatestInput::Stale(std::int64_t now_utime, double max_age_s) const {
  return last_accept_utime_ < 0 || double(now_utime - last_accept_utime_) * 1e-6 > max_age_s;
}

}  // namespace sandbox::bridge
