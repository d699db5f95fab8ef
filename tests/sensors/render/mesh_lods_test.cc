// Levels of detail checked against facts of the surfaces they simplify: a
// flat square keeps its area and outline, a wavy surface keeps to the
// analytic function within each level's error, and triangles across skin
// groups stay as they are.

#include "sensors/render/mesh_lods.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <set>

namespace sandbox::render {
namespace {

// An n x n grid of quads over [0, size]^2 with heights z(x, y).
struct Grid {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint32_t> indices;
};
template <typename Height>
Grid MakeGrid(int n, double size, Height z) {
  Grid grid;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = size * i / n, y = size * j / n;
      grid.positions.emplace_back(float(x), float(y), float(z(x, y)));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1,
                          c = a + std::uint32_t(n + 1), d = c + 1;
      grid.indices.insert(grid.indices.end(), {a, b, d, a, d, c});
    }
  }
  return grid;
}

std::vector<std::uint32_t> LevelIndices(const MeshLods& lods, std::size_t k) {
  const MeshLods::Level& level = lods.levels[k];
  return {lods.indices.begin() + level.first, lods.indices.begin() + level.first + level.count};
}

// The edges used by one triangle only, as vertex pairs (smaller first).
std::set<std::pair<std::uint32_t, std::uint32_t>> OpenEdges(const std::vector<std::uint32_t>& t) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[i + std::size_t(e)], b = t[i + std::size_t((e + 1) % 3)];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<std::pair<std::uint32_t, std::uint32_t>> open;
  for (const auto& [edge, count] : uses) {
    if (count == 1) open.insert(edge);
  }
  return open;
}

TEST(MeshLodsTest, AFlatSquareKeepsItsAreaAndItsOutline) {
  const Grid grid = MakeGrid(60, 10.0, [](double, double) { return 0.0; });
  const MeshLods lods = MakeMeshLods(grid.positions, grid.indices);
  ASSERT_GE(lods.levels.size(), 2u);
  EXPECT_EQ(lods.levels[0].count, grid.indices.size());
  EXPECT_EQ(lods.levels[0].error_m, 0.f);
  const auto outline = OpenEdges(grid.indices);
  ASSERT_EQ(outline.size(), 4u * 60u);
  for (std::size_t k = 1; k < lods.levels.size(); ++k) {
    const std::vector<std::uint32_t> t = LevelIndices(lods, k);
    EXPECT_LE(4 * t.size(), 3 * std::size_t(lods.levels[k - 1].count)) << "level " << k;
    EXPECT_LT(lods.levels[k].error_m, 1e-3f) << "a plane stays a plane";
    double area = 0.0;
    for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
      const Eigen::Vector3f &a = grid.positions[t[i]], &b = grid.positions[t[i + 1]],
                            &c = grid.positions[t[i + 2]];
      const Eigen::Vector3f n = (b - a).cross(c - a);
      area += 0.5 * n.norm();
      EXPECT_GE(n.z(), -1e-6f) << "none folded over";
    }
    EXPECT_NEAR(area, 100.0, 1e-3) << "level " << k;
    EXPECT_EQ(OpenEdges(t), outline) << "the outline stays where it was, level " << k;
  }
  EXPECT_LT(lods.levels.back().count, grid.indices.size() / 20);
}

TEST(MeshLodsTest, AWavySurfaceStaysWithinEachLevelsErrorOfItsFunction) {
  // 40 m square at 0.25 m with waves of 0.5 m amplitude and 12.6 m wavelength.
  auto z = [](double x, double y) { return 0.5 * std::sin(0.5 * x) * std::cos(0.5 * y); };
  const Grid grid = MakeGrid(160, 40.0, z);
  const MeshLods lods = MakeMeshLods(grid.positions, grid.indices);
  ASSERT_GE(lods.levels.size(), 3u);
  // The grid itself is within h^2 / 8 * curvature (< 2 mm) of the function.
  for (std::size_t k = 1; k < lods.levels.size(); ++k) {
    const MeshLods::Level& level = lods.levels[k];
    EXPECT_GT(level.error_m, lods.levels[k - 1].error_m);
    const std::vector<std::uint32_t> t = LevelIndices(lods, k);
    double worst = 0.0;
    for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
      const Eigen::Vector3d a = grid.positions[t[i]].cast<double>(),
                            b = grid.positions[t[i + 1]].cast<double>(),
                            c = grid.positions[t[i + 2]].cast<double>();
      // Points across the triangle; slopes reach 0.25, so a vertical gap is
      // at most 3% more than the distance.
      for (const Eigen::Vector3d& w :
           {Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3), Eigen::Vector3d(0.5, 0.5, 0),
            Eigen::Vector3d(0, 0.5, 0.5), Eigen::Vector3d(0.5, 0, 0.5),
            Eigen::Vector3d(0.7, 0.2, 0.1)}) {
        const Eigen::Vector3d p = w.x() * a + w.y() * b + w.z() * c;
        worst = std::max(worst, std::abs(p.z() - z(p.x(), p.y())) / 1.03 - 0.002);
      }
    }
    EXPECT_LE(worst, level.error_m) << "level " << k << " of " << level.count / 3 << " triangles";
  }
  EXPECT_LT(lods.levels.back().count, grid.indices.size() / 10);
}

TEST(MeshLodsTest, TrianglesAcrossGroupsStayInEveryLevel) {
  const Grid grid = MakeGrid(40, 10.0, [](double, double) { return 0.0; });
  std::vector<std::uint32_t> group(grid.positions.size());
  for (std::size_t v = 0; v < group.size(); ++v) group[v] = grid.positions[v].x() < 5.f ? 0 : 1;
  std::set<std::array<std::uint32_t, 3>> across;
  for (std::size_t i = 0; i + 2 < grid.indices.size(); i += 3) {
    const std::uint32_t a = grid.indices[i], b = grid.indices[i + 1], c = grid.indices[i + 2];
    if (group[a] != group[b] || group[b] != group[c]) across.insert({a, b, c});
  }
  ASSERT_EQ(across.size(), 2u * 40u);
  const MeshLods lods = MakeMeshLods(grid.positions, grid.indices, &group);
  ASSERT_GE(lods.levels.size(), 2u);
  for (std::size_t k = 1; k < lods.levels.size(); ++k) {
    const std::vector<std::uint32_t> t = LevelIndices(lods, k);
    std::set<std::array<std::uint32_t, 3>> kept;
    for (std::size_t i = 0; i + 2 < t.size(); i += 3) {
      const std::uint32_t a = t[i], b = t[i + 1], c = t[i + 2];
      if (group[a] != group[b] || group[b] != group[c]) kept.insert({a, b, c});
    }
    EXPECT_EQ(kept, across) << "level " << k;
  }
}

// A mesh that repeats its vertices for each triangle (as OBJ files come
// through assimp): welded, it simplifies like the connected one; a vertex
// is joined only with one equal in every stream.
TEST(MeshLodsTest, WeldedTriangleSoupsSimplifyAndKeepTheirAttributes) {
  const Grid grid = MakeGrid(40, 10.0, [](double x, double) { return 0.1 * x; });
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<std::uint32_t> soup;
  for (std::size_t i = 0; i < grid.indices.size(); ++i) {
    positions.push_back(grid.positions[grid.indices[i]]);
    // Two kinds of normal: the left half's corners differ from the right half's.
    normals.push_back(positions.back().x() < 5.f ? Eigen::Vector3f::UnitZ()
                                                 : Eigen::Vector3f::UnitX());
    soup.push_back(std::uint32_t(i));
  }
  EXPECT_EQ(MakeMeshLods(positions, soup).levels.size(), 1u) << "no triangle shares an edge";
  const std::vector<std::uint32_t> welded =
      WeldIdentical(soup, positions.size(), {{positions.data(), 12}, {normals.data(), 12}});
  ASSERT_EQ(welded.size(), soup.size());
  std::set<std::uint32_t> used(welded.begin(), welded.end());
  // Each grid vertex once, those at x = 5 (where the normals change) twice at most.
  EXPECT_LE(used.size(), grid.positions.size() + 41);
  EXPECT_GE(used.size(), grid.positions.size());
  for (std::size_t i = 0; i < soup.size(); ++i) {
    EXPECT_EQ(positions[welded[i]], positions[soup[i]]);
    EXPECT_EQ(normals[welded[i]], normals[soup[i]]);
  }
  const MeshLods lods = MakeMeshLods(positions, welded);
  ASSERT_GE(lods.levels.size(), 2u);
  EXPECT_LT(lods.levels.back().count, soup.size() / 10);
}

TEST(MeshLodsTest, LevelForTakesTheCoarsestWithinTheAllowance) {
  const std::vector<MeshLods::Level> levels = {{0, 300, 0.f}, {300, 90, 0.01f}, {390, 30, 0.05f}};
  EXPECT_EQ(LevelFor(levels, 0.f).count, 300u);
  EXPECT_EQ(LevelFor(levels, 0.009f).count, 300u);
  EXPECT_EQ(LevelFor(levels, 0.01f).count, 90u);
  EXPECT_EQ(LevelFor(levels, 0.2f).count, 30u);
}

TEST(MeshLodsTest, SmallMeshesGetNoLevels) {
  const Grid grid = MakeGrid(4, 1.0, [](double, double) { return 0.0; });
  const MeshLods lods = MakeMeshLods(grid.positions, grid.indices);
  ASSERT_EQ(lods.levels.size(), 1u);
  EXPECT_EQ(lods.indices, grid.indices);
}

// Levels at 0, 1 cm, 3 cm, 9 cm (errors), for choosing.
std::vector<MeshLods::Level> Levels() {
  return {{0, 300, 0.f}, {300, 200, 0.01f}, {500, 100, 0.03f}, {600, 50, 0.09f}};
}

TEST(MeshLodsTest, ALevelGoesCoarserOnlyWellWithinItsError) {
  const std::vector<MeshLods::Level> levels = Levels();
  EXPECT_EQ(NextLevel(levels, 0, 0.f), 0u);
  EXPECT_EQ(NextLevel(levels, 0, 0.035f), 1u);  // 3 cm allowed, but 3.5 / 1.5 < 3 cm: one step
  EXPECT_EQ(NextLevel(levels, 0, 0.05f), 2u);   // 5 / 1.5 = 3.3 cm: level 2
  EXPECT_EQ(NextLevel(levels, 2, 0.035f), 2u);  // stays
  EXPECT_EQ(NextLevel(levels, 2, 0.02f), 1u);   // finer at once when the error shrinks
  EXPECT_EQ(NextLevel(levels, 3, 1.f), 3u);
}

TEST(MeshLodsTest, PixelErrorIsWhatThePixelsSpanAtTheNearestPoint) {
  // A box 100 m ahead (its near face at x = 100): 2 pixels of 1 mrad span 0.2 m.
  const Eigen::AlignedBox3f box(Eigen::Vector3f(100, -5, -5), Eigen::Vector3f(110, 5, 5));
  EXPECT_NEAR(PixelError(2.f, 0.001f, box), 0.2f, 1e-6f);
  EXPECT_EQ(PixelError(0.f, 0.001f, box), 0.f);
  EXPECT_EQ(PixelError(2.f, 0.001f, Eigen::AlignedBox3f()), 0.f);
  // The eye inside the box: no simplification at all.
  EXPECT_EQ(PixelError(2.f, 0.001f,
                       Eigen::AlignedBox3f(Eigen::Vector3f(-1, -1, -1), Eigen::Vector3f(1, 1, 1))),
            0.f);
}

TEST(MeshLodsTest, UnderShadowsTheErrorIsAFifthOfTheCascadesTexel) {
  std::vector<ShadowCascade> cascades(2);
  cascades[0].far_m = 50.0, cascades[0].texel_m = 0.05;
  cascades[1].far_m = 300.0, cascades[1].texel_m = 0.5;
  const Eigen::Vector3f axis(1, 0, 0);
  auto box_at = [](float x) {
    return Eigen::AlignedBox3f(Eigen::Vector3f(x, -1, -1), Eigen::Vector3f(x + 2, 1, 1));
  };
  EXPECT_NEAR(UnderShadowTexel(1.f, cascades, axis, box_at(20)), 0.01f, 1e-7f);     // first cascade
  EXPECT_NEAR(UnderShadowTexel(1.f, cascades, axis, box_at(100)), 0.1f, 1e-7f);     // second
  EXPECT_NEAR(UnderShadowTexel(0.05f, cascades, axis, box_at(100)), 0.05f, 1e-7f);  // smaller kept
  EXPECT_EQ(UnderShadowTexel(1.f, cascades, axis, box_at(400)), 1.f);  // beyond the shadows
  EXPECT_EQ(UnderShadowTexel(1.f, {}, axis, box_at(20)), 1.f);
}

}  // namespace
}  // namespace sandbox::render
