#include "scene/frames.h"

namespace sandbox::scene {

std::optional<UpAxis> ParseUpAxis(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text == "x" || text == "X") return UpAxis::kPosX;
  if (text == "-x" || text == "-X") return UpAxis::kNegX;
  if (text == "y" || text == "Y") return UpAxis::kPosY;
  if (text == "-y" || text == "-Y") return UpAxis::kNegY;
  if (text == "z" || text == "Z") return UpAxis::kPosZ;
  if (text == "-z" || text == "-Z") return UpAxis::kNegZ;
  return std::nullopt;
}

std::string ToString(UpAxis axis) {
  switch (axis) {
    case UpAxis::kPosX:
      return "x";
    case UpAxis::kNegX:
      return "-x";
    case UpAxis::kPosY:
      return "y";
    case UpAxis::kNegY:
      return "-y";
    case UpAxis::kPosZ:
      return "z";
    case UpAxis::kNegZ:
      return "-z";
  }
  return "?";
}

Eigen::Matrix3d UpAxisToWorld(UpAxis up) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  const double half_pi = 0.5 * 3.14159265358979323846;
  switch (up) {
    case UpAxis::kPosX:
      return AngleAxisd(-half_pi, Vector3d::UnitY()).toRotationMatrix();
    case UpAxis::kNegX:
      return AngleAxisd(half_pi, Vector3d::UnitY()).toRotationMatrix();
    case UpAxis::kPosY:
      return AngleAxisd(half_pi, Vector3d::UnitX()).toRotationMatrix();
    case UpAxis::kNegY:
      return AngleAxisd(-half_pi, Vector3d::UnitX()).toRotationMatrix();
    case UpAxis::kPosZ:
      return Eigen::Matrix3d::Identity();
    case UpAxis::kNegZ:
      return AngleAxisd(2.0 * half_pi, Vector3d::UnitX()).toRotationMatrix();
  }
  return Eigen::Matrix3d::Identity();
}

Eigen::Matrix3d RotationFromRollPitchYaw(double roll_rad, double pitch_rad, double yaw_rad) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return (AngleAxisd(yaw_rad, Vector3d::UnitZ()) * AngleAxisd(pitch_rad, Vector3d::UnitY()) *
          AngleAxisd(roll_rad, Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace sandbox::scene
