#pragma once
// A robot model from a robot description (URDF, SDF): a node per link (and
// one per off-origin SDF pivot), a bone per movable joint with its limits,
// the visual shapes as drawn meshes and the collision shapes as
// RobotModel::collision_meshes, each rigid on its link. Scene-internal.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "scene/robot_model.h"

namespace sandbox::scene {

struct Level;

// Fills `model` (its name, spawn pose and settings already set) from the
// description `spec.file`. Materials and mesh files' textures go to `level`;
// `where` prefixes messages ("manifest:line: robot 'name': "). Throws
// LevelError.
void BuildDescribedRobot(
    const RobotSpec& spec, const std::string& where, Level* level,
    const std::function<void(const std::filesystem::path&, std::string_view)>& on_file,
    RobotModel* model);

}  // namespace sandbox::scene
