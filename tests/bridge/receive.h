#pragma once
// The test tools' LCM handlers: a received buffer decoded as one message,
// checked (bridge/checked_decode.h) as the sandbox does.

#include <lcm/lcm-cpp.hpp>

#include <string>

#include "bridge/checked_decode.h"
#include "sandbox_msgs/status_t.hpp"

namespace sandbox::testing {

template <typename Message>
bool Decode(const lcm::ReceiveBuffer* buffer, Message* message) {
  return bridge::DecodeChecked(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size,
                               message)
      .empty();
}

// The column of `channel` in a STATUS message, or -1 when it is not there.
inline int StatusColumn(const sandbox_msgs::status_t& status, const std::string& channel) {
  for (int c = 0; c < status.num_channels; ++c) {
    if (status.channels[std::size_t(c)] == channel) return c;
  }
  return -1;
}

}  // namespace sandbox::testing
