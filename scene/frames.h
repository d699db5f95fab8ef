#pragma once
// World frame conventions (../shared/DESIGN.md): right-handed, Z up, metres,
// radians; roll-pitch-yaw means R = Rz(yaw) * Ry(pitch) * Rx(roll).

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>

namespace sandbox::scene {

// The axis an asset file treats as up.
enum class UpAxis { kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ };

// Parses "x", "-x", "y", "-y", "z", "-z" (also with a leading "+"); nullopt otherwise.
std::optional<UpAxis> ParseUpAxis(std::string_view text);
std::string ToString(UpAxis axis);

// The unit vector of an axis: kNegY is (0, -1, 0).
Eigen::Vector3d AxisDirection(UpAxis axis);

// The rotation R_WF that takes coordinates of a file whose up is `up` to the
// world frame. kPosY maps asset (x, y, z) to world (x, -z, y) (+90 degrees
// about X, as Blender does); kPosZ is the identity.
Eigen::Matrix3d UpAxisToWorld(UpAxis up);

// R = Rz(yaw) * Ry(pitch) * Rx(roll); angles in radians.
Eigen::Matrix3d RotationFromRollPitchYaw(double roll_rad, double pitch_rad, double yaw_rad);

constexpr double kDegToRad = 0.017453292519943295;

}  // namespace sandbox::scene
