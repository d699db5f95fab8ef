#pragma once
// Decoding LCM messages from the network or a log file, where nothing can be
// trusted. lcm-gen's decoders (LCM 1.3.1) resize an array to whatever count
// the bytes claim before reading it, and take a string of length 0 as one of
// 2^64 - 1 bytes: one message with a negative or huge count ends the process
// or takes gigabytes. Here the layout is walked first, every count and string
// length checked against the bytes that remain, and only bytes that hold
// exactly one message of the type reach the generated decoder.
//
// Bridge-internal (it includes the generated types); any thread.

#include <cstddef>
#include <cstdint>
#include <string>

namespace sandbox::bridge {

// Returns "" with *message filled, or why `data` is not exactly one Message,
// as a short reason without numbers from the bytes (so that a flood of
// garbage gives few distinct reasons): "cannot decode as bone_values_t:
// num_values is negative". Defined for every type in bridge/lcmtypes.
template <typename Message>
std::string DecodeChecked(const std::uint8_t* data, std::size_t size, Message* message);

// Only the check: "" when DecodeChecked would succeed.
template <typename Message>
std::string CheckLayout(const std::uint8_t* data, std::size_t size);

}  // namespace sandbox::bridge
