#pragma once
// The level as the browser draws it: its actors' meshes in one binary glTF
// (GLB, written by assimp's glTF 2 exporter; three.js's GLTFLoader reads it).
// Each actor is a node named after it: a static actor's meshes in the world
// frame, a movable one's in its own frame under a node at its load-time pose
// (the stream's placements move it); coloured by the materials' base colours. Positions stay Z up
// (the page turns its camera; glTF's own convention is Y up). Over
// `max_triangles`, every mesh is simplified by the same ratio
// (meshoptimizer), keeping its borders.

#include <cstddef>
#include <string>

#include "scene/level.h"

namespace sandbox::web {

struct LevelModel {
  std::string glb;                  // the file's bytes
  std::size_t triangles{0};         // in it
  std::size_t source_triangles{0};  // in the level's actors
};

// Throws std::runtime_error when assimp cannot write it.
LevelModel MakeLevelModel(const scene::Level& level, std::size_t max_triangles = 2'000'000);

}  // namespace sandbox::web
