#pragma once
// Foxglove's well-known schemas for what the run knows but publishes on no
// LCM channel: a robot's link or bone frames (foxglove.FrameTransforms), a
// camera's frames (foxglove.CompressedImage, foxglove.CameraCalibration and
// the camera's FrameTransform) and the level's and robots' geometry
// (foxglove.SceneUpdate). JSON encoding, as foxglove_views.h. Threads: any
// (no state).

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "bridge/foxglove_views.h"

namespace sandbox::bridge {

// The frame Foxglove knows a robot by: its channel prefix, the
// FrameTransform that a robot's STATE becomes (foxglove_views.h) ends in.
// Its links are "<robot>/<link>", its cameras "<robot>/camera/<camera>".
std::string FoxgloveLinkFrame(const std::string& robot_frame, const std::string& link);

struct NamedPose {
  std::string child;  // frame id
  Eigen::Isometry3d X_PC;
};

// foxglove.FrameTransforms on `topic`: each child's pose in `parent`.
FoxgloveView FrameTransforms(const std::string& topic, const std::string& parent,
                             const std::vector<NamedPose>& children, std::int64_t utime);

// A camera frame as foxglove.CompressedImage ("jpeg" or "png" bytes) in
// `frame_id`, an optical frame (x right, y down, z forward).
FoxgloveView CompressedImage(const std::string& topic, const std::string& frame_id,
                             const std::string& format, const std::string& bytes,
                             std::int64_t utime);

// A camera's intrinsics as foxglove.CameraCalibration: `model` "plumb_bob"
// (D = k1 k2 p1 p2 k3), "kannala_brandt" (D = k1 k2 k3 k4) or "" (a pinhole:
// plumb_bob with D zero); K from fx, fy, cx, cy (pixel centres at whole
// coordinates, OpenCV's), R identity, P = [K | 0].
struct Intrinsics {
  int width{0}, height{0};
  double fx{0.0}, fy{0.0}, cx{0.0}, cy{0.0};
  std::string model;
  std::vector<double> D;
};
FoxgloveView CameraCalibration(const std::string& topic, const std::string& frame_id,
                               const Intrinsics& intrinsics, std::int64_t utime);

// The optical frame (x right, y down, z forward) in a camera frame whose x
// looks forward, y left and z up (render::CameraView's).
Eigen::Isometry3d OpticalInCamera();

// One foxglove.SceneEntity: a triangle list in `frame_id` at `X_FE`.
struct SceneMesh {
  std::string id;        // unique within the topic
  std::string frame_id;  // "world", a robot's link frame, ...
  Eigen::Isometry3d X_FE{Eigen::Isometry3d::Identity()};
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::uint32_t> indices;  // three a triangle
  float rgba[4]{0.7f, 0.7f, 0.7f, 1.0f};
};
// foxglove.SceneUpdate adding (or replacing) the entities, never expiring;
// its JSON schema.
const std::string& SceneUpdateSchema();
FoxgloveView SceneUpdate(const std::string& topic, const std::vector<SceneMesh>& meshes,
                         std::int64_t utime);

}  // namespace sandbox::bridge
