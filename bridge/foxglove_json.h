#pragma once
// What foxglove_views.cc and foxglove_messages.cc share: the JSON schemas'
// common parts, Foxglove's time stamp and base64 bytes spliced into a
// message (base64 needs no escaping; the JSON writer's escape check on it
// was a fifth of a recording's work).

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace sandbox::bridge::foxglove_json {

// Parts of the JSON schemas (made on first use: no order of static
// initialisation between files to depend on).
const std::string& TimeSchema();
const std::string& Vector3Schema();
const std::string& QuaternionSchema();
const std::string& PoseSchema();
const std::string& FrameTransformSchema();  // foxglove.FrameTransform's

// {"sec": .., "nsec": ..}; negative times as 0.
nlohmann::json Time(std::int64_t utime);
// `message` dumped, with "field": "" filled with the bytes in base64.
std::string WithBase64(const nlohmann::json& message, const char* field, const void* bytes,
                       std::size_t size);

}  // namespace sandbox::bridge::foxglove_json
