// Generates the meshes of the bundled sample level (assets/sample/level.toml
// places them): terrain, water, rocks, a thin tall stone wall, a ruined tower,
// a large boulder and a gate. Deterministic: the same files every run.
//
//   make_sample_level OUT_DIR

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <utility>

#include "assets/generators/gltf_writer.h"
#include "assets/generators/sample_terrain.h"

namespace sandbox::assets {
namespace {

using Point = std::array<float, 3>;
constexpr double kPi = 3.14159265358979323846;

GeneratedMesh Terrain() {
  GeneratedMesh mesh{"terrain", {0.36f, 0.45f, 0.24f, 1.0f}};
  const int n = sample::kTerrainPoints;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const double x = sample::GridX(col), y = sample::GridY(row);
      mesh.AddVertex(float(x), float(y), float(sample::TerrainHeight(x, y)));
    }
  }
  for (int row = 0; row + 1 < n; ++row) {
    for (int col = 0; col + 1 < n; ++col) {
      const auto nw = std::uint32_t(row * n + col), ne = nw + 1;
      const auto sw = nw + std::uint32_t(n), se = sw + 1;
      mesh.AddTriangle(sw, se, ne);
      mesh.AddTriangle(sw, ne, nw);
    }
  }
  return mesh;
}

GeneratedMesh Water() {
  GeneratedMesh mesh{"water", {0.15f, 0.32f, 0.55f, 0.6f}};
  const auto h = float(sample::kTerrainHalfSize_m);
  mesh.AddQuad({-h, -h, 0.f}, {h, -h, 0.f}, {h, h, 0.f}, {-h, h, 0.f});
  return mesh;
}

// A deterministic bumpy displacement of a unit direction.
double Bumps(const Point& d, double seed) {
  return 0.12 * std::sin(3.1 * d[0] + 1.7 * seed) * std::sin(2.3 * d[1] + 0.4 + seed) *
             std::sin(2.9 * d[2] + 2.1 * seed) +
         0.06 * std::sin(7.3 * d[0] + 5.1 * d[1] + seed) + 0.04 * std::cos(9.7 * d[2] + 3.0 * seed);
}

// An icosphere of `subdivisions`, radius scaled per axis and displaced by Bumps.
void AddRock(GeneratedMesh* mesh, Point centre, Point radius, int subdivisions, double seed) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Point> v = {{-1, float(t), 0},  {1, float(t), 0},   {-1, float(-t), 0},
                          {1, float(-t), 0},  {0, -1, float(t)},  {0, 1, float(t)},
                          {0, -1, float(-t)}, {0, 1, float(-t)},  {float(t), 0, -1},
                          {float(t), 0, 1},   {float(-t), 0, -1}, {float(-t), 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  auto normalize = [](Point p) {
    const float l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return Point{p[0] / l, p[1] / l, p[2] / l};
  };
  for (Point& p : v) p = normalize(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = midpoints.emplace(key, std::uint32_t(v.size()));
      if (inserted) {
        v.push_back(
            normalize({(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2}));
      }
      return it->second;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& f : faces) {
      const std::uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]),
                          ca = midpoint(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  const auto base = std::uint32_t(mesh->positions.size());
  for (const Point& d : v) {
    const double k = 1.0 + Bumps(d, seed);
    mesh->AddVertex(float(centre[0] + radius[0] * k * d[0]),
                    float(centre[1] + radius[1] * k * d[1]),
                    float(centre[2] + radius[2] * k * d[2]));
  }
  for (const auto& f : faces) mesh->AddTriangle(base + f[0], base + f[1], base + f[2]);
}

// Rocks scattered over the terrain, baked at their world positions.
GeneratedMesh Rocks() {
  GeneratedMesh mesh{"rocks", {0.5f, 0.49f, 0.47f, 1.0f}};
  for (int i = 0; i < 16; ++i) {
    const double x = 150.0 * std::sin(1.9 * i + 0.3), y = 150.0 * std::cos(2.7 * i + 1.1);
    const double r = 1.0 + 1.5 * (0.5 + 0.5 * std::sin(4.1 * i));
    AddRock(&mesh, {float(x), float(y), float(sample::TerrainHeight(x, y) + 0.3 * r)},
            {float(r * 1.3), float(r), float(r * 0.8)}, 1, i);
  }
  return mesh;
}

GeneratedMesh Boulder() {
  GeneratedMesh mesh{"boulder", {0.42f, 0.4f, 0.38f, 1.0f}};
  AddRock(&mesh, {0.f, 0.f, 4.f}, {11.f, 9.f, 8.f}, 3, 42.0);
  return mesh;
}

// 40 m long, 0.6 m thick, 14 m above its origin, with a 5 m foundation.
GeneratedMesh Wall() {
  GeneratedMesh mesh{"wall", {0.62f, 0.6f, 0.56f, 1.0f}};
  mesh.AddBox({-20.f, -0.3f, -5.f}, {20.f, 0.3f, 14.f});
  return mesh;
}

// A curved block of the tower's ring wall between two angles and two heights.
void AddRingBlock(GeneratedMesh* mesh, double r_in, double r_out, double a0, double a1, float z0,
                  float z1) {
  auto at = [](double r, double a, float z) {
    return Point{float(r * std::cos(a)), float(r * std::sin(a)), z};
  };
  mesh->AddQuad(at(r_out, a0, z0), at(r_out, a1, z0), at(r_out, a1, z1), at(r_out, a0, z1));
  mesh->AddQuad(at(r_in, a1, z0), at(r_in, a0, z0), at(r_in, a0, z1), at(r_in, a1, z1));
  mesh->AddQuad(at(r_in, a0, z1), at(r_out, a0, z1), at(r_out, a1, z1), at(r_in, a1, z1));
  mesh->AddQuad(at(r_in, a1, z0), at(r_out, a1, z0), at(r_out, a0, z0), at(r_in, a0, z0));
  mesh->AddQuad(at(r_in, a0, z0), at(r_out, a0, z0), at(r_out, a0, z1), at(r_in, a0, z1));
  mesh->AddQuad(at(r_in, a1, z0), at(r_in, a1, z1), at(r_out, a1, z1), at(r_out, a1, z0));
}

// A hollow round tower (outer radius 6 m, wall 1 m, up to 24 m) with a door,
// windows, a breach and a broken top; its foundation goes 4 m below ground.
GeneratedMesh Tower() {
  GeneratedMesh mesh{"tower", {0.55f, 0.5f, 0.44f, 1.0f}};
  const int segments = 36, levels = 12;
  for (int s = 0; s < segments; ++s) {
    const double a0 = 2.0 * kPi * s / segments, a1 = 2.0 * kPi * (s + 1) / segments;
    int top = levels - int(2.5 + 2.5 * std::sin(0.9 * s) * std::cos(0.4 * s));
    if (s >= 20 && s <= 25) top = 6;  // the breach
    for (int level = -2; level < top; ++level) {
      const bool door = s <= 1 && level >= 0 && level <= 1;
      const bool window = (s % 9 == 0 && level == 4) || (s % 9 == 4 && level == 7);
      if (door || window) continue;
      AddRingBlock(&mesh, 5.0, 6.0, a0, a1, 2.0f * float(level), 2.0f * float(level + 1));
    }
  }
  return mesh;
}

// Two posts, a beam and a slatted leaf; the actor that may be moved from outside.
GeneratedMesh Gate() {
  GeneratedMesh mesh{"gate", {0.45f, 0.3f, 0.16f, 1.0f}};
  mesh.AddBox({-2.9f, -0.2f, -2.f}, {-2.5f, 0.2f, 5.f});
  mesh.AddBox({2.5f, -0.2f, -2.f}, {2.9f, 0.2f, 5.f});
  mesh.AddBox({-2.9f, -0.25f, 4.6f}, {2.9f, 0.25f, 5.2f});
  for (int slat = 0; slat < 6; ++slat) {
    const float x = -2.2f + 0.8f * float(slat);
    mesh.AddBox({x, -0.08f, 0.2f}, {x + 0.6f, 0.08f, 3.8f});
  }
  mesh.AddBox({-2.4f, -0.1f, 1.0f}, {2.4f, 0.1f, 1.3f});
  mesh.AddBox({-2.4f, -0.1f, 3.0f}, {2.4f, 0.1f, 3.3f});
  return mesh;
}

}  // namespace
}  // namespace sandbox::assets

int main(int argc, char** argv) {
  using namespace sandbox::assets;
  return GeneratorMain(argc, argv, [](const std::filesystem::path& out) {
    WriteGltf(out / "terrain.gltf", {Terrain()});
    WriteGltf(out / "water.gltf", {Water()});
    WriteGltf(out / "rocks.gltf", {Rocks()});
    WriteGltf(out / "boulder.gltf", {Boulder()});
    WriteGltf(out / "wall.gltf", {Wall()});
    WriteGltf(out / "tower.gltf", {Tower()});
    WriteGltf(out / "gate.gltf", {Gate()});
  });
}
