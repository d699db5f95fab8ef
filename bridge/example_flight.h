#pragma once
// The example model's flight: the bundled flying wing (ELAHA) circling 120 m
// around the sample level's centre, 60 m up, banked, bending both wings and
// working the elevators. examples/fly_wing publishes it over LCM as an
// external model would; `sandbox demo` publishes it in-process when it
// cannot make a private network namespace. Its two wingmen are quadrotors
// (assets/formation): `fly_wing --slot left|right`.

#include <cstdint>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace sandbox::bridge {

// The pose and bone messages at t seconds into the flight, stamped with
// `seq` and `utime`.
void ExampleFlight(double t, std::int64_t seq, std::int64_t utime, sandbox_msgs::robot_pose_t* pose,
                   sandbox_msgs::bone_values_t* bones);

// A quadrotor wingman (bones: body, rotor1-rotor4, one angle about z each) at
// t seconds: 1.2 s (18 m) behind the wing on its circle, 12 m inside (side
// -1, left) or outside (side +1, right) of it and 4 m lower, nose on the
// circle's tangent and pitched 6 degrees down, rotors spinning at 3 turns a
// second (1 and 3 one way, 2 and 4 the other).
// The highlands flight (assets/highlands): from the airfield (the world
// origin) eastwards at 300 m/s over the ground, climbing as
// z = 2 + 20000 (1 - exp(-x / 12 km)) metres: 3 km up after 2 km, 20 km up
// (less 5 m) at x = 100 km, reached after 333 s; then on at 20 km. Nose along
// the path, wings bent up by the climb.
void HighlandsFlight(double t, std::int64_t seq, std::int64_t utime,
                     sandbox_msgs::robot_pose_t* pose, sandbox_msgs::bone_values_t* bones);
constexpr double kHighlandsSpeed_mps = 300.0;

void WingmanFlight(int side, double t, std::int64_t seq, std::int64_t utime,
                   sandbox_msgs::robot_pose_t* pose, sandbox_msgs::bone_values_t* bones);

}  // namespace sandbox::bridge
