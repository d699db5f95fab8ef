// Fuzz target: bytes as a compact face-scan message (scan_face_compact_t), as
// a consumer of <ROBOT>/SCAN_FACE reads it: the checked LCM decoder, then the
// face back to world points.

#include <cstdint>
#include <stdexcept>

#include "bridge/checked_decode.h"
#include "bridge/face_points.h"
#include "sandbox_msgs/scan_face_compact_t.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sandbox_msgs::scan_face_compact_t message;
  if (!sandbox::bridge::DecodeChecked(data, size, &message).empty()) return 0;
  try {
    const sandbox::bridge::FacePoints points = sandbox::bridge::DecodeCompactFace(message);
    if (points.occupancy.size() != points.points_W.size()) __builtin_trap();
    if (!points.surface.empty() && points.surface.size() != points.points_W.size())
      __builtin_trap();
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
