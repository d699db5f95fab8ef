#include "bridge/foxglove_views.h"

#include <glib.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "bridge/foxglove_json.h"
#include "bridge/lcm_types.h"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"

namespace sandbox::bridge::foxglove_json {

const std::string& TimeSchema() {
  static const std::string schema =
      R"({"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}}})";
  return schema;
}

const std::string& Vector3Schema() {
  static const std::string schema =
      R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}})";
  return schema;
}

const std::string& QuaternionSchema() {
  static const std::string schema =
      R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}})";
  return schema;
}

const std::string& PoseSchema() {
  static const std::string schema = R"({"type":"object","properties":{"position":)" +
                                    Vector3Schema() + R"(,"orientation":)" + QuaternionSchema() +
                                    "}}";
  return schema;
}

const std::string& FrameTransformSchema() {
  static const std::string schema =
      R"({"title":"foxglove.FrameTransform","description":"A transform between two reference frames in 3D space","type":"object","properties":{"timestamp":)" +
      TimeSchema() +
      R"(,"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":)" +
      Vector3Schema() + R"(,"rotation":)" + QuaternionSchema() + "}}";
  return schema;
}

nlohmann::json Time(std::int64_t utime) {
  const std::int64_t sec = utime >= 0 ? utime / 1'000'000 : 0;
  return {{"sec", sec}, {"nsec", utime >= 0 ? (utime % 1'000'000) * 1000 : 0}};
}

std::string WithBase64(const nlohmann::json& message, const char* field, const void* bytes,
                       std::size_t size) {
  std::string text = message.dump();
  const std::string key = std::string("\"") + field + "\":\"";
  const std::size_t at = text.find(key);
  gchar* base64 = g_base64_encode(static_cast<const guchar*>(bytes), size);
  text.insert(at + key.size(), base64);
  g_free(base64);
  return text;
}

}  // namespace sandbox::bridge::foxglove_json

namespace sandbox::bridge {
namespace {

using nlohmann::json;

using foxglove_json::Time;

const std::string& PointCloudSchema() {
  static const std::string schema =
      R"({"title":"foxglove.PointCloud","description":"A collection of N-dimensional points, which may contain additional fields with information like normals, intensity, etc.","type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() + R"(,"frame_id":{"type":"string"},"pose":)" +
      foxglove_json::PoseSchema() +
      R"(,"point_stride":{"type":"integer","minimum":0},"fields":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"offset":{"type":"integer","minimum":0},"type":{"type":"integer","description":"1 UINT8, 2 INT8, 3 UINT16, 4 INT16, 5 UINT32, 6 INT32, 7 FLOAT32, 8 FLOAT64"}}}},"data":{"type":"string","contentEncoding":"base64"}}})";
  return schema;
}

const std::string& LocationFixSchema() {
  static const std::string schema =
      R"({"title":"foxglove.LocationFix","description":"A navigation satellite fix for any Global Navigation Satellite System","type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() +
      R"(,"frame_id":{"type":"string"},"latitude":{"type":"number"},"longitude":{"type":"number"},"altitude":{"type":"number"},"position_covariance":{"type":"array","items":{"type":"number"}},"position_covariance_type":{"type":"integer","description":"0 UNKNOWN, 1 APPROXIMATED, 2 DIAGONAL_KNOWN, 3 KNOWN"}}})";
  return schema;
}

const std::string& GridSchema() {
  static const std::string schema =
      R"({"title":"foxglove.Grid","description":"A 2D grid of data","type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() + R"(,"frame_id":{"type":"string"},"pose":)" +
      foxglove_json::PoseSchema() +
      R"(,"column_count":{"type":"integer","minimum":0},"cell_size":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}}},"row_stride":{"type":"integer","minimum":0},"cell_stride":{"type":"integer","minimum":0},"fields":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"offset":{"type":"integer","minimum":0},"type":{"type":"integer","description":"6 INT32, 7 FLOAT32"}}}},"data":{"type":"string","contentEncoding":"base64"}}})";
  return schema;
}

enum NumericType { kInt32 = 6, kFloat32 = 7 };

// Decodes an LCM message, or false.
template <typename Message>
bool Decode(const std::uint8_t* data, std::size_t size, Message* message) {
  return message->decode(data, 0, int(size)) == int(size);
}

FoxgloveView Transform(const std::string& channel, const std::string& robot, std::int64_t utime,
                       const double* position, const double* wxyz) {
  json message = {{"timestamp", Time(utime)},
                  {"parent_frame_id", "world"},
                  {"child_frame_id", robot},
                  {"translation", {{"x", position[0]}, {"y", position[1]}, {"z", position[2]}}},
                  {"rotation", {{"x", wxyz[1]}, {"y", wxyz[2]}, {"z", wxyz[3]}, {"w", wxyz[0]}}}};
  return {channel + "/tf", "foxglove.FrameTransform", &foxglove_json::FrameTransformSchema(),
          message.dump()};
}

// A point cloud's fields, packed point after point.
class Points {
 public:
  void Field(const char* name, NumericType type, int bytes) {
    fields_.push_back({{"name", name}, {"offset", stride_}, {"type", int(type)}});
    stride_ += bytes;
  }
  template <typename T>
  void Put(T value) {
    const auto* bytes = reinterpret_cast<const char*>(&value);
    data_.append(bytes, sizeof(T));
  }
  FoxgloveView View(const std::string& topic, std::int64_t utime, const double* origin) const {
    json message = {{"timestamp", Time(utime)},
                    {"frame_id", "world"},
                    {"pose",
                     {{"position", {{"x", origin[0]}, {"y", origin[1]}, {"z", origin[2]}}},
                      {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}},
                    {"point_stride", stride_},
                    {"fields", fields_},
                    {"data", ""}};
    std::string text = foxglove_json::WithBase64(message, "data", data_.data(), data_.size());
    return {topic, "foxglove.PointCloud", &PointCloudSchema(), std::move(text)};
  }

 private:
  json fields_ = json::array();
  int stride_{0};
  std::string data_;
};

std::string RobotOf(const std::string& channel) {
  const std::size_t slash = channel.rfind('/');
  return slash == std::string::npos ? channel : channel.substr(0, slash);
}

}  // namespace

bool HasFoxgloveView(const std::uint8_t* data, std::size_t size) {
  const LcmType* type = LcmTypeOf(data, size);
  return type != nullptr && (type->name == "robot_state_t" || type->name == "robot_pose_t" ||
                             type->name == "scan_face_t" || type->name == "lidar_scan_t" ||
                             type->name == "gnss_t" || type->name == "ground_map_t");
}

std::vector<FoxgloveView> FoxgloveViewsOf(const std::string& channel, const std::uint8_t* data,
                                          std::size_t size) {
  const LcmType* type = LcmTypeOf(data, size);
  if (type == nullptr) return {};
  if (type->name == "robot_state_t") {
    sandbox_msgs::robot_state_t state;
    if (!Decode(data, size, &state)) return {};
    return {Transform(channel, RobotOf(channel), state.utime, state.position, state.orientation)};
  }
  if (type->name == "robot_pose_t") {
    sandbox_msgs::robot_pose_t pose;
    if (!Decode(data, size, &pose)) return {};
    return {Transform(channel, RobotOf(channel), pose.utime, pose.position, pose.orientation)};
  }
  if (type->name == "scan_face_t") {
    sandbox_msgs::scan_face_t face;
    if (!Decode(data, size, &face) || face.num_xyz != 3 * face.num_points) return {};
    const bool ids = face.num_surface == face.num_points;
    Points points;
    for (const char* axis : {"x", "y", "z"}) points.Field(axis, kFloat32, 4);
    if (ids) points.Field("surface", kInt32, 4);
    // The occupied samples: a free or unvisited cell is no surface to show.
    for (int k = 0; k < face.num_points; ++k) {
      if (face.occupancy[std::size_t(k)] != 1) continue;
      for (int a = 0; a < 3; ++a) points.Put(face.xyz[std::size_t(3 * k + a)]);
      if (ids) points.Put(face.surface[std::size_t(k)]);
    }
    return {points.View(channel + "/points", face.utime, face.origin)};
  }
  if (type->name == "lidar_scan_t") {
    sandbox_msgs::lidar_scan_t scan;
    if (!Decode(data, size, &scan) || scan.num_xyz != 3 * scan.num_beams) return {};
    const bool ids = scan.num_surface == scan.num_beams;
    const bool intensity = scan.num_intensity == scan.num_beams;
    Points points;
    for (const char* axis : {"x", "y", "z"}) points.Field(axis, kFloat32, 4);
    points.Field("range", kFloat32, 4);
    if (ids) points.Field("surface", kInt32, 4);
    if (intensity) points.Field("intensity", kFloat32, 4);
    // The returns: a beam that hit nothing has no point.
    for (int i = 0; i < scan.num_beams; ++i) {
      if (scan.hit[std::size_t(i)] == 0) continue;
      for (int a = 0; a < 3; ++a) points.Put(scan.xyz[std::size_t(3 * i + a)]);
      points.Put(scan.range_m[std::size_t(i)]);
      if (ids) points.Put(scan.surface[std::size_t(i)]);
      if (intensity) points.Put(scan.intensity[std::size_t(i)]);
    }
    return {points.View(channel + "/points", scan.utime, scan.origin)};
  }
  if (type->name == "gnss_t") {  // a LocationFix a fix, at the time it was taken
    sandbox_msgs::gnss_t gnss;
    if (!Decode(data, size, &gnss)) return {};
    std::vector<FoxgloveView> fixes;
    for (int i = 0; i < gnss.num_fixes; ++i) {
      const json fix = {{"timestamp", Time(gnss.fix_utime[std::size_t(i)])},
                        {"frame_id", gnss.sensor},
                        {"latitude", gnss.latitude_deg[std::size_t(i)]},
                        {"longitude", gnss.longitude_deg[std::size_t(i)]},
                        {"altitude", gnss.height_m[std::size_t(i)]},
                        {"position_covariance", std::vector<double>(9, 0.0)},
                        {"position_covariance_type", 0}};
      fixes.push_back({channel + "/fix", "foxglove.LocationFix", &LocationFixSchema(), fix.dump()});
    }
    return fixes;
  }
  if (type->name == "ground_map_t") {  // a Grid whose cells are centred on the map's points
    sandbox_msgs::ground_map_t map;
    if (!Decode(data, size, &map) || map.n <= 0 || map.num_points != map.n * map.n) return {};
    const bool ids = map.num_surface == map.num_points;
    json fields = json::array({{{"name", "height"}, {"offset", 0}, {"type", int(kFloat32)}}});
    if (ids) fields.push_back({{"name", "surface"}, {"offset", 4}, {"type", int(kInt32)}});
    const int stride = ids ? 8 : 4;
    std::string cells;
    cells.reserve(std::size_t(map.num_points * stride));
    for (int k = 0; k < map.num_points; ++k) {
      cells.append(reinterpret_cast<const char*>(&map.height[std::size_t(k)]), 4);
      if (ids) cells.append(reinterpret_cast<const char*>(&map.surface[std::size_t(k)]), 4);
    }
    const double half = map.resolution_m / 2.0;
    const json grid = {
        {"timestamp", Time(map.utime)},
        {"frame_id", "world"},
        {"pose",
         {{"position",
           {{"x", map.corner[0] - half}, {"y", map.corner[1] - half}, {"z", map.origin_z}}},
          {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}},
        {"column_count", map.n},
        {"cell_size", {{"x", map.resolution_m}, {"y", map.resolution_m}}},
        {"row_stride", map.n * stride},
        {"cell_stride", stride},
        {"fields", fields},
        {"data", ""}};
    return {{channel + "/grid", "foxglove.Grid", &GridSchema(),
             foxglove_json::WithBase64(grid, "data", cells.data(), cells.size())}};
  }
  return {};
}

}  // namespace sandbox::bridge
