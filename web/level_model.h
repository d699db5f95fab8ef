#pragma once
// The level as the browser draws it: its actors' meshes in one binary glTF
// (GLB, written by assimp's glTF 2 exporter; three.js's GLTFLoader reads it).
// Each actor is a node named after it: a static actor's meshes in the world
// frame, a movable one's in its own frame under a node at its load-time pose
// (the stream's placements move it); coloured by the materials' base colours. Positions stay Z up
// (the page turns its camera; glTF's own convention is Y up), with base
// colour textures and texture coordinates. Over
// `max_triangles`, every mesh is simplified by the same ratio
// (meshoptimizer), keeping its borders.
// Each robot is a node named RobotNodeName(index) at the origin, holding its
// skin joints' nodes "<node>_joint<k>" (k indexing RobotModel::joints) flat
// at their rest poses in the robot's body frame, and its meshes (not
// simplified) as glTF skins of those joints: the page places the node at the
// robot's pose and the joints at the poses the stream sends, and skins.

#include <cstddef>
#include <cstdint>
#include <string>

#include "scene/level.h"

namespace sandbox::web {

struct LevelModel {
  std::string glb;                  // the file's bytes
  std::size_t triangles{0};         // in it
  std::size_t source_triangles{0};  // in the level's actors
  std::size_t robot_triangles{0};   // the robots' (part of `triangles`)
  std::size_t textures{0};          // base colour textures embedded
  std::size_t textures_left_out{0};  // PNG or JPEG ones over the byte budget
};

// What the page is told of the level before its model (JSON text): its name,
// its surface ids (id, kind, name: what a sample hit), and per robot its
// bones (name, number of values) and sensors (name, type); for a recorded
// run (`sandbox view`), the log, its ticks and its duration, which show the
// page's player. docs/reference/web.md.
struct RecordedRun {
  std::string log;
  std::int64_t ticks{0};
  double duration_s{0.0};
};
// `camera_control`: the page may steer the cameras (`--web-control`).
std::string LevelInfoJson(const scene::Level& level, const RecordedRun* recorded = nullptr,
                          bool camera_control = false);

// The name of robot `robot`'s node ("sandbox_robot0"; three.js keeps it as is).
std::string RobotNodeName(int robot);

// Base colour textures go in as their files are (PNG and JPEG, which
// browsers decode; other formats and raw texels are left out: the base
// colour alone), each file once, up to `max_texture_bytes` in all.
// Throws std::runtime_error when assimp cannot write it.
LevelModel MakeLevelModel(const scene::Level& level, std::size_t max_triangles = 2'000'000,
                          std::size_t max_texture_bytes = 64u << 20);

}  // namespace sandbox::web
