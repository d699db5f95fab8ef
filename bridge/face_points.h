#pragma once
// The compact face-scan encoding (sandbox_msgs::scan_face_compact_t): a face
// as a distance a grid cell, and back to world points.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sensors/face_scanner.h"

namespace sandbox::bridge {

// The 16-bit millimetre codes that are not distances.
inline constexpr std::uint16_t kFreeMm = 65535;       // nothing within the half extent
inline constexpr std::uint16_t kUnvisitedMm = 65534;  // not scanned yet
inline constexpr std::uint16_t kBeyondMm = 65533;     // a hit beyond 65.532 m
// Fills the message's face `f` of `scan` (its grid, box and distances in the
// scan's encoding, and its id plane when the scan publishes surface ids);
// the caller stamps utime, seq, input and tick.
void EncodeCompactFace(const sensors::FaceScan& scan, int f,
                       sandbox_msgs::scan_face_compact_t* message);

// A compact face back as world points (the hit, or the ray's end when free;
// NaN when not scanned yet, and for a hit beyond the millimetre range) and
// occupancy (sensors::Occupancy), row r, column c at k = r n + c, and each
// sample's surface id (empty when the message has no id plane).
struct FacePoints {
  std::vector<Eigen::Vector3d> points_W;
  std::vector<std::int8_t> occupancy;
  std::vector<std::int32_t> surface;
};
// Throws std::invalid_argument naming the field when the message is not a
// face (face not 0..5, unknown encoding, n^2 not the number of distances
// sent, n not 2 half_extent_m / resolution_m + 1, an id plane whose arrays
// disagree, with a run not positive or runs not adding up to n^2): checked
// before anything is allocated, so a lying n costs nothing.
void CheckCompactFace(const sandbox_msgs::scan_face_compact_t& message);
FacePoints DecodeCompactFace(const sandbox_msgs::scan_face_compact_t& message);

}  // namespace sandbox::bridge
