#pragma once
// The robot's shape for contact: its mesh file read in the robot frame (x
// forward, y left, z up, metres, origin at the centre of mass), turned into a
// signed distance field sampled on a grid (negative inside).

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sandbox::examples {

struct Triangle {
  Eigen::Vector3d a, b, c;
};

// All triangles of `file` (any format assimp reads) with its node transforms
// applied, in the robot frame. glTF files are Y-up (their robot frame is
// turned as the sandbox turns it: (x, y, z) -> (x, -z, y)); other formats are
// taken as Z-up. Skinned meshes are read in their bind pose. Throws
// std::runtime_error naming the file when it cannot be read or has no triangles.
std::vector<Triangle> ReadRobotMesh(const std::string& file);

// Distance from point p to the triangle (exact, unsigned).
double DistanceToTriangle(const Eigen::Vector3d& p, const Triangle& triangle);

// A signed distance field of a closed mesh on a regular grid of nodes, exact
// at the nodes within `band_m` of the surface and clamped to +-band_m beyond;
// trilinear between nodes. The grid is centred on the mesh's bounding box, so
// that a mirror-symmetric mesh gives a mirror-symmetric field.
class SignedDistanceField {
 public:
  struct Options {
    double voxel_m{0.02};  // node spacing
    double band_m{0.1};    // exact within this distance of the surface
  };

  SignedDistanceField(const std::vector<Triangle>& triangles, const Options& options);

  // The distance at p (robot frame), negative inside, and its gradient (the
  // outward direction, not normalised). Outside the grid: +band, gradient 0.
  double Distance(const Eigen::Vector3d& p, Eigen::Vector3d* gradient) const;

  double band_m() const { return options_.band_m; }
  const Eigen::Vector3d& box_min() const { return box_min_; }  // the mesh's bounds
  const Eigen::Vector3d& box_max() const { return box_max_; }
  long nodes() const { return long(values_.size()); }

 private:
  double Node(int i, int j, int k) const {
    return values_[(std::size_t(k) * std::size_t(dims_[1]) + std::size_t(j)) *
                       std::size_t(dims_[0]) +
                   std::size_t(i)];
  }
  Eigen::Vector3d NodePosition(int i, int j, int k) const;

  Options options_;
  Eigen::Vector3d box_min_, box_max_, centre_;
  Eigen::Vector3i dims_;  // nodes per axis (odd)
  std::vector<double> values_;
};

}  // namespace sandbox::examples
