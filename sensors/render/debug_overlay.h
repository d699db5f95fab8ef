#pragma once
// The debug overlay's marks, as a game editor draws them: the face scanner's
// samples (occupied red, free green; or coloured by surface id) as points or short stubs along
// their rays, each bone's frame as three axis stubs (x red, y green, z blue), and actors' bounding
// boxes.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/face_scanner.h"
#include "sensors/render/view.h"

namespace sandbox::render {

// How scanner samples are coloured: occupied red and free green, or by what
// each hit (SurfaceColour of its surface id; free samples grey).
enum class SampleColour { kOccupancy, kSurface };

// A colour for surface id `id` (scene/surface_ids.h): hue the fractional
// part of id x 0.618 (the golden ratio's), so that neighbouring ids differ;
// saturation 0.8, value 0.95. Id 0 (nothing) is grey.
Eigen::Vector3f SurfaceColour(std::int32_t id);

// Scanned samples of `scan` (unvisited ones skipped). stub_m = 0 draws
// points; otherwise a stub of that length ending at each sample, pointing
// back along its ray (long lines are slow on llvmpipe: keep stubs short).
void AddFaceScan(const sensors::FaceScan& scan, double stub_m, Overlay* overlay,
                 SampleColour colour = SampleColour::kOccupancy);

// Every bone of the bone map: its frame's axes, axis_m long.
void AddBoneFrames(const scene::RobotState& state, double axis_m, Overlay* overlay);

// Each actor's bounds (Actor::bounds_W at its load pose) moved to its
// current pose, as an oriented box; `actor_poses` empty: load poses. Static
// actors only when `static_too` (a level may have thousands).
void AddActorBounds(const scene::Level& level, const std::vector<Eigen::Isometry3d>& actor_poses,
                    bool static_too, Overlay* overlay);

}  // namespace sandbox::render
