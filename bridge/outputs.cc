#include "bridge/outputs.h"

#include <map>
#include <variant>

#include "bridge/face_points.h"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"

namespace sandbox::bridge {

namespace {

// What every output's header says: when, and the input it was computed from
// (Send numbers it on its channel).
struct Header {
  const std::string& sensor;
  std::int64_t tick;
  InputTag input;
  std::int64_t now_utime;

  template <typename Message>
  void Stamp(Message* message) const {
    message->utime = now_utime;
    message->input_seq = input.seq;
    message->input_utime = input.utime;
  }
};

// World points as float offsets from a double origin, flat.
void Offsets(const std::vector<Eigen::Vector3d>& points_W, const Eigen::Vector3d& origin,
             std::vector<float>* xyz) {
  xyz->resize(3 * points_W.size());
  for (std::size_t i = 0; i < points_W.size(); ++i) {
    const Eigen::Vector3d offset = points_W[i] - origin;
    for (int k = 0; k < 3; ++k) (*xyz)[3 * i + std::size_t(k)] = float(offset[k]);
  }
}

// What each sample hit: its surface id (when published) and normal (when
// kept), into the message's surface and normal arrays.
template <typename Message>
void SurfaceFields(bool ids, const std::vector<std::int32_t>& surface,
                   const std::vector<Eigen::Vector3f>& normal_W, Message* message) {
  message->num_surface = ids ? int(surface.size()) : 0;
  if (ids) {
    message->surface = surface;
  } else {
    message->surface.clear();
  }
  message->num_normal = int(3 * normal_W.size());
  message->normal.resize(3 * normal_W.size());
  for (std::size_t i = 0; i < normal_W.size(); ++i) {
    for (int k = 0; k < 3; ++k) message->normal[3 * i + std::size_t(k)] = normal_W[i][k];
  }
}

// A pose as position and w, x, y, z.
void PoseFields(const Eigen::Isometry3d& X, double position[3], double orientation[4]) {
  const Eigen::Quaterniond q(X.linear());
  for (int k = 0; k < 3; ++k) position[k] = X.translation()[k];
  orientation[0] = q.w(), orientation[1] = q.x(), orientation[2] = q.y(), orientation[3] = q.z();
}

}  // namespace

RobotOutputs::RobotOutputs(LcmLink& link, std::string channel_prefix,
                           const Translation& state_translation)
    : link_(link),
      prefix_(std::move(channel_prefix) + "/"),
      state_translation_(state_translation) {}

template <typename Message>
void RobotOutputs::Send(const std::string& topic, Message& message) {
  message.seq = next_seq_[topic]++;  // each channel counts its own messages
  buffer_.resize(std::size_t(message.getEncodedSize()));
  message.encode(buffer_.data(), 0, int(buffer_.size()));
  if (link_.Publish(prefix_ + topic, buffer_.data(), unsigned(buffer_.size()))) ++published_;
}

void CheckOutputChannels(const scene::Level& level) {
  for (const scene::RobotModel& robot : level.robots) {
    std::map<std::string, const scene::SensorSpec*> used;
    for (const scene::SensorSpec& spec : robot.sensors) {
      const std::string channel = sensors::OutputChannel(spec);
      const auto [it, fresh] = used.emplace(channel, &spec);
      const sensors::SensorKind kind = sensors::ParseSensorKind(spec);
      if (!fresh &&
          !(sensors::Info(kind).shares_channel && kind == sensors::ParseSensorKind(*it->second))) {
        throw scene::LevelError(spec.Where() + "publishes on " + channel + " like sensor '" +
                                it->second->name + "'; give one of them its own 'channel'");
      }
    }
  }
}

namespace {

// Each kind's publish function: its output as messages, handed to `send`.
// (Adding a sensor kind adds one here.)

template <typename Send>
void PublishOutput(const sensors::FaceScan& scan, const Header& header, Send&& send) {
  for (int f = 0; f < 6; ++f) {
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    if (face.tick != header.tick) continue;  // only the faces this tick refreshed
    if (scan.encoding != sensors::FaceEncoding::kPoints) {
      sandbox_msgs::scan_face_compact_t message{};
      header.Stamp(&message);
      message.tick = header.tick;
      EncodeCompactFace(scan, f, &message);
      send(message);
      continue;
    }
    sandbox_msgs::scan_face_t message{};
    header.Stamp(&message);
    message.tick = header.tick;
    message.face = std::int8_t(f);
    message.n = scan.n;
    const Eigen::Vector3d p = face.X_WS.translation();
    PoseFields(face.X_WS, message.sensor_position, message.sensor_orientation);
    for (int k = 0; k < 3; ++k) message.origin[k] = p[k];
    const std::size_t n = face.occupancy.size();
    message.num_points = int(n);
    message.occupancy = face.occupancy;
    message.num_xyz = int(3 * n);
    Offsets(scan.PointsW(f), p, &message.xyz);
    SurfaceFields(scan.surface_ids, face.surface, face.normal_W, &message);
    send(message);
  }
}

template <typename Send>
void PublishOutput(const sensors::HeightMap& map, const Header& header, Send&& send) {
  sandbox_msgs::ground_map_t message{};
  header.Stamp(&message);
  message.n = map.n;
  message.resolution_m = map.resolution_m;
  message.corner[0] = map.corner_W.x(), message.corner[1] = map.corner_W.y();
  message.origin_z = 0.0;
  message.num_points = int(map.height_m.size());
  message.height.assign(map.height_m.begin(), map.height_m.end());
  SurfaceFields(map.surface_ids, map.surface, map.normal_W, &message);
  send(message);
}

template <typename Send>
void PublishOutput(const sensors::LidarScan& scan, const Header& header, Send&& send) {
  sandbox_msgs::lidar_scan_t message{};
  header.Stamp(&message);
  message.channels = scan.channels;
  message.steps = scan.azimuth_steps;
  const Eigen::Vector3d& origin = scan.origin_W;
  for (int k = 0; k < 3; ++k) message.origin[k] = origin[k];
  message.sweep_s = scan.sweep_s;
  PoseFields(scan.X_WS_start, message.start_position, message.start_orientation);
  PoseFields(scan.X_WS_end, message.end_position, message.end_orientation);
  const std::size_t n = scan.range_m.size();
  message.num_beams = int(n);
  message.range_m = scan.range_m;
  message.hit.assign(scan.hit.begin(), scan.hit.end());
  message.num_xyz = int(3 * n);
  Offsets(scan.points_W, origin, &message.xyz);
  message.time_s.assign(scan.time_s.begin(), scan.time_s.end());
  SurfaceFields(scan.surface_ids, scan.surface, scan.normal_W, &message);
  message.num_intensity = int(scan.intensity.size());
  message.intensity = scan.intensity;
  message.num_last = int(scan.last_range_m.size());
  message.last_range_m = scan.last_range_m;
  message.num_last_xyz = int(3 * scan.last_points_W.size());
  Offsets(scan.last_points_W, origin, &message.last_xyz);
  message.num_last_surface = scan.surface_ids ? int(scan.last_surface.size()) : 0;
  if (scan.surface_ids) message.last_surface = scan.last_surface;
  message.num_last_intensity = int(scan.last_intensity.size());
  message.last_intensity = scan.last_intensity;
  send(message);
}

// Several range sensors may share a channel: the message names its sensor.
template <typename Send>
void PublishOutput(const sensors::RangeReading& reading, const Header& header, Send&& send) {
  sandbox_msgs::range_t message{};
  header.Stamp(&message);
  message.sensor = header.sensor;
  for (int k = 0; k < 3; ++k) {
    message.origin[k] = reading.origin_W[k];
    message.direction[k] = reading.direction_W[k];
    message.point[k] = reading.point_W[k];
    message.normal[k] = reading.normal_W[k];
  }
  message.hit = reading.hit ? 1 : 0;
  message.range_m = reading.range_m;
  message.surface = reading.surface;
  send(message);
}

// Several IMUs may share a channel: the message names its sensor. Nothing
// when no sample was due (no new pose).
template <typename Send>
void PublishOutput(const sensors::ImuSamples& samples, const Header& header, Send&& send) {
  if (samples.utime.empty()) return;
  sandbox_msgs::imu_t message{};
  header.Stamp(&message);
  message.sensor = header.sensor;
  const std::size_t n = samples.utime.size();
  message.num_samples = int(n);
  message.sample_utime = samples.utime;
  message.num_xyz = int(3 * n);
  message.specific_force.resize(3 * n);
  message.angular_rate.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      message.specific_force[3 * i + std::size_t(k)] = samples.specific_force_S[i][k];
      message.angular_rate[3 * i + std::size_t(k)] = samples.angular_rate_S[i][k];
    }
  }
  send(message);
}

// Several receivers may share a channel: the message names its sensor.
// Nothing when no fix was released.
template <typename Send>
void PublishOutput(const sensors::GnssFixes& released, const Header& header, Send&& send) {
  if (released.fixes.empty()) return;
  sandbox_msgs::gnss_t message{};
  header.Stamp(&message);
  message.sensor = header.sensor;
  const std::size_t n = released.fixes.size();
  message.num_fixes = int(n);
  message.num_ned = int(3 * n);
  message.velocity_ned.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const sensors::GnssFix& fix = released.fixes[i];
    message.fix_utime.push_back(fix.utime);
    message.latitude_deg.push_back(fix.latitude_deg);
    message.longitude_deg.push_back(fix.longitude_deg);
    message.height_m.push_back(fix.height_m);
    for (int k = 0; k < 3; ++k) message.velocity_ned[3 * i + std::size_t(k)] = fix.velocity_ned[k];
  }
  send(message);
}

// Several air data computers may share a channel: the message names its
// sensor. Nothing when no sample was due.
template <typename Send>
void PublishOutput(const sensors::AirDataSamples& taken, const Header& header, Send&& send) {
  if (taken.samples.empty()) return;
  sandbox_msgs::air_data_t message{};
  header.Stamp(&message);
  message.sensor = header.sensor;
  message.num_samples = int(taken.samples.size());
  for (const sensors::AirDataSample& s : taken.samples) {
    message.sample_utime.push_back(s.utime);
    message.static_pressure_pa.push_back(s.static_pressure_pa);
    message.temperature_k.push_back(s.temperature_k);
    message.density_kg_m3.push_back(s.density_kg_m3);
    message.pressure_altitude_m.push_back(s.pressure_altitude_m);
    message.impact_pressure_pa.push_back(s.impact_pressure_pa);
    message.true_airspeed_m_s.push_back(s.true_airspeed_m_s);
    message.indicated_airspeed_m_s.push_back(s.indicated_airspeed_m_s);
    message.mach.push_back(s.mach);
    message.angle_of_attack_rad.push_back(s.angle_of_attack_rad);
    message.sideslip_rad.push_back(s.sideslip_rad);
  }
  send(message);
}

}  // namespace

void RobotOutputs::Publish(const sensors::SensorOutput& output, const Address& to,
                           std::int64_t tick, const InputTag& input, std::int64_t now_utime) {
  const Header header{to.sensor, tick, input, now_utime};
  std::visit(
      [&](const auto& value) {
        PublishOutput(value, header, [&](auto& message) { Send(to.channel, message); });
      },
      output);
}

void RobotOutputs::PublishState(const scene::RobotState& state, const InputTag& input,
                                std::int64_t now_utime, const FaceFrames* X_WF) {
  sandbox_msgs::robot_state_t message{};
  Header{"", 0, input, now_utime}.Stamp(&message);
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
  state_translation_.FromWorld(state.pose(), &p, &q);
  for (int k = 0; k < 3; ++k) message.position[k] = p[k];
  message.orientation[0] = q.w(), message.orientation[1] = q.x();
  message.orientation[2] = q.y(), message.orientation[3] = q.z();
  message.num_values = int(state.bone_values().size());
  message.bone_values = state.bone_values();
  // Face frames in the robot frame (the sandbox's own body axes); without a
  // face scanner, the robot frame itself.
  for (int f = 0; f < 6; ++f) {
    Eigen::Isometry3d X_RF = Eigen::Isometry3d::Identity();
    if (X_WF != nullptr) X_RF = state.pose().inverse() * (*X_WF)[std::size_t(f)];
    PoseFields(X_RF, &message.face_positions[3 * f], &message.face_orientations[4 * f]);
  }
  Send("STATE", message);
}

void RobotOutputs::PublishStatus(double loop_rate_hz, std::int64_t ticks, std::int64_t overruns,
                                 const std::vector<ChannelStatus>& channels,
                                 std::int64_t now_utime) {
  sandbox_msgs::status_t message{};
  message.utime = now_utime;
  message.loop_rate_hz = loop_rate_hz;
  message.ticks = ticks;
  message.overruns = overruns;
  message.num_channels = int(channels.size());
  for (const ChannelStatus& c : channels) {
    message.channels.push_back(c.channel);
    message.received.push_back(c.received);
    message.superseded.push_back(c.superseded);
    message.rejected.push_back(c.rejected);
    message.stale.push_back(c.stale ? 1 : 0);
    message.last_reject_reason.push_back(c.last_reject_reason);
  }
  Send("STATUS", message);
}

void RobotOutputs::PublishSurfaces(const std::vector<scene::SurfaceEntry>& table,
                                   std::uint64_t revision, std::int64_t now_utime) {
  sandbox_msgs::surface_table_t message{};
  message.utime = now_utime;
  message.revision = std::int64_t(revision);
  message.num_surfaces = int(table.size());
  for (const scene::SurfaceEntry& entry : table) {
    message.id.push_back(entry.id);
    message.kind.push_back(entry.kind);
    message.name.push_back(entry.name);
    message.actor.push_back(entry.actor);
    message.robot.push_back(entry.robot_name);
    message.bone.push_back(entry.bone_name);
    message.reflectivity.push_back(entry.reflectivity);
  }
  Send("WORLD", message);
}

}  // namespace sandbox::bridge
