#include "bridge/example_flight.h"

#include <cmath>

namespace sandbox::bridge {
namespace {

// The wing's circle: 120 m around the level's centre at 15 m/s.
constexpr double kRadius_m = 120.0, kSpeed_mps = 15.0;

// Rz(yaw) Ry(pitch) Rx(roll) as (w, x, y, z).
void SetRpy(double roll, double pitch, double yaw, double* wxyz) {
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2), cp = std::cos(pitch / 2),
               sp = std::sin(pitch / 2), cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  wxyz[0] = cy * cp * cr + sy * sp * sr;
  wxyz[1] = cy * cp * sr - sy * sp * cr;
  wxyz[2] = cy * sp * cr + sy * cp * sr;
  wxyz[3] = sy * cp * cr - cy * sp * sr;
}

}  // namespace

void ExampleFlight(double t, std::int64_t seq, std::int64_t utime, sandbox_msgs::robot_pose_t* pose,
                   sandbox_msgs::bone_values_t* bones) {
  // A 120 m circle at 15 m/s, banked into the turn.
  const double radius = kRadius_m, speed = kSpeed_mps, w = speed / radius, a = w * t;
  *pose = {};
  pose->utime = utime;
  pose->seq = seq;
  pose->position[0] = radius * std::cos(a);
  pose->position[1] = radius * std::sin(a);
  pose->position[2] = 60.0 + 5.0 * std::sin(0.3 * t);
  const double yaw = a + M_PI / 2, roll = -0.2;  // heading along the circle, banked left
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2), cr = std::cos(roll / 2),
               sr = std::sin(roll / 2);
  pose->orientation[0] = cy * cr;  // Rz(yaw) Rx(roll)
  pose->orientation[1] = cy * sr;
  pose->orientation[2] = sy * sr;
  pose->orientation[3] = sy * cr;

  // Bones: root (2 angles), R1-R10 and L1-L10 (roll, pitch), E1-E3 (pitch).
  *bones = {};
  bones->utime = utime;
  bones->seq = seq;
  bones->num_values = 45;
  bones->values.assign(45, 0.0);
  const double bend = 0.06 * std::sin(1.5 * t);  // up to 3.4 degrees a joint
  for (int b = 1; b <= 20; ++b) bones->values[std::size_t(2 * b)] = b <= 10 ? bend : -bend;
  for (int e = 0; e < 3; ++e) bones->values[std::size_t(42 + e)] = 0.2 * std::sin(2.0 * t + e);
}

void HighlandsFlight(double t, std::int64_t seq, std::int64_t utime,
                     sandbox_msgs::robot_pose_t* pose, sandbox_msgs::bone_values_t* bones) {
  constexpr double kScale_m = 12000.0, kCeiling_m = 20000.0;
  const double x = kHighlandsSpeed_mps * std::max(0.0, t);
  const double climb = std::exp(-x / kScale_m);
  *pose = {};
  pose->utime = utime;
  pose->seq = seq;
  pose->position[0] = x;
  pose->position[1] = 0.0;
  pose->position[2] = 2.0 + kCeiling_m * (1.0 - climb);
  const double pitch = -std::atan(kCeiling_m / kScale_m * climb);  // nose up: negative about y
  SetRpy(0.0, pitch, 0.0, pose->orientation);
  *bones = {};
  bones->utime = utime;
  bones->seq = seq;
  bones->num_values = 45;
  bones->values.assign(45, 0.0);
  const double bend = 0.02 + 0.04 * climb + 0.01 * std::sin(0.7 * t);
  for (int b = 1; b <= 20; ++b) bones->values[std::size_t(2 * b)] = b <= 10 ? bend : -bend;
}

void WingmanFlight(int side, double t, std::int64_t seq, std::int64_t utime,
                   sandbox_msgs::robot_pose_t* pose, sandbox_msgs::bone_values_t* bones) {
  const double lag_s = 1.2, radius = kRadius_m + 12.0 * side;
  const double a = kSpeed_mps / kRadius_m * (t - lag_s);
  *pose = {};
  pose->utime = utime;
  pose->seq = seq;
  pose->position[0] = radius * std::cos(a);
  pose->position[1] = radius * std::sin(a);
  pose->position[2] = 56.0 + 5.0 * std::sin(0.3 * (t - lag_s));
  SetRpy(0.0, 0.1, a + M_PI / 2, pose->orientation);

  *bones = {};
  bones->utime = utime;
  bones->seq = seq;
  bones->num_values = 5;
  bones->values.assign(5, 0.0);
  const double spin = std::remainder(2.0 * M_PI * 3.0 * t, 2.0 * M_PI);
  for (int r = 1; r <= 4; ++r) bones->values[std::size_t(r)] = r % 2 ? spin : -spin;
}

}  // namespace sandbox::bridge
