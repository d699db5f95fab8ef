#include "bridge/foxglove_messages.h"

#include <charconv>
#include <nlohmann/json.hpp>

#include "bridge/foxglove_json.h"

namespace sandbox::bridge {
namespace {

using foxglove_json::Time;
using nlohmann::json;

const std::string& FrameTransformsSchema() {
  static const std::string schema =
      R"({"title":"foxglove.FrameTransforms","description":"An array of FrameTransform messages","type":"object","properties":{"transforms":{"type":"array","items":)" +
      foxglove_json::FrameTransformSchema() + "}}}";
  return schema;
}

const std::string& CompressedImageSchema() {
  static const std::string schema =
      R"({"title":"foxglove.CompressedImage","description":"A compressed image","type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() +
      R"(,"frame_id":{"type":"string"},"data":{"type":"string","contentEncoding":"base64"},"format":{"type":"string"}}})";
  return schema;
}

const std::string& CameraCalibrationSchema() {
  static const std::string numbers = R"({"type":"array","items":{"type":"number"}})";
  static const std::string schema =
      R"({"title":"foxglove.CameraCalibration","description":"Camera calibration parameters","type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() +
      R"(,"frame_id":{"type":"string"},"width":{"type":"integer","minimum":0},"height":{"type":"integer","minimum":0},"distortion_model":{"type":"string"},"D":)" +
      numbers + R"(,"K":)" + numbers + R"(,"R":)" + numbers + R"(,"P":)" + numbers + "}}";
  return schema;
}

}  // namespace

const std::string& SceneUpdateSchema() {
  static const std::string color =
      R"({"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}})";
  static const std::string empty = R"({"type":"array","items":{"type":"object"}})";
  static const std::string triangles =
      R"({"type":"array","items":{"type":"object","properties":{"pose":)" +
      foxglove_json::PoseSchema() + R"(,"points":{"type":"array","items":)" +
      foxglove_json::Vector3Schema() + R"(},"color":)" + color +
      R"(,"colors":{"type":"array","items":)" + color +
      R"(},"indices":{"type":"array","items":{"type":"integer","minimum":0}}}}})";
  static const std::string schema =
      R"({"title":"foxglove.SceneUpdate","description":"An update to the entities displayed in a 3D scene","type":"object","properties":{"deletions":)" +
      empty + R"(,"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":)" +
      foxglove_json::TimeSchema() +
      R"(,"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":)" +
      foxglove_json::TimeSchema() + R"(,"frame_locked":{"type":"boolean"},"metadata":)" + empty +
      R"(,"arrows":)" + empty + R"(,"cubes":)" + empty + R"(,"spheres":)" + empty +
      R"(,"cylinders":)" + empty + R"(,"lines":)" + empty + R"(,"triangles":)" + triangles +
      R"(,"texts":)" + empty + R"(,"models":)" + empty + "}}}}}";
  return schema;
}

namespace {

json Vector(const Eigen::Vector3d& v) { return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}}; }

json Rotation(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  return {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}};
}

json Pose(const Eigen::Isometry3d& X) {
  return {{"position", Vector(X.translation())}, {"orientation", Rotation(X)}};
}

void Append(std::string* out, float value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
  out->append(buffer, end);
}

}  // namespace

std::string FoxgloveLinkFrame(const std::string& robot_frame, const std::string& link) {
  return robot_frame + "/" + link;
}

FoxgloveView FrameTransforms(const std::string& topic, const std::string& parent,
                             const std::vector<NamedPose>& children, std::int64_t utime) {
  json transforms = json::array();
  const json stamp = Time(utime);
  for (const NamedPose& child : children) {
    transforms.push_back({{"timestamp", stamp},
                          {"parent_frame_id", parent},
                          {"child_frame_id", child.child},
                          {"translation", Vector(child.X_PC.translation())},
                          {"rotation", Rotation(child.X_PC)}});
  }
  return {topic, "foxglove.FrameTransforms", &FrameTransformsSchema(),
          json{{"transforms", transforms}}.dump()};
}

FoxgloveView CompressedImage(const std::string& topic, const std::string& frame_id,
                             const std::string& format, const std::string& bytes,
                             std::int64_t utime) {
  const json message = {
      {"timestamp", Time(utime)}, {"frame_id", frame_id}, {"data", ""}, {"format", format}};
  return {topic, "foxglove.CompressedImage", &CompressedImageSchema(),
          foxglove_json::WithBase64(message, "data", bytes.data(), bytes.size())};
}

FoxgloveView CameraCalibration(const std::string& topic, const std::string& frame_id,
                               const Intrinsics& in, std::int64_t utime) {
  std::vector<double> D = in.D;
  std::string model = in.model;
  if (model.empty()) model = "plumb_bob", D.assign(5, 0.0);
  const json message = {
      {"timestamp", Time(utime)},
      {"frame_id", frame_id},
      {"width", in.width},
      {"height", in.height},
      {"distortion_model", model},
      {"D", D},
      {"K", {in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0}},
      {"R", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
      {"P", {in.fx, 0.0, in.cx, 0.0, 0.0, in.fy, in.cy, 0.0, 0.0, 0.0, 1.0, 0.0}}};
  return {topic, "foxglove.CameraCalibration", &CameraCalibrationSchema(), message.dump()};
}

Eigen::Isometry3d OpticalInCamera() {
  Eigen::Matrix3d R;                     // columns: the optical axes in the camera frame
  R.col(0) = -Eigen::Vector3d::UnitY();  // right
  R.col(1) = -Eigen::Vector3d::UnitZ();  // down
  R.col(2) = Eigen::Vector3d::UnitX();   // forward
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  return X;
}

FoxgloveView SceneUpdate(const std::string& topic, const std::vector<SceneMesh>& meshes,
                         std::int64_t utime) {
  // The points and indices are written by hand: a level's million vertices
  // through the JSON library's objects cost seconds.
  const json stamp = Time(utime);
  std::string text = R"({"deletions":[],"entities":[)";
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const SceneMesh& mesh = meshes[m];
    if (m > 0) text += ',';
    const json head = {{"timestamp", stamp},
                       {"frame_id", mesh.frame_id},
                       {"id", mesh.id},
                       {"lifetime", {{"sec", 0}, {"nsec", 0}}},
                       {"frame_locked", true}};
    text += head.dump();
    text.pop_back();  // the closing brace: the primitives follow
    text += R"(,"metadata":[],"arrows":[],"cubes":[],"spheres":[],"cylinders":[],"lines":[],)";
    text += R"("texts":[],"models":[],"triangles":[{"pose":)" + Pose(mesh.X_FE).dump();
    text += R"(,"color":)" +
            json{{"r", mesh.rgba[0]}, {"g", mesh.rgba[1]}, {"b", mesh.rgba[2]}, {"a", mesh.rgba[3]}}
                .dump();
    text += R"(,"colors":[],"points":[)";
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      text += v > 0 ? R"(,{"x":)" : R"({"x":)";
      Append(&text, mesh.vertices[v].x());
      text += R"(,"y":)";
      Append(&text, mesh.vertices[v].y());
      text += R"(,"z":)";
      Append(&text, mesh.vertices[v].z());
      text += '}';
    }
    text += R"(],"indices":[)";
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
      if (i > 0) text += ',';
      text += std::to_string(mesh.indices[i]);
    }
    text += "]}]}";
  }
  text += "]}";
  return {topic, "foxglove.SceneUpdate", &SceneUpdateSchema(), std::move(text)};
}

}  // namespace sandbox::bridge
