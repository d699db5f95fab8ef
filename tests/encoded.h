#pragma once
// An LCM message's bytes, as lcm-gen's encode() writes them (for logs and
// injected messages in tests).

#include <cstdint>
#include <vector>

namespace sandbox::testing {

template <typename Message>
std::vector<std::uint8_t> Encoded(const Message& message) {
  std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  return bytes;
}

}  // namespace sandbox::testing
