#pragma once
// The sandbox's messages as Foxglove's well-known schemas, for MCAP
// recordings that Foxglove and Lichtblick show without knowing LCM: a robot's
// pose (robot_state_t, robot_pose_t) as foxglove.FrameTransform from "world"
// to the robot, face scans (scan_face_t, their occupied samples) and lidar
// sweeps (lidar_scan_t, their returns) as foxglove.PointCloud in "world" with
// their hit ids and intensities as fields, GNSS fixes (gnss_t) as
// foxglove.LocationFix, ground maps (ground_map_t) as foxglove.Grid. JSON encoding (schema encoding "jsonschema"), bytes as
// base64, as Foxglove's JSON schemas say. Threads: any (no state).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sandbox::bridge {

struct FoxgloveView {
  std::string topic;                   // "<channel>/tf" or "<channel>/points"
  std::string schema_name;             // "foxglove.FrameTransform"
  const std::string* schema{nullptr};  // its JSON schema
  std::string json;                    // the message
};

// A view made when (and where) it is needed: on a recording's writer thread
// or the live server's thread, never on the loop's.
using MakeView = std::function<FoxgloveView()>;

// Whether the message is of a type with a view (a look at its fingerprint).
bool HasFoxgloveView(const std::uint8_t* data, std::size_t size);

// The views of one LCM message on `channel` (none for other types or a
// message that does not decode).
std::vector<FoxgloveView> FoxgloveViewsOf(const std::string& channel, const std::uint8_t* data,
                                          std::size_t size);

}  // namespace sandbox::bridge
