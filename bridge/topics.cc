#include "bridge/topics.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "bridge/lcm_link_impl.h"
#include "bridge/lcm_types.h"

namespace sandbox::bridge {
namespace {

// The type whose fingerprint leads a message (the first 8 bytes, big-endian).
std::string TypeOf(const std::uint8_t* data, std::uint32_t size) {
  if (size < 8) return "?";
  std::int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  if (const LcmType* type = LcmTypeOf(data, size)) return type->name;
  char text[24];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

void Count(const std::string& channel, const std::uint8_t* data, std::uint32_t size,
           std::int64_t utime, std::map<std::string, ChannelStats>* stats) {
  ChannelStats& s = (*stats)[channel];
  if (s.messages == 0) {
    s.first_utime = utime;
    s.type = TypeOf(data, size);
  }
  ++s.messages;
  s.bytes += size;
  ++s.window_messages;
  s.window_bytes += size;
  s.last_utime = utime;
}

void Deliver(const lcm::ReceiveBuffer* buffer, const std::string& channel, TopicMonitor* monitor) {
  monitor->OnMessage(channel, static_cast<const std::uint8_t*>(buffer->data), buffer->data_size,
                     buffer->recv_utime);
}

}  // namespace

double ChannelStats::rate_hz() const {
  return messages > 1 && last_utime > first_utime
             ? double(messages - 1) / (double(last_utime - first_utime) * 1e-6)
             : 0.0;
}

double ChannelStats::bandwidth_Bps() const {
  return messages > 1 && last_utime > first_utime
             ? double(bytes) * double(messages - 1) / double(messages) /
                   (double(last_utime - first_utime) * 1e-6)
             : 0.0;
}

TopicMonitor::TopicMonitor(LcmLink& link) : link_(link) {
  lcm::Subscription* subscription = link_.impl().lcm.subscribeFunction("(?s).*", &Deliver, this);
  if (subscription == nullptr) throw std::runtime_error("sandbox topics: cannot subscribe");
  subscription->setQueueCapacity(LatestInput::kQueueCapacity);
  subscription_ = subscription;
}

TopicMonitor::~TopicMonitor() {
  link_.impl().lcm.unsubscribe(static_cast<lcm::Subscription*>(subscription_));
}

void TopicMonitor::OnMessage(const std::string& channel, const std::uint8_t* data,
                             std::uint32_t size, std::int64_t utime) {
  Count(channel, data, size, utime, &stats_);
}

void TopicMonitor::Listen(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (auto now = std::chrono::steady_clock::now(); now < end;
       now = std::chrono::steady_clock::now()) {
    const int ms = int(std::chrono::duration<double, std::milli>(end - now).count()) + 1;
    link_.impl().lcm.handleTimeout(std::min(ms, 20));
  }
}

void TopicMonitor::StartWindow() {
  for (auto& [channel, s] : stats_) s.window_messages = s.window_bytes = 0;
}

std::map<std::string, ChannelStats> ReadLogTopics(const std::string& path,
                                                  std::string* stopped_early) {
  std::map<std::string, ChannelStats> stats;
  const std::unique_ptr<EventReader> log = OpenEventReader(path);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  while (log->Next(&channel, &data, &utime)) {
    Count(channel, data.data(), std::uint32_t(data.size()), utime, &stats);
  }
  *stopped_early = log->stopped_early();
  return stats;
}

}  // namespace sandbox::bridge
