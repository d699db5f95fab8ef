#include "bridge/lcm_link.h"

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
  return impl_->lcm.publish(channel, data, size) == 0;
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
  if (fresh_) ++superseded_;  // the one waiting was never taken
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  newest_.assign(bytes, bytes + size);
  fresh_ = true;
  last_receive_utime_ = receive_utime;
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
