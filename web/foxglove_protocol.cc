#include "web/foxglove_protocol.h"

#include <nlohmann/json.hpp>
#include <stdexcept>

namespace sandbox::web {
namespace {

std::uint32_t Id(const nlohmann::json& value, const char* field) {
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xffffffffu) {
    throw std::invalid_argument(std::string(field) + " must be a whole number from 0 to 2^32-1");
  }
  return value.get<std::uint32_t>();
}

const nlohmann::json& ArrayField(const nlohmann::json& message, const char* field) {
  const auto it = message.find(field);
  if (it == message.end() || !it->is_array()) {
    throw std::invalid_argument(std::string("\"") + field + "\" must be an array");
  }
  return *it;
}

}  // namespace

FoxgloveRequest ParseFoxgloveRequest(const std::string& text) {
  const nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
  if (message.is_discarded()) throw std::invalid_argument("not JSON");
  if (!message.is_object()) throw std::invalid_argument("not a JSON object");
  const auto op = message.find("op");
  if (op == message.end() || !op->is_string()) throw std::invalid_argument("no \"op\" string");
  FoxgloveRequest request;
  request.op_name = op->get_ref<const std::string&>();
  if (request.op_name == "subscribe") {
    request.op = FoxgloveRequest::Op::kSubscribe;
    for (const nlohmann::json& s : ArrayField(message, "subscriptions")) {
      if (!s.is_object() || !s.contains("id") || !s.contains("channelId")) {
        throw std::invalid_argument("a subscription needs \"id\" and \"channelId\"");
      }
      request.subscribe.emplace_back(Id(s["id"], "\"id\""), Id(s["channelId"], "\"channelId\""));
    }
  } else if (request.op_name == "unsubscribe") {
    request.op = FoxgloveRequest::Op::kUnsubscribe;
    for (const nlohmann::json& id : ArrayField(message, "subscriptionIds")) {
      request.unsubscribe.push_back(Id(id, "a subscription id"));
    }
  }
  return request;
}

}  // namespace sandbox::web
