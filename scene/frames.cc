#include "scene/frames.h"

#include <cctype>
#include <utility>

namespace sandbox::scene {

namespace {

// Each axis with its name, for parsing and printing alike.
constexpr std::pair<UpAxis, std::string_view> kAxisNames[] = {
    {UpAxis::kPosX, "x"},  {UpAxis::kNegX, "-x"}, {UpAxis::kPosY, "y"},
    {UpAxis::kNegY, "-y"}, {UpAxis::kPosZ, "z"},  {UpAxis::kNegZ, "-z"}};

}  // namespace

std::optional<UpAxis> ParseUpAxis(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const auto& [axis, name] : kAxisNames) {
    if (lower == name) return axis;
  }
  return std::nullopt;
}

std::string ToString(UpAxis axis) {
  for (const auto& [candidate, name] : kAxisNames) {
    if (candidate == axis) return std::string(name);
  }
  return "?";
}

Eigen::Vector3d AxisDirection(UpAxis axis) {
  const int index = static_cast<int>(axis);  // kPosX, kNegX, kPosY, ... in pairs
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  direction[index / 2] = index % 2 == 0 ? 1.0 : -1.0;
  return direction;
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
