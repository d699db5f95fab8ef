#include "scene/shape_meshes.h"

#include <cmath>
#include <cstdint>

namespace sandbox::scene {
namespace {

std::uint32_t AddVertex(Mesh* mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  mesh->positions_A.push_back(p.cast<float>());
  mesh->normals_A.push_back(n.normalized().cast<float>());
  return static_cast<std::uint32_t>(mesh->positions_A.size() - 1);
}

void AddTriangle(Mesh* mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  mesh->indices.insert(mesh->indices.end(), {a, b, c});
}

}  // namespace

Mesh BoxMesh(const Eigen::Vector3d& size) {
  Mesh mesh;
  const Eigen::Vector3d half = size / 2.0;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {-1.0, 1.0}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      // u, v span the face with u x v = n.
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
      u[a] = half[a], v[b] = half[b];
      if (sign < 0.0) u = -u;
      const Eigen::Vector3d c = n.cwiseProduct(half);
      const std::uint32_t i0 = AddVertex(&mesh, c - u - v, n), i1 = AddVertex(&mesh, c + u - v, n);
      const std::uint32_t i2 = AddVertex(&mesh, c + u + v, n), i3 = AddVertex(&mesh, c - u + v, n);
      AddTriangle(&mesh, i0, i1, i2);
      AddTriangle(&mesh, i0, i2, i3);
    }
  }
  return mesh;
}

Mesh CylinderMesh(double radius, double length, int segments) {
  Mesh mesh;
  const double h = length / 2.0;
  for (int s = 0; s < segments; ++s) {
    const double a0 = 2.0 * M_PI * s / segments, a1 = 2.0 * M_PI * (s + 1) / segments;
    const Eigen::Vector3d r0(std::cos(a0), std::sin(a0), 0.0), r1(std::cos(a1), std::sin(a1), 0.0);
    const Eigen::Vector3d up(0.0, 0.0, h);
    const std::uint32_t b0 = AddVertex(&mesh, radius * r0 - up, r0);
    const std::uint32_t b1 = AddVertex(&mesh, radius * r1 - up, r1);
    const std::uint32_t t1 = AddVertex(&mesh, radius * r1 + up, r1);
    const std::uint32_t t0 = AddVertex(&mesh, radius * r0 + up, r0);
    AddTriangle(&mesh, b0, b1, t1);
    AddTriangle(&mesh, b0, t1, t0);
  }
  for (const double sign : {-1.0, 1.0}) {
    const Eigen::Vector3d n(0.0, 0.0, sign);
    const std::uint32_t centre = AddVertex(&mesh, n * h, n);
    const std::uint32_t first = static_cast<std::uint32_t>(mesh.positions_A.size());
    for (int s = 0; s < segments; ++s) {
      const double a = 2.0 * M_PI * s / segments;
      AddVertex(&mesh, Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), sign * h), n);
    }
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t i = first + std::uint32_t(s),
                          j = first + std::uint32_t((s + 1) % segments);
      if (sign > 0.0) {
        AddTriangle(&mesh, centre, i, j);
      } else {
        AddTriangle(&mesh, centre, j, i);
      }
    }
  }
  return mesh;
}

Mesh SphereMesh(double radius, int rings, int segments) {
  Mesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const double polar = M_PI * r / rings;
    for (int s = 0; s <= segments; ++s) {
      const double a = 2.0 * M_PI * s / segments;
      const Eigen::Vector3d n(std::sin(polar) * std::cos(a), std::sin(polar) * std::sin(a),
                              std::cos(polar));
      AddVertex(&mesh, radius * n, n);
    }
  }
  const std::uint32_t row = std::uint32_t(segments + 1);
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t i = std::uint32_t(r) * row + std::uint32_t(s);
      // From the north pole down: (i, i + row, i + row + 1) faces outward.
      if (r > 0) AddTriangle(&mesh, i, i + row, i + 1);
      if (r < rings - 1) AddTriangle(&mesh, i + 1, i + row, i + row + 1);
    }
  }
  return mesh;
}

}  // namespace sandbox::scene
