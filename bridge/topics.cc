#include "bridge/topics.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "bridge/lcm_link_impl.h"
#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace sandbox::bridge {
namespace {

// The type whose fingerprint leads a message (the first 8 bytes, big-endian).
std::string TypeOf(const std::uint8_t* data, std::uint32_t size) {
  if (size < 8) return "?";
  std::int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  using namespace sandbox_msgs;
  const std::pair<std::int64_t, const char*> known[] = {
      {robot_pose_t::getHash(), "robot_pose_t"},
      {bone_values_t::getHash(), "bone_values_t"},
      {actor_placements_t::getHash(), "actor_placements_t"},
      {camera_command_t::getHash(), "camera_command_t"},
      {scan_face_t::getHash(), "scan_face_t"},
      {scan_face_compact_t::getHash(), "scan_face_compact_t"},
      {ground_map_t::getHash(), "ground_map_t"},
      {imu_t::getHash(), "imu_t"},
      {gnss_t::getHash(), "gnss_t"},
      {air_data_t::getHash(), "air_data_t"},
      {lidar_scan_t::getHash(), "lidar_scan_t"},
      {range_t::getHash(), "range_t"},
      {robot_state_t::getHash(), "robot_state_t"},
      {wrench_t::getHash(), "wrench_t"},
      {status_t::getHash(), "status_t"}};
  for (const auto& [known_hash, name] : known) {
    if (known_hash == hash) return name;
  }
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
  LogReader log(path);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  while (log.Next(&channel, &data, &utime)) {
    Count(channel, data.data(), std::uint32_t(data.size()), utime, &stats);
  }
  *stopped_early = log.stopped_early();
  return stats;
}

}  // namespace sandbox::bridge
