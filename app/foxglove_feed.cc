#include "app/foxglove_feed.h"

#include <algorithm>

#include "bridge/foxglove_views.h"

namespace sandbox::app {
namespace {

// Foxglove's time stamps: nanoseconds, none before the epoch.
std::uint64_t Nanoseconds(std::int64_t utime) {
  return std::uint64_t(std::max<std::int64_t>(utime, 0)) * 1000;
}

}  // namespace

void FoxgloveFeed::Published(const std::string& channel, const void* data, unsigned size,
                             std::int64_t utime) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  if (!server_.HasClients() || !bridge::HasFoxgloveView(bytes, size)) return;
  server_.Defer([this, channel, copy = std::string(static_cast<const char*>(data), size), utime] {
    Convert(channel, copy, utime);
  });
}

void FoxgloveFeed::Convert(const std::string& channel, const std::string& bytes,
                           std::int64_t utime) {
  const auto known = views_.find(channel);
  if (known != views_.end() &&
      std::none_of(known->second.begin(), known->second.end(),
                   [this](std::uint32_t id) { return server_.Subscribed(id); })) {
    return;  // advertised, and nobody wants it
  }
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  std::vector<std::uint32_t>& ids = views_[channel];
  for (const bridge::FoxgloveView& view : bridge::FoxgloveViewsOf(channel, data, bytes.size())) {
    Send(view, utime, &ids);
  }
}

void FoxgloveFeed::PublishView(const std::string& topic, bridge::MakeView make,
                               std::int64_t utime) {
  if (!server_.HasClients()) return;
  server_.Defer([this, topic, make = std::move(make), utime] {
    const auto known = ids_.find(topic);
    if (known != ids_.end() && !server_.Subscribed(known->second)) return;
    Send(make(), utime, nullptr);
  });
}

void FoxgloveFeed::Latch(const std::string& topic, const std::string& schema_name,
                         const std::string& schema, bridge::MakeView make, std::int64_t utime) {
  auto it = latched_ids_.find(topic);
  if (it == latched_ids_.end()) {
    it = latched_ids_
             .emplace(topic, server_.Advertise({topic, "json", schema_name, "jsonschema", schema}))
             .first;
  }
  server_.Latch(it->second, Nanoseconds(utime), [make = std::move(make)] { return make().json; });
}

void FoxgloveFeed::Send(const bridge::FoxgloveView& view, std::int64_t utime,
                        std::vector<std::uint32_t>* ids) {
  auto it = ids_.find(view.topic);
  if (it == ids_.end()) {
    it = ids_.emplace(view.topic, server_.Advertise({view.topic, "json", view.schema_name,
                                                     "jsonschema", *view.schema}))
             .first;
    if (ids != nullptr) ids->push_back(it->second);
  }
  if (server_.Subscribed(it->second)) {
    server_.Send(it->second, Nanoseconds(utime), view.json);
  }
}

}  // namespace sandbox::app
