#pragma once
// The Foxglove WebSocket protocol's client messages the sandbox's server
// takes (foxglove.websocket.v1: subscribe and unsubscribe, JSON text), apart
// from the server so that a fuzz target parses arbitrary text with it.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sandbox::web {

inline constexpr const char* kFoxgloveSubprotocol = "foxglove.websocket.v1";

struct FoxgloveRequest {
  enum class Op { kSubscribe, kUnsubscribe, kOther };
  Op op{Op::kOther};
  std::string op_name;                                             // as sent
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscribe;  // (subscription id, channel id)
  std::vector<std::uint32_t> unsubscribe;                          // subscription ids
};

// Parses one text message; throws std::invalid_argument saying what is wrong
// (not JSON, no "op", a field of the wrong type or out of range).
FoxgloveRequest ParseFoxgloveRequest(const std::string& text);

}  // namespace sandbox::web
