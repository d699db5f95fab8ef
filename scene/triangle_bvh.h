#pragma once
// A bounding-volume hierarchy over a mesh's triangles, laid out for rays
// tested four at a time: each node holds the boxes of its (up to) four
// children side by side, each leaf the corners of (up to) four triangles side
// by side, in the mesh's own frame. Built by the surface area heuristic over
// binned centroids. Immutable once built; any thread may read it.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sandbox::scene {

struct TriangleBvh {
  static constexpr int kWidth = 4;
  // A child reference: a node's index (>= 0), a leaf's (Leaf(i) = -1 - i),
  // or kEmpty (its box holds nothing: lower bounds +inf, upper -inf).
  static constexpr std::int32_t kEmpty = INT32_MIN;
  static constexpr std::int32_t Leaf(std::int32_t leaf) { return -1 - leaf; }

  struct Node {
    float lower[3][kWidth];  // [axis][child]
    float upper[3][kWidth];
    std::int32_t child[kWidth];
  };
  struct Leaves {
    // [corner * 3 + axis][triangle]; lanes past `count` repeat the last triangle.
    float corner[9][kWidth];
    std::int32_t part[kWidth], triangle[kWidth];  // which triangle of which part
    std::int32_t count;
  };

  std::vector<Node> nodes;  // nodes[0] is the root unless `root` is a leaf
  std::vector<Leaves> leaves;
  std::int32_t root{kEmpty};
  Eigen::Vector3f lower{Eigen::Vector3f::Zero()}, upper{Eigen::Vector3f::Zero()};  // all corners
  int depth{0};  // nodes on the longest path from the root to a leaf
};

// One part of a mesh: positions and triangle indices (three a triangle).
struct TriangleSoup {
  const Eigen::Vector3f* positions;
  std::size_t num_positions;
  const std::uint32_t* indices;
  std::size_t num_triangles;
};

// The hierarchy over every triangle of `parts` (a triangle is (part, index)).
// Triangles whose indices lie outside their part's positions are left out.
TriangleBvh BuildTriangleBvh(const std::vector<TriangleSoup>& parts);

}  // namespace sandbox::scene
