#pragma once
// The sandbox's LCM message types as data: name, fingerprint and the .lcm
// text that defines them (a recording's schema), generated from
// bridge/lcmtypes/ at build time.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sandbox::bridge {

struct LcmType {
  std::string name;     // "robot_pose_t"
  std::int64_t hash{};  // the fingerprint that leads every encoded message
  std::string schema;   // the .lcm file's text
  std::string full_name() const { return "sandbox_msgs." + name; }
};

const std::vector<LcmType>& SandboxLcmTypes();

// The type whose fingerprint leads an encoded message (its first 8 bytes,
// big-endian), or null for a message of another type or under 8 bytes.
const LcmType* LcmTypeOf(const std::uint8_t* data, std::size_t size);

}  // namespace sandbox::bridge
