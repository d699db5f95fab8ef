#pragma once
// How assets are read and placed: errors, axis and unit conversion, placement.

#include <Eigen/Geometry>
#include <optional>
#include <stdexcept>

#include "scene/frames.h"

namespace sandbox::scene {

// Thrown for every problem with a level or asset file. what() names the file,
// the line or node where known, and what is wrong: "level.toml:12: actor 'gate':
// scale must be positive, got -1".
class LevelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// How to read a plain scene file given as a level (a manifest says it per actor).
// Unset fields take the file's own statement or the format's convention
// (docs/reference/levels.md lists them).
struct AssetConversion {
  std::optional<UpAxis> up;
  std::optional<double> unit_scale_m;  // metres per file unit
};

// Where and how a manifest places an asset: X_WA = translation * rotation,
// vertices scaled in the asset's converted frame.
struct Placement {
  Eigen::Vector3d position_m{Eigen::Vector3d::Zero()};
  Eigen::Quaterniond rotation{Eigen::Quaterniond::Identity()};
  Eigen::Vector3d scale{Eigen::Vector3d::Ones()};
  AssetConversion conversion;

  Eigen::Isometry3d pose() const { return Eigen::Translation3d(position_m) * rotation; }
};

}  // namespace sandbox::scene
