#include "examples/contact/robot_shape.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <stdexcept>

namespace sandbox::examples {
namespace {

bool IsGltf(const std::string& file) {
  std::string extension = file.substr(file.find_last_of('.') + 1);
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension == "gltf" || extension == "glb";
}

// A node's transform in double. Writers round quaternions (0.707107) and
// assimp composes in float: either would tilt the shape by 1e-7 and break its
// symmetry, so rotation entries within 1e-6 of 0 or +-1 (quarter turns) are
// made exact, and scales within 1e-5 of 1 are 1.
Eigen::Affine3d LocalTransform(const aiMatrix4x4& m) {
  aiVector3D scaling, position;
  aiQuaternion rotation;
  m.Decompose(scaling, rotation, position);
  Eigen::Vector3d scale(scaling.x, scaling.y, scaling.z);
  for (int k = 0; k < 3; ++k) {
    if (std::abs(scale[k] - 1.0) < 1e-5) scale[k] = 1.0;
  }
  Eigen::Matrix3d R = Eigen::Quaterniond(rotation.w, rotation.x, rotation.y, rotation.z)
                          .normalized()
                          .toRotationMatrix();
  for (int i = 0; i < 9; ++i) {
    double& entry = R.data()[i];
    if (std::abs(entry - std::round(entry)) < 1e-6) entry = std::round(entry);
  }
  return Eigen::Translation3d(position.x, position.y, position.z) * Eigen::Affine3d(R) *
         Eigen::Scaling(scale);
}

void AddNode(const aiScene& scene, const aiNode& node, const Eigen::Affine3d& parent,
             std::vector<Triangle>* triangles) {
  const Eigen::Affine3d global = parent * LocalTransform(node.mTransformation);
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
    // A skinned mesh's vertices are already in its bind pose (the joints'
    // bind transforms and inverse bind matrices cancel): no node transform.
    const Eigen::Affine3d X = mesh.HasBones() ? Eigen::Affine3d::Identity() : global;
    auto vertex = [&](unsigned i) {
      const aiVector3D& v = mesh.mVertices[i];
      return Eigen::Vector3d(X * Eigen::Vector3d(v.x, v.y, v.z));
    };
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      triangles->push_back(
          {vertex(face.mIndices[0]), vertex(face.mIndices[1]), vertex(face.mIndices[2])});
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    AddNode(scene, *node.mChildren[c], global, triangles);
  }
}

// The vertical line through (x, y) meets the triangle at height *z (the
// triangle's projection contains the point strictly or on its lower-left edges).
bool VerticalCrossing(const Triangle& t, double x, double y, double* z) {
  const double d =
      (t.b.x() - t.a.x()) * (t.c.y() - t.a.y()) - (t.c.x() - t.a.x()) * (t.b.y() - t.a.y());
  if (d == 0.0) return false;  // seen edge-on from above
  const double u = ((x - t.a.x()) * (t.c.y() - t.a.y()) - (t.c.x() - t.a.x()) * (y - t.a.y())) / d;
  const double v = ((t.b.x() - t.a.x()) * (y - t.a.y()) - (x - t.a.x()) * (t.b.y() - t.a.y())) / d;
  if (u < 0.0 || v < 0.0 || u + v > 1.0) return false;
  *z = t.a.z() + u * (t.b.z() - t.a.z()) + v * (t.c.z() - t.a.z());
  return true;
}

}  // namespace

std::vector<Triangle> ReadRobotMesh(const std::string& file) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error(file + ": cannot read the robot's mesh: " + importer.GetErrorString());
  }
  std::vector<Triangle> triangles;
  AddNode(*scene, *scene->mRootNode, Eigen::Affine3d::Identity(), &triangles);
  if (triangles.empty()) throw std::runtime_error(file + ": the robot's mesh has no triangles");
  if (IsGltf(file)) {  // glTF's +Y up to the robot frame's +Z up
    for (Triangle& t : triangles) {
      for (Eigen::Vector3d* v : {&t.a, &t.b, &t.c}) *v = Eigen::Vector3d(v->x(), -v->z(), v->y());
    }
  }
  return triangles;
}

double DistanceToTriangle(const Eigen::Vector3d& p, const Triangle& t) {
  // The closest point by the triangle's Voronoi regions (Ericson, Real-Time
  // Collision Detection, 5.1.5).
  const Eigen::Vector3d ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const Eigen::Vector3d bp = p - t.b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (ap - ab * (d1 / (d1 - d3))).norm();
  const Eigen::Vector3d cp = p - t.c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (ap - ac * (d2 / (d2 - d6))).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (bp - (t.c - t.b) * w).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (ap - ab * (vb * denom) - ac * (vc * denom)).norm();
}

SignedDistanceField::SignedDistanceField(const std::vector<Triangle>& triangles,
                                         const Options& options)
    : options_(options) {
  if (!(options.voxel_m > 0.0) || !(options.band_m > 0.0)) {
    throw std::invalid_argument("signed distance field: voxel and band must be positive");
  }
  box_min_ = Eigen::Vector3d::Constant(INFINITY);
  box_max_ = -box_min_;
  for (const Triangle& t : triangles) {
    for (const Eigen::Vector3d* v : {&t.a, &t.b, &t.c}) {
      box_min_ = box_min_.cwiseMin(*v);
      box_max_ = box_max_.cwiseMax(*v);
    }
  }
  centre_ = 0.5 * (box_min_ + box_max_);
  const double h = options.voxel_m;
  for (int axis = 0; axis < 3; ++axis) {
    const double half = 0.5 * (box_max_[axis] - box_min_[axis]) + options.band_m + 2.0 * h;
    dims_[axis] = 2 * int(std::ceil(half / h)) + 1;  // odd: a node on the centre
  }
  const double cells = double(dims_[0]) * dims_[1] * dims_[2];
  if (cells > 2e8) {
    throw std::invalid_argument("signed distance field: " + std::to_string(long(cells)) +
                                " nodes; use a coarser voxel");
  }
  values_.assign(std::size_t(cells), options.band_m);
  auto node_range = [&](double lo, double hi, int axis, int* first, int* last) {
    const double half = 0.5 * (dims_[axis] - 1);
    *first = std::max(0, int(std::floor((lo - centre_[axis]) / h + half)));
    *last = std::min(dims_[axis] - 1, int(std::ceil((hi - centre_[axis]) / h + half)));
  };
  // Unsigned distances: each triangle updates the nodes within the band of its box.
  for (const Triangle& t : triangles) {
    const Eigen::Vector3d lo = t.a.cwiseMin(t.b).cwiseMin(t.c).array() - options.band_m;
    const Eigen::Vector3d hi = t.a.cwiseMax(t.b).cwiseMax(t.c).array() + options.band_m;
    int i0, i1, j0, j1, k0, k1;
    node_range(lo.x(), hi.x(), 0, &i0, &i1);
    node_range(lo.y(), hi.y(), 1, &j0, &j1);
    node_range(lo.z(), hi.z(), 2, &k0, &k1);
    for (int k = k0; k <= k1; ++k) {
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          double& value = values_[(std::size_t(k) * std::size_t(dims_[1]) + std::size_t(j)) *
                                      std::size_t(dims_[0]) +
                                  std::size_t(i)];
          value = std::min(value, DistanceToTriangle(NodePosition(i, j, k), t));
        }
      }
    }
  }
  // Signs: a node is inside when the vertical line through it crosses the
  // surface an odd number of times above it. The line is moved off the
  // node by a tiny irrational step so that it misses edges and corners.
  const double jitter_x = 1e-7 * h * 0.5772156649, jitter_y = 1e-7 * h * 0.3183098862;
  const std::size_t columns = std::size_t(dims_[0]) * std::size_t(dims_[1]);
  std::vector<std::vector<double>> crossings(columns);
  for (const Triangle& t : triangles) {
    const Eigen::Vector3d lo = t.a.cwiseMin(t.b).cwiseMin(t.c),
                          hi = t.a.cwiseMax(t.b).cwiseMax(t.c);
    int i0, i1, j0, j1;
    node_range(lo.x(), hi.x(), 0, &i0, &i1);
    node_range(lo.y(), hi.y(), 1, &j0, &j1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Eigen::Vector3d node = NodePosition(i, j, 0);
        double z = 0.0;
        if (VerticalCrossing(t, node.x() + jitter_x, node.y() + jitter_y, &z)) {
          crossings[std::size_t(j) * std::size_t(dims_[0]) + std::size_t(i)].push_back(z);
        }
      }
    }
  }
  for (int j = 0; j < dims_[1]; ++j) {
    for (int i = 0; i < dims_[0]; ++i) {
      std::vector<double>& zs = crossings[std::size_t(j) * std::size_t(dims_[0]) + std::size_t(i)];
      if (zs.empty()) continue;
      std::sort(zs.begin(), zs.end());
      for (int k = 0; k < dims_[2]; ++k) {
        const double z = NodePosition(i, j, k).z();
        const auto above = zs.end() - std::upper_bound(zs.begin(), zs.end(), z);
        if (above % 2 == 1) {
          values_[(std::size_t(k) * std::size_t(dims_[1]) + std::size_t(j)) *
                      std::size_t(dims_[0]) +
                  std::size_t(i)] *= -1.0;
        }
      }
    }
  }
}

Eigen::Vector3d SignedDistanceField::NodePosition(int i, int j, int k) const {
  // From the centre in whole steps: node positions mirror exactly about it.
  const Eigen::Vector3d steps(i - (dims_[0] - 1) / 2, j - (dims_[1] - 1) / 2,
                              k - (dims_[2] - 1) / 2);
  return centre_ + options_.voxel_m * steps;
}

double SignedDistanceField::Distance(const Eigen::Vector3d& p, Eigen::Vector3d* gradient) const {
  const double h = options_.voxel_m;
  int cell[3];
  double f[3];
  for (int axis = 0; axis < 3; ++axis) {
    const double x = (p[axis] - centre_[axis]) / h + 0.5 * (dims_[axis] - 1);
    if (!(x >= 0.0 && x <= dims_[axis] - 1)) {  // outside the grid (or NaN)
      if (gradient != nullptr) gradient->setZero();
      return options_.band_m;
    }
    cell[axis] = std::min(int(x), dims_[axis] - 2);
    f[axis] = x - cell[axis];
  }
  const int i = cell[0], j = cell[1], k = cell[2];
  const double c000 = Node(i, j, k), c100 = Node(i + 1, j, k), c010 = Node(i, j + 1, k),
               c110 = Node(i + 1, j + 1, k), c001 = Node(i, j, k + 1), c101 = Node(i + 1, j, k + 1),
               c011 = Node(i, j + 1, k + 1), c111 = Node(i + 1, j + 1, k + 1);
  const double x = f[0], y = f[1], z = f[2];
  // Along x first, then y, then z; the gradient is the trilinear's own.
  const double c00 = c000 + x * (c100 - c000), c10 = c010 + x * (c110 - c010),
               c01 = c001 + x * (c101 - c001), c11 = c011 + x * (c111 - c011);
  const double c0 = c00 + y * (c10 - c00), c1 = c01 + y * (c11 - c01);
  if (gradient != nullptr) {
    const double dx0 = (1 - y) * (c100 - c000) + y * (c110 - c010);
    const double dx1 = (1 - y) * (c101 - c001) + y * (c111 - c011);
    const double dy0 = c10 - c00, dy1 = c11 - c01;
    *gradient = Eigen::Vector3d((1 - z) * dx0 + z * dx1, (1 - z) * dy0 + z * dy1, c1 - c0) / h;
  }
  return c0 + z * (c1 - c0);
}

}  // namespace sandbox::examples
