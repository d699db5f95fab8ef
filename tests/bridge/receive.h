#pragma once
// The test tools' LCM handlers: a received buffer decoded as one message,
// checked (bridge/checked_decode.h) as the sandbox does.

#include <lcm/lcm-cpp.hpp>

#include "bridge/checked_decode.h"

namespace sandbox::testing {

template <typename Message>
bool Decode(const lcm::ReceiveBuffer* buffer, Message* message) {
  return bridge::DecodeChecked(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size,
                               message)
      .empty();
}

}  // namespace sandbox::testing
