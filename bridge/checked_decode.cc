#include "bridge/checked_decode.h"

#include <climits>
#include <cstring>

#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/joint_values_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace sandbox::bridge {
namespace {

// Walks an encoded message field by field. The first problem sticks; later
// calls do nothing.
class WireReader {
 public:
  WireReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  // The 8-byte fingerprint every message starts with.
  void Fingerprint(std::int64_t expected) {
    if (!Need(8, "the fingerprint")) return;
    if (BigEndian(8) != std::uint64_t(expected)) Fail("wrong fingerprint (another type?)");
    at_ += 8;
  }
  // Fields of a fixed size.
  void Fixed(std::size_t bytes, const char* fields) {
    if (Need(bytes, fields)) at_ += bytes;
  }
  // An int32 length field.
  std::int64_t Count(const char* field) {
    if (!Need(4, field)) return 0;
    const auto count = std::int32_t(std::uint32_t(BigEndian(4)));
    at_ += 4;
    if (count < 0) Fail(std::string(field) + " is negative");
    return count < 0 ? 0 : count;
  }
  // `count` items of `item_bytes` each.
  void Array(std::int64_t count, std::size_t item_bytes, const char* field) {
    const auto bytes = std::uint64_t(count) * item_bytes;
    if (error_.empty() && bytes > size_ - at_)
      return Fail(std::string(field) + " runs past the end");
    at_ += std::size_t(bytes);
  }
  // `count` strings: an int32 length that counts the terminating '\0', then
  // the bytes.
  void Strings(std::int64_t count, const char* field) {
    for (std::int64_t i = 0; i < count && error_.empty(); ++i) {
      const std::int64_t length = Count(field);
      if (!error_.empty()) return;
      if (length < 1) return Fail(std::string(field) + " has a string without its '\\0'");
      if (std::uint64_t(length) > size_ - at_) {
        return Fail(std::string(field) + " runs past the end");
      }
      if (data_[at_ + std::size_t(length) - 1] != 0) {
        return Fail(std::string(field) + " has a string without its '\\0'");
      }
      if (std::memchr(data_ + at_, 0, std::size_t(length) - 1) != nullptr) {
        return Fail(std::string(field) + " has a '\\0' inside a string");
      }
      at_ += std::size_t(length);
    }
  }
  // "" when nothing failed and every byte was used.
  std::string Finish() {
    if (error_.empty() && at_ != size_) Fail("bytes after the message");
    return error_;
  }

 private:
  bool Need(std::size_t bytes, const char* what) {
    if (!error_.empty()) return false;
    if (bytes > size_ - at_) {
      Fail(std::string("too short for ") + what);
      return false;
    }
    return true;
  }
  std::uint64_t BigEndian(int n) const {
    std::uint64_t value = 0;
    for (int i = 0; i < n; ++i) value = value << 8 | data_[at_ + std::size_t(i)];
    return value;
  }
  void Fail(const std::string& what) {
    if (error_.empty()) error_ = what;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_{0};
  std::string error_;
};

// Each type's fields after its fingerprint, as its .lcm file declares them.
using namespace sandbox_msgs;

void Layout(const robot_pose_t*, WireReader& r) { r.Fixed(8 * 2 + 8 * 7, "the pose"); }

void Layout(const bone_values_t*, WireReader& r) {
  r.Fixed(8 * 2, "utime and seq");
  r.Array(r.Count("num_values"), 8, "values");
}

void Layout(const joint_values_t*, WireReader& r) {
  r.Fixed(8 * 2, "utime and seq");
  r.Strings(r.Count("num_names"), "names");
  r.Array(r.Count("num_values"), 8, "values");
}

void Layout(const actor_placements_t*, WireReader& r) {
  r.Fixed(8 * 2, "utime and seq");
  r.Strings(r.Count("num_actors"), "names");
  r.Array(r.Count("num_positions"), 8, "positions");
  r.Array(r.Count("num_orientations"), 8, "orientations");
}

void Layout(const camera_command_t*, WireReader& r) {
  r.Fixed(8 * 2, "utime and seq");
  r.Strings(1, "active_camera");
  r.Fixed(8 * 3, "pan, tilt and zoom");
}

void Layout(const ground_map_t*, WireReader& r) {
  r.Fixed(8 * 4 + 4 + 8 + 8 * 2 + 8, "the header");
  r.Array(r.Count("num_points"), 4, "height");
  r.Array(r.Count("num_surface"), 4, "surface");
  r.Array(r.Count("num_normal"), 4, "normal");
}

void Layout(const air_data_t*, WireReader& r) {
  r.Fixed(8 * 4, "the header");
  r.Strings(1, "sensor");
  const std::int64_t n = r.Count("num_samples");
  for (const char* field :
       {"sample_utime", "static_pressure_pa", "temperature_k", "density_kg_m3",
        "pressure_altitude_m", "impact_pressure_pa", "true_airspeed_m_s", "indicated_airspeed_m_s",
        "mach", "angle_of_attack_rad", "sideslip_rad"}) {
    r.Array(n, 8, field);
  }
}

void Layout(const gnss_t*, WireReader& r) {
  r.Fixed(8 * 4, "the header");
  r.Strings(1, "sensor");
  const std::int64_t fixes = r.Count("num_fixes");
  r.Array(fixes, 8, "fix_utime");
  r.Array(fixes, 8, "latitude_deg");
  r.Array(fixes, 8, "longitude_deg");
  r.Array(fixes, 8, "height_m");
  r.Array(r.Count("num_ned"), 8, "velocity_ned");
}

void Layout(const imu_t*, WireReader& r) {
  r.Fixed(8 * 4, "the header");
  r.Strings(1, "sensor");
  r.Array(r.Count("num_samples"), 8, "sample_utime");
  const std::int64_t xyz = r.Count("num_xyz");
  r.Array(xyz, 8, "specific_force");
  r.Array(xyz, 8, "angular_rate");
}

void Layout(const lidar_scan_t*, WireReader& r) {
  r.Fixed(8 * 4 + 4, "the header");
  const std::int64_t steps = r.Count("steps");
  r.Fixed(8 * 3 + 8 + 8 * 14, "origin and the sweep's poses");
  const std::int64_t beams = r.Count("num_beams");
  r.Array(beams, 4, "range_m");
  r.Array(beams, 1, "hit");
  r.Array(r.Count("num_xyz"), 4, "xyz");
  r.Array(steps, 4, "time_s");
  r.Array(r.Count("num_surface"), 4, "surface");
  r.Array(r.Count("num_normal"), 4, "normal");
  r.Array(r.Count("num_intensity"), 4, "intensity");
  r.Array(r.Count("num_last"), 4, "last_range_m");
  r.Array(r.Count("num_last_xyz"), 4, "last_xyz");
  r.Array(r.Count("num_last_surface"), 4, "last_surface");
  r.Array(r.Count("num_last_intensity"), 4, "last_intensity");
}

void Layout(const range_t*, WireReader& r) {
  r.Fixed(8 * 4, "the header");
  r.Strings(1, "sensor");
  r.Fixed(8 * 6 + 1 + 8 + 8 * 6 + 4, "the reading");
}

void Layout(const robot_state_t*, WireReader& r) {
  r.Fixed(8 * 4 + 8 * 7, "the header and pose");
  r.Array(r.Count("num_values"), 8, "bone_values");
  r.Fixed(8 * 18 + 8 * 24, "the face frames");
}

void Layout(const scan_face_t*, WireReader& r) {
  r.Fixed(8 * 5 + 1 + 4 + 8 * 10, "the header");
  r.Array(r.Count("num_points"), 1, "occupancy");
  r.Array(r.Count("num_xyz"), 4, "xyz");
  r.Array(r.Count("num_surface"), 4, "surface");
  r.Array(r.Count("num_normal"), 4, "normal");
}

void Layout(const scan_face_compact_t*, WireReader& r) {
  r.Fixed(8 * 5 + 1 + 4 + 8 * 13 + 1, "the header");
  r.Array(r.Count("num_mm"), 2, "distance_mm");
  r.Array(r.Count("num_m"), 4, "distance_m");
  const std::int64_t runs = r.Count("num_runs");
  r.Array(runs, 4, "run_surface");
  r.Array(runs, 4, "run_length");
}

void Layout(const status_t*, WireReader& r) {
  r.Fixed(8 * 5, "the header");
  const std::int64_t channels = r.Count("num_channels");
  r.Strings(channels, "channels");
  r.Array(channels, 8 * 3 + 1, "the counters");
  r.Strings(channels, "last_reject_reason");
}

void Layout(const surface_table_t*, WireReader& r) {
  r.Fixed(8 * 3, "the header");
  const std::int64_t surfaces = r.Count("num_surfaces");
  r.Array(surfaces, 4, "id");
  r.Strings(surfaces, "kind");
  r.Strings(surfaces, "name");
  r.Array(surfaces, 4, "actor");
  r.Strings(surfaces, "robot");
  r.Strings(surfaces, "bone");
  r.Array(surfaces, 4, "reflectivity");
}

void Layout(const wrench_t*, WireReader& r) {
  r.Fixed(8 * 3, "the header");
  r.Strings(1, "frame");
  r.Fixed(8 * 9, "point, force and torque");
}

}  // namespace

template <typename Message>
std::string CheckLayout(const std::uint8_t* data, std::size_t size) {
  const std::string prefix = std::string("cannot decode as ") + Message::getTypeName() + ": ";
  if (size > std::size_t(INT_MAX)) return prefix + "over 2 GB";
  WireReader reader(data, size);
  reader.Fingerprint(Message::getHash());
  Layout(static_cast<const Message*>(nullptr), reader);
  const std::string problem = reader.Finish();
  return problem.empty() ? problem : prefix + problem;
}

template <typename Message>
std::string DecodeChecked(const std::uint8_t* data, std::size_t size, Message* message) {
  if (std::string problem = CheckLayout<Message>(data, size); !problem.empty()) return problem;
  if (message->decode(data, 0, int(size)) != int(size)) {
    return std::string("cannot decode as ") + Message::getTypeName();
  }
  return "";
}

#define SANDBOX_CHECKED_DECODE(Type)                                        \
  template std::string CheckLayout<Type>(const std::uint8_t*, std::size_t); \
  template std::string DecodeChecked<Type>(const std::uint8_t*, std::size_t, Type*);

SANDBOX_CHECKED_DECODE(actor_placements_t)
SANDBOX_CHECKED_DECODE(air_data_t)
SANDBOX_CHECKED_DECODE(bone_values_t)
SANDBOX_CHECKED_DECODE(camera_command_t)
SANDBOX_CHECKED_DECODE(gnss_t)
SANDBOX_CHECKED_DECODE(ground_map_t)
SANDBOX_CHECKED_DECODE(imu_t)
SANDBOX_CHECKED_DECODE(joint_values_t)
SANDBOX_CHECKED_DECODE(lidar_scan_t)
SANDBOX_CHECKED_DECODE(range_t)
SANDBOX_CHECKED_DECODE(robot_pose_t)
SANDBOX_CHECKED_DECODE(robot_state_t)
SANDBOX_CHECKED_DECODE(scan_face_t)
SANDBOX_CHECKED_DECODE(scan_face_compact_t)
SANDBOX_CHECKED_DECODE(status_t)
SANDBOX_CHECKED_DECODE(surface_table_t)
SANDBOX_CHECKED_DECODE(wrench_t)

#undef SANDBOX_CHECKED_DECODE

}  // namespace sandbox::bridge
