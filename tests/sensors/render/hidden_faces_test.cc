// Which meshes' back faces can be culled, and from where: hand-made solids
// and height fields, and shapes that are neither.

#include "sensors/render/hidden_faces.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sandbox::render {
namespace {

using Eigen::Vector3f;
using Shape = HiddenBackFaces::Shape;

struct Mesh {
  std::vector<Vector3f> positions;
  std::vector<std::uint32_t> indices;
  // A quad a, b, c, d (counter-clockwise seen from its front), vertices of its own.
  void Quad(const Vector3f& a, const Vector3f& b, const Vector3f& c, const Vector3f& d) {
    const auto base = std::uint32_t(positions.size());
    positions.insert(positions.end(), {a, b, c, d});
    indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  // An axis-aligned box from lo to hi, its faces wound outwards.
  void Box(const Vector3f& lo, const Vector3f& hi) {
    const float x0 = lo.x(), y0 = lo.y(), z0 = lo.z(), x1 = hi.x(), y1 = hi.y(), z1 = hi.z();
    Quad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});  // +x
    Quad({x0, y1, z0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1});  // -x
    Quad({x1, y1, z0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1});  // +y
    Quad({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // -y
    Quad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // +z
    Quad({x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}, {x0, y0, z0});  // -z
  }
  void FlipTriangle(std::size_t t) { std::swap(indices[3 * t + 1], indices[3 * t + 2]); }
  HiddenBackFaces Hidden() const { return HiddenBackFaces::Of(positions, indices); }
};

// A grid of n x n cells over [0, size]^2 at heights z(x, y), wound upwards.
Mesh Grid(int n, float size, float (*z)(float, float)) {
  Mesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const float x = size * float(i) / float(n), y = size * float(j) / float(n);
      mesh.positions.emplace_back(x, y, z(x, y));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const auto a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1) + 1,
                 d = a + std::uint32_t(n + 1);
      mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}
float Hills(float x, float y) { return 3.f * std::sin(0.3f * x) * std::cos(0.2f * y); }

TEST(HiddenBackFacesTest, ClosedOutwardMeshesAreSolids) {
  Mesh box;
  box.Box({0, 0, 0}, {1, 2, 3});
  EXPECT_EQ(box.Hidden().shape(), Shape::kSolid);
  EXPECT_TRUE(
      box.Hidden().box().isApprox(Eigen::AlignedBox3f(Vector3f(0, 0, 0), Vector3f(1, 2, 3))));
  // Blocks stacked face to face (a wall of bricks, the sample's tower) are one solid.
  Mesh stack = box;
  stack.Box({0, 0, 3}, {1, 2, 4});
  stack.Box({5, 5, 5}, {6, 6, 6});
  EXPECT_EQ(stack.Hidden().shape(), Shape::kSolid);
}

TEST(HiddenBackFacesTest, OpenInsideOutOrMisWoundMeshesAreNeither) {
  Mesh open;
  open.Box({0, 0, 0}, {1, 1, 1});
  open.indices.resize(open.indices.size() - 6);  // no bottom
  EXPECT_EQ(open.Hidden().shape(), Shape::kNone);
  Mesh flipped;
  flipped.Box({0, 0, 0}, {1, 1, 1});
  flipped.FlipTriangle(4);
  EXPECT_EQ(flipped.Hidden().shape(), Shape::kNone);
  Mesh inside_out;
  inside_out.Box({0, 0, 0}, {1, 1, 1});
  for (std::size_t t = 0; t < 12; ++t) inside_out.FlipTriangle(t);
  EXPECT_EQ(inside_out.Hidden().shape(), Shape::kNone);
  // One piece inside out beside a good one.
  Mesh pair = inside_out;
  pair.Box({3, 0, 0}, {4, 1, 1});
  EXPECT_EQ(pair.Hidden().shape(), Shape::kNone);
  EXPECT_EQ(Mesh().Hidden().shape(), Shape::kNone);
}

TEST(HiddenBackFacesTest, TerrainGridsAreHeightFields) {
  EXPECT_EQ(Grid(20, 100.f, Hills).Hidden().shape(), Shape::kHeightField);
  EXPECT_EQ(Grid(1, 1.f, [](float, float) { return 0.f; }).Hidden().shape(), Shape::kHeightField);
}

TEST(HiddenBackFacesTest, FoldsOverhangsHolesAndConcaveFootprintsAreNot) {
  // Wound downwards.
  Mesh down = Grid(10, 10.f, Hills);
  for (std::size_t t = 0; t < down.indices.size() / 3; ++t) down.FlipTriangle(t);
  EXPECT_EQ(down.Hidden().shape(), Shape::kNone);
  // A vertical cliff face.
  Mesh cliff = Grid(10, 10.f, Hills);
  cliff.Quad({10, 0, -5}, {10, 10, -5}, {10, 10, 5}, {10, 0, 5});
  EXPECT_EQ(cliff.Hidden().shape(), Shape::kNone);
  // A fold: one vertex pushed past its neighbour, so that two triangles overlap in plan.
  Mesh fold = Grid(10, 10.f, [](float, float) { return 0.f; });
  fold.positions[5 * 11 + 5].x() += 1.5f;
  EXPECT_EQ(fold.Hidden().shape(), Shape::kNone);
  // A hole: the middle cell's two triangles left out.
  Mesh hole = Grid(10, 10.f, Hills);
  const std::size_t middle = 2 * (5 * 10 + 5);
  hole.indices.erase(hole.indices.begin() + std::ptrdiff_t(3 * middle),
                     hole.indices.begin() + std::ptrdiff_t(3 * middle + 6));
  EXPECT_EQ(hole.Hidden().shape(), Shape::kNone);
  // An L-shaped footprint: a corner quarter left out.
  Mesh ell = Grid(10, 10.f, Hills);
  std::vector<std::uint32_t> kept;
  for (std::size_t t = 0; t < ell.indices.size() / 3; ++t) {
    const std::size_t cell = t / 2, i = cell % 10, j = cell / 10;
    if (i >= 5 && j >= 5) continue;
    kept.insert(kept.end(), ell.indices.begin() + std::ptrdiff_t(3 * t),
                ell.indices.begin() + std::ptrdiff_t(3 * t + 3));
  }
  ell.indices = kept;
  EXPECT_EQ(ell.Hidden().shape(), Shape::kNone);
}

TEST(HiddenBackFacesTest, SolidsHideTheirBackFacesFromOutsideTheirBoxBeyondTheNearPlane) {
  Mesh box;
  box.Box({0, 0, 0}, {1, 1, 1});
  const HiddenBackFaces solid = box.Hidden();
  EXPECT_TRUE(solid.HiddenFrom({5, 0.5f, 0.5f}, 0.2f));
  EXPECT_FALSE(solid.HiddenFrom({0.5f, 0.5f, 0.5f}, 0.2f));  // inside
  EXPECT_FALSE(solid.HiddenFrom({1.1f, 0.5f, 0.5f}, 0.2f));  // the near plane could cut it open
  EXPECT_TRUE(solid.HiddenFrom({1.3f, 0.5f, 0.5f}, 0.2f));
  // Two solids' union: outside both boxes only.
  Mesh other;
  other.Box({10, 0, 0}, {11, 1, 1});
  const HiddenBackFaces both = HiddenBackFaces::Union(solid, other.Hidden());
  EXPECT_EQ(both.shape(), Shape::kSolid);
  EXPECT_FALSE(both.HiddenFrom({5, 0.5f, 0.5f}, 0.2f));  // inside the union's box
  EXPECT_TRUE(both.HiddenFrom({5, 0.5f, 5.f}, 0.2f));
  EXPECT_EQ(HiddenBackFaces::Union(solid, Grid(4, 4.f, Hills).Hidden()).shape(), Shape::kNone);
  EXPECT_FALSE(HiddenBackFaces().HiddenFrom({100, 100, 100}, 0.f));
}

TEST(HiddenBackFacesTest, HeightFieldsHideTheirBackFacesFromAboveOverTheirFootprint) {
  const HiddenBackFaces terrain = Grid(40, 100.f, Hills).Hidden();
  ASSERT_EQ(terrain.shape(), Shape::kHeightField);
  EXPECT_TRUE(terrain.HiddenFrom({50, 50, 10}, 0.2f));
  EXPECT_FALSE(terrain.HiddenFrom({50, 50, -10}, 0.2f));  // below
  EXPECT_FALSE(terrain.HiddenFrom({150, 50, 10}, 0.2f));  // beside: under its edge in view
  EXPECT_FALSE(terrain.HiddenFrom({-1, 50, 10}, 0.2f));
  // Just above the ground: not while the near plane could reach it.
  const float x = 20.f, y = 30.f, ground = Hills(x, y);
  EXPECT_FALSE(terrain.HiddenFrom({x, y, ground + 0.1f}, 0.2f));
  EXPECT_TRUE(terrain.HiddenFrom({x, y, 3.5f}, 0.2f));  // above the highest hill
}

}  // namespace
}  // namespace sandbox::render
