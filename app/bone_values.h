#pragma once
// Bone values from the command line: "BONE V1 [V2 ...]; BONE ..." or a file of
// such lines ('#' starts a comment), BONE a name or a bone-map index, angles in
// degrees, quaternions w x y z.

#include <string>

#include "scene/robot_state.h"

namespace sandbox::app {

// Applies `spec` to `state`; throws CommandError naming the option and bone.
void ApplyBones(const std::string& spec, const scene::RobotModel& model, scene::RobotState* state);

}  // namespace sandbox::app
