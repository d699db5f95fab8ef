#pragma once
// Triangle meshes of the primitive shapes robot descriptions use (URDF <box>,
// <cylinder>, <sphere>), centred on their frame's origin, with outward unit
// normals and counter-clockwise triangles seen from outside.

#include <Eigen/Core>

#include "scene/mesh.h"

namespace sandbox::scene {

// A box of these edge lengths: flat faces (24 vertices, 12 triangles).
Mesh BoxMesh(const Eigen::Vector3d& size);

// A cylinder along z: `segments` flat side faces with smooth normals and two
// flat caps. Its polygon's corners lie on the radius.
Mesh CylinderMesh(double radius, double length, int segments = 32);

// A sphere of `rings` bands of latitude and `segments` of longitude; its
// vertices lie on the radius.
Mesh SphereMesh(double radius, int rings = 16, int segments = 32);

}  // namespace sandbox::scene
