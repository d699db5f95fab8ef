#pragma once
// The example model's flight: the bundled flying wing (ELAHA) circling 120 m
// around the sample level's centre, 60 m up, banked, bending both wings and
// working the elevators. examples/fly_wing publishes it over LCM as an
// external model would; `sandbox demo` publishes it in-process when it
// cannot make a private network namespace.

#include <cstdint>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace sandbox::bridge {

// The pose and bone messages at t seconds into the flight, stamped with
// `seq` and `utime`.
void ExampleFlight(double t, std::int64_t seq, std::int64_t utime, sandbox_msgs::robot_pose_t* pose,
                   sandbox_msgs::bone_values_t* bones);

}  // namespace sandbox::bridge
