#include "bridge/lcm_link.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "bridge/lcm_link_impl.h"

namespace sandbox::bridge {

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

struct LogReader::Impl {
  explicit Impl(const std::string& path) : log(path, "r") {}
  lcm::LogFile log;
  long size{1};
};

LogReader::LogReader(const std::string& path) : impl_(std::make_unique<Impl>(path)) {
  if (!impl_->log.good())
    throw std::runtime_error("LogReader: cannot read the LCM log '" + path + "'");
  std::FILE* file = impl_->log.getFilePtr();
  const long at = std::ftell(file);
  std::fseek(file, 0, SEEK_END);
  impl_->size = std::max(1L, std::ftell(file));
  std::fseek(file, at, SEEK_SET);
}

LogReader::~LogReader() = default;

bool LogReader::Next(std::string* channel, std::vector<std::uint8_t>* data, std::int64_t* utime) {
  const lcm::LogEvent* event = impl_->log.readNextEvent();
  if (event == nullptr) return false;
  *channel = event->channel;
  const auto* bytes = static_cast<const std::uint8_t*>(event->data);
  data->assign(bytes, bytes + event->datalen);
  *utime = event->timestamp;
  return true;
}

double LogReader::fraction_read() const {
  return double(std::ftell(impl_->log.getFilePtr())) / double(impl_->size);
}

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
