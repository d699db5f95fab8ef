#pragma once
// A small glTF 2.0 writer for generated assets: one .gltf (JSON) and one .bin
// per file, one material per mesh, optionally a node hierarchy and one skin.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace sandbox::assets {

struct GeneratedMesh {
  GeneratedMesh() = default;
  GeneratedMesh(std::string mesh_name, std::array<float, 4> color)
      : name(std::move(mesh_name)), base_color(color) {}

  std::string name;
  std::array<float, 4> base_color{0.8f, 0.8f, 0.8f, 1.0f};  // linear RGBA
  std::vector<std::array<float, 3>> positions;              // Z up, metres
  std::vector<std::array<float, 3>> normals;                // filled by ComputeNormals if empty
  std::vector<std::uint32_t> indices;                       // counter-clockwise seen from outside
  // Skinned meshes: per vertex four joints (indices into GltfSkin::joints) and weights.
  std::vector<std::array<std::uint16_t, 4>> joints;
  std::vector<std::array<float, 4>> weights;

  std::uint32_t AddVertex(float x, float y, float z);
  void AddTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  // A planar quad a-b-c-d, counter-clockwise seen from outside.
  void AddQuad(const std::array<float, 3>& a, const std::array<float, 3>& b,
               const std::array<float, 3>& c, const std::array<float, 3>& d);
  // An axis-aligned box between corners lo and hi, 6 outward quads.
  void AddBox(const std::array<float, 3>& lo, const std::array<float, 3>& hi);
  // Area-weighted vertex normals (shared vertices are smooth).
  void ComputeNormals();
};

struct GltfNode {
  std::string name;
  int mesh{-1};         // index into GltfScene::meshes, -1: none
  bool skinned{false};  // the mesh is deformed by GltfScene::skin
  std::array<float, 3> translation{0.f, 0.f, 0.f};
  std::array<float, 4> rotation_xyzw{0.f, 0.f, 0.f, 1.f};
  std::vector<int> children;
};

struct GltfSkin {
  std::vector<int> joints;                          // node indices
  std::vector<std::array<float, 16>> inverse_bind;  // column-major, one per joint
};

// A scene written as given, in glTF's own axes (Y up).
struct GltfScene {
  std::vector<GeneratedMesh> meshes;
  std::vector<GltfNode> nodes;
  std::vector<int> roots;
  GltfSkin skin;
};

// World Z-up coordinates to glTF Y-up: (x, y, z) -> (x, z, -y).
std::array<float, 3> ToGltf(const std::array<float, 3>& p);

// Writes `file` (.gltf) and `file` with .bin beside it. Throws std::runtime_error.
void WriteGltfScene(const std::filesystem::path& file, const GltfScene& scene);

// Meshes given in the world frame (Z up, metres), one root node each, written
// Y-up as glTF requires.
void WriteGltf(const std::filesystem::path& file, const std::vector<GeneratedMesh>& meshes);

// The main() of a generator program: `program OUT_DIR` creates OUT_DIR and
// calls `write` with it; prints usage or the error and returns the exit code.
int GeneratorMain(int argc, char** argv,
                  const std::function<void(const std::filesystem::path&)>& write);

}  // namespace sandbox::assets
