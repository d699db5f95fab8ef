// The ray caster's hierarchy over a mesh's triangles: every triangle in
// exactly one leaf with its own corners, every box around everything below
// it, bad triangles left out, and a depth of the order of log4 of the count.

#include "scene/triangle_bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>

namespace sandbox::scene {
namespace {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint32_t> indices;
  TriangleSoup soup() const {
    return {positions.data(), positions.size(), indices.data(), indices.size() / 3};
  }
};

// n random small triangles scattered in a 100 m box.
Mesh Scattered(int n, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> where(-50.f, 50.f), offset(-1.f, 1.f);
  Mesh mesh;
  for (int t = 0; t < n; ++t) {
    const Eigen::Vector3f centre(where(random), where(random), where(random));
    for (int k = 0; k < 3; ++k) {
      mesh.indices.push_back(std::uint32_t(mesh.positions.size()));
      mesh.positions.push_back(centre +
                               Eigen::Vector3f(offset(random), offset(random), offset(random)));
    }
  }
  return mesh;
}

// Checks the subtree at `ref` and collects its triangles; returns its box.
void Walk(const TriangleBvh& bvh, std::int32_t ref, const Eigen::Vector3f& lower,
          const Eigen::Vector3f& upper, std::map<std::pair<int, int>, int>* seen,
          const std::vector<Mesh>& meshes) {
  if (ref < 0) {
    const TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - ref)];
    ASSERT_GE(leaf.count, 1);
    ASSERT_LE(leaf.count, TriangleBvh::kWidth);
    for (int i = 0; i < leaf.count; ++i) {
      ++(*seen)[{leaf.part[i], leaf.triangle[i]}];
      const Mesh& mesh = meshes[std::size_t(leaf.part[i])];
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f& p =
            mesh.positions[mesh.indices[3 * std::size_t(leaf.triangle[i]) + std::size_t(k)]];
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(leaf.corner[3 * k + a][i], p[a]);
          EXPECT_GE(p[a], lower[a]);
          EXPECT_LE(p[a], upper[a]);
        }
      }
    }
    return;
  }
  const TriangleBvh::Node& node = bvh.nodes[std::size_t(ref)];
  int children = 0;
  for (int c = 0; c < TriangleBvh::kWidth; ++c) {
    if (node.child[c] == TriangleBvh::kEmpty) continue;
    ++children;
    const Eigen::Vector3f child_lower(node.lower[0][c], node.lower[1][c], node.lower[2][c]);
    const Eigen::Vector3f child_upper(node.upper[0][c], node.upper[1][c], node.upper[2][c]);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(child_lower[a], lower[a]);
      EXPECT_LE(child_upper[a], upper[a]);
    }
    Walk(bvh, node.child[c], child_lower, child_upper, seen, meshes);
  }
  EXPECT_GE(children, 2) << "a node of fewer than two children";
}

TEST(TriangleBvhTest, EveryTriangleInOneLeafInsideEveryBoxAboveIt) {
  const std::vector<Mesh> meshes = {Scattered(5000, 1), Scattered(333, 2), Scattered(1, 3)};
  std::vector<TriangleSoup> soups;
  for (const Mesh& mesh : meshes) soups.push_back(mesh.soup());
  const TriangleBvh bvh = BuildTriangleBvh(soups);
  ASSERT_GE(bvh.root, 0);
  std::map<std::pair<int, int>, int> seen;
  Walk(bvh, bvh.root, bvh.lower, bvh.upper, &seen, meshes);
  EXPECT_EQ(seen.size(), 5000u + 333u + 1u);
  for (const auto& [triangle, times] : seen) EXPECT_EQ(times, 1);
  // Four-way splits: log4(5334) = 6.2 levels for a perfect tree.
  EXPECT_LE(bvh.depth, 12);
}

TEST(TriangleBvhTest, TrianglesOnOnePointAndOutOfRangeIndices) {
  // Many triangles with one centre (no split by area parts them) and one
  // whose index lies outside the positions.
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int t = 0; t < 100; ++t) mesh.indices.insert(mesh.indices.end(), {0, 1, 2});
  mesh.indices.insert(mesh.indices.end(), {0, 1, 7});
  const TriangleBvh bvh = BuildTriangleBvh({mesh.soup()});
  std::map<std::pair<int, int>, int> seen;
  Walk(bvh, bvh.root, bvh.lower, bvh.upper, &seen, {mesh});
  EXPECT_EQ(seen.size(), 100u);
  EXPECT_EQ(seen.count({0, 100}), 0u) << "the bad triangle is left out";
  EXPECT_LE(bvh.depth, 6);
}

TEST(TriangleBvhTest, CentresApartByADenormalOnOneAxis) {
  // The bins' scale, 16 / 1e-44, overflows to infinity: the binning must not
  // turn that into an int (undefined; UBSan aborted on a glTF model in CI).
  Mesh mesh = Scattered(200, 4);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    mesh.positions[i].z() = (i / 3) % 2 ? 1e-44f : 0.f;
  }
  const TriangleBvh bvh = BuildTriangleBvh({mesh.soup()});
  std::map<std::pair<int, int>, int> seen;
  Walk(bvh, bvh.root, bvh.lower, bvh.upper, &seen, {mesh});
  EXPECT_EQ(seen.size(), 200u);
}

TEST(TriangleBvhTest, NoTrianglesNoRoot) {
  EXPECT_EQ(BuildTriangleBvh({}).root, TriangleBvh::kEmpty);
  const Mesh empty;
  EXPECT_EQ(BuildTriangleBvh({empty.soup()}).root, TriangleBvh::kEmpty);
}

}  // namespace
}  // namespace sandbox::scene
